// The audit of a cable beside a scanned part against a brute-force oracle: the distance from
// the cable's axis to every scanned point. Nothing closer than required is missed, findings
// never claim more than the voxel bound allows, and "beyond-bound" is always a true violation.
#include "common/test_files.hpp"
#include "routing/audit/audit.hpp"
#include "routing/audit/report_json.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>

namespace {

using loom::testing::scratch_dir;
using loom::testing::write_file;

// C1 runs straight from (−20, 5, 5) to (30, 5, 5), radius 1; the required clearance is 2.
const std::string kHarness = R"(<harness name="h" units="mm">
  <attributes>
    <cable id="C1"><electrical><port id="J1"/><port id="J2"/></electrical>
      <physical type="t" color="red" diameter="2" min_bend_radius="10"/></cable>
  </attributes>
  <structure>
    <port id="J1" x="-20" y="5" z="5" dx="1" dy="0" dz="0"/>
    <port id="J2" x="30" y="5" z="5" dx="-1" dy="0" dz="0"/>
    <segment from="J1" to="J2"/>
  </structure>
</harness>
)";
constexpr double kRadius = 1.0, kRequired = 2.0, kRes = 0.5;

double axis_distance(const loom::Vec3& p) {
  const double x = std::clamp(p.x(), -20.0, 30.0);
  return (p - loom::Vec3(x, 5, 5)).norm();
}

struct Outcome {
  double oracle;                                  // true clearance to the scanned points
  double least = std::numeric_limits<double>::infinity();  // least clearance over findings on the scan
  int findings = 0, beyond = 0;
};

Outcome audit_case(unsigned seed, double gap) {
  const auto d = scratch_dir("voxel_audit_" + std::to_string(seed) + "_");
  // A rough slab of points whose nearest face lies `gap` beyond the cable's surface (+y side),
  // kept 10 mm from the ports so that no port exit is excused.
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(-8, 18), uy(0, 3), uz(1, 9);
  std::ostringstream xyz;
  xyz.precision(17);
  Outcome o;
  o.oracle = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 600; ++i) {
    const loom::Vec3 p(ux(rng), 5 + kRadius + gap + uy(rng) * uy(rng), uz(rng));
    xyz << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
    o.oracle = std::min(o.oracle, axis_distance(p) - kRadius);
  }
  write_file(d / "scan.xyz", xyz.str());
  write_file(d / "h.xml", kHarness);
  write_file(d / "s.toml", "[scene]\nname = \"s\"\nunits = \"mm\"\n[[part]]\nname = \"scan\"\nfile = \"scan.xyz\"\n"
                           "resolution = 0.5\n[harness]\nfile = \"h.xml\"\n[routing]\nclearance = 2.0\n");
  const loom::AuditReport rep = loom::audit_scene_file(d / "s.toml", {});
  const nlohmann::json j = loom::audit_report_json(rep);
  EXPECT_EQ(j.at("scanned_parts").size(), 1u);
  EXPECT_NEAR(j["scanned_parts"][0]["accuracy"].get<double>(), 0.5 * std::sqrt(3.0) * kRes, 1e-12);
  for (const char* list : {"clashes", "violations"})
    for (const auto& f : j.at(list)) {
      if (f.value("part", "") != "scan") continue;
      ++o.findings;
      o.least = std::min(o.least, f.at("clearance").get<double>());
      o.beyond += f.at("voxel") == "beyond-bound" ? 1 : 0;
      EXPECT_TRUE(f.at("voxel") == "beyond-bound" || f.at("voxel") == "within-bound") << f;
    }
  return o;
}

TEST(VoxelAudit, AgreesWithTheScannedPointsWithinTheBound) {
  const double bound = std::sqrt(3.0) * kRes;  // one voxel diagonal: twice the accuracy
  const double tol = 0.02;                     // above the audit's certified tolerance (r / 100)
  int beyond = 0, within = 0, clear = 0;
  unsigned seed = 1;
  for (const double gap : {-0.6, 0.3, 0.9, 1.4, 1.8, 2.1, 2.6, 3.5, 5.0})
    for (int rep = 0; rep < 2; ++rep, ++seed) {
      const Outcome o = audit_case(seed, gap);
      SCOPED_TRACE("gap " + std::to_string(gap) + " oracle " + std::to_string(o.oracle));
      // Nothing missed: closer than required to a scanned point means a finding.
      if (o.oracle < kRequired - tol) {
        EXPECT_GT(o.findings, 0);
      }
      if (o.findings == 0) {
        EXPECT_GE(o.oracle, kRequired - tol);
        ++clear;
        continue;
      }
      // The voxels hold the points: their clearance is a lower bound, at most one diagonal low.
      EXPECT_LE(o.least, o.oracle + tol);
      EXPECT_GE(o.least, o.oracle - bound - tol);
      // Beyond the bound is a real violation of the scanned structure.
      if (o.beyond > 0) {
        EXPECT_LT(o.oracle, kRequired + tol);
      }
      (o.beyond > 0 ? beyond : within) += 1;
    }
  std::printf("beyond-bound %d, within-bound %d, clear %d cases\n", beyond, within, clear);
  // The cases cover all three outcomes.
  EXPECT_GT(beyond, 0);
  EXPECT_GT(within, 0);
  EXPECT_GT(clear, 0);
}

}  // namespace
