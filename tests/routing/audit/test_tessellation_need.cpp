// Tessellation by need on the wing section's STEP parts: a cable through an avionics box
// and one just above the curved actuator (inside its clearance); two boxes and a rib far
// from both. The near parts are refined, the far ones stay coarse; the audit finds what the
// audit of the uniformly fine mesh finds; and the certificate holds against brute force:
// every cable sample is farther from each coarse part's fine surface than its reach.
#include "routing/audit/audit.hpp"
#include "common/test_files.hpp"
#include "core/io/harness_xml.hpp"
#include "core/io/scene_load.hpp"
#include "index/embree_index.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

namespace loom {
namespace {

namespace fs = std::filesystem;

constexpr double kDiameter = 4.0;   ///< fine deflection r / 10 = 0.2 mm, coarse 4 mm
constexpr double kClearance = 3.0;  ///< [routing] clearance

/// The scene file: four STEP parts of the wing section (by name), the harness beside it.
fs::path write_scene(const fs::path& dir, bool by_need) {
  const fs::path ex = fs::path(LOOM_SOURCE_DIR) / "examples" / "wing-section";
  std::string toml = "[scene]\nname = \"need\"\nunits = \"mm\"\n[harness]\nfile = \"harness.xml\"\n"
                     "[routing]\nclearance = " + std::to_string(kClearance) + "\n";
  if (by_need) toml += "[tessellation]\nby_need = true\n";
  auto part = [&](const std::string& name, const std::string& file, double x) {
    toml += "[[part]]\nname = \"" + name + "\"\nfile = \"" + (ex / file).string() + "\"\ntransform = { translate = [" +
            std::to_string(x) + ", 0.0, 0.0] }\n";
  };
  part("avionics-1", "avionics-box.step", 300.0);
  part("avionics-2", "avionics-box.step", 900.0);
  part("rib-4", "rib.step", 1050.0);
  toml += "[[part]]\nname = \"actuator\"\nfile = \"" + (ex / "actuator.step").string() + "\"\n";
  const fs::path f = dir / (by_need ? "by_need.toml" : "uniform.toml");
  testing::write_file(f, toml);
  return f;
}

/// C1 crosses avionics-1 (x 210–390, y 375–714, z 40–160); C2 runs along the top of the
/// actuator (x 458–738, y 540–714, z up to 135), just inside the clearance above it.
void write_harness(const fs::path& dir) {
  Harness h;
  h.name = "need";
  h.ports = {{"A", {300, 250, 100}, {0, 1, 0}, 0},
             {"B", {300, 800, 100}, {0, -1, 0}, 0},
             {"C", {420, 620, 134.5}, {1, 0, 0}, 0},
             {"D", {700, 620, 134.5}, {-1, 0, 0}, 0}};
  for (const auto& [a, b] : {std::pair("A", "B"), std::pair("C", "D")}) {
    Segment s;
    s.from = a, s.to = b, s.interp = Interp::Polyline;
    h.segments.push_back(s);
    Cable c;
    c.id = std::string(a) == "A" ? "C1" : "C2", c.ports[0] = a, c.ports[1] = b, c.physical.diameter = kDiameter;
    h.cables.push_back(c);
  }
  write_harness_xml(h, dir / "harness.xml");
}

/// (kind, cable, part) of every clash and violation.
std::vector<std::string> finding_keys(const AuditReport& r) {
  std::vector<std::string> out;
  for (const ClashEntry& e : r.result.clashes)
    out.push_back(std::string(clash_kind_name(e.kind)) + " " + r.check_ids[static_cast<std::size_t>(e.cable)] + " " +
                  (e.part >= 0 ? r.part_names[static_cast<std::size_t>(e.part)] : ""));
  for (const Violation& v : r.result.violations)
    out.push_back(std::string(violation_kind_name(v.kind)) + " " + r.check_ids[static_cast<std::size_t>(v.cable)] +
                  " " + (v.part >= 0 ? r.part_names[static_cast<std::size_t>(v.part)] : ""));
  std::sort(out.begin(), out.end());
  return out;
}

TEST(TessellationNeed, RefinesWhatCablesComeNearAndFindsWhatTheFineMeshFinds) {
  const fs::path dir = testing::scratch_dir("tess-need");
  write_harness(dir);
  AuditOptions opt;
  opt.check.threads = 1;
  const AuditReport fine = audit_scene_file(write_scene(dir, false), opt);
  const AuditReport need = audit_scene_file(write_scene(dir, true), opt);
  EXPECT_FALSE(fine.tessellation.used);
  ASSERT_TRUE(need.tessellation.used);
  std::vector<std::string> refined;
  for (const int q : need.tessellation.refined) refined.push_back(need.part_names[static_cast<std::size_t>(q)]);
  EXPECT_EQ(refined, (std::vector<std::string>{"avionics-1", "actuator"}));
  EXPECT_EQ(need.tessellation.coarse_parts, 2u);
  EXPECT_DOUBLE_EQ(need.tessellation.coarse_deflection, 20.0 * need.tessellation.fine_deflection);
  EXPECT_LT(need.triangles, fine.triangles);
  // The same findings, and there are some (a clash with the box, a shortfall at the actuator).
  const auto keys = finding_keys(need);
  EXPECT_EQ(keys, finding_keys(fine));
  EXPECT_NE(std::find(keys.begin(), keys.end(), "cable-structure C1 avionics-1"), keys.end());
  EXPECT_NE(std::find(keys.begin(), keys.end(), "clearance C2 actuator"), keys.end());
  for (std::size_t i = 0; i < need.result.clashes.size(); ++i)
    EXPECT_NEAR(need.result.clashes[i].clearance, fine.result.clashes[i].clearance, need.result.tolerance);

  // The certificate, by brute force on the fine meshes: no sample of any cable (every r/4)
  // comes within r + required + tolerance of a part left coarse, nor lies inside it.
  SceneLoadOptions lo;
  const Scene fine_scene = load_scene(write_scene(dir, false), lo);
  const EmbreeIndex idx(fine_scene.parts);
  std::vector<AuditCable> ac;
  for (const CableInput& c : audit_cable_inputs(fine_scene.harness, ac))
    for (const auto& [s, p] : c.curve.sample_by_arc_length(c.radius / 4)) {
      for (std::size_t q = 0; q < fine_scene.parts.size(); ++q) {
        if (std::find(refined.begin(), refined.end(), fine_scene.parts[q].name) != refined.end()) continue;
        const double reach = c.radius + kClearance + need.result.tolerance;
        const ClosestHit h = idx.closest_on_part(p, static_cast<int>(q), reach);
        EXPECT_FALSE(h.found()) << c.id << " s = " << s << " within " << h.distance << " of " << fine_scene.parts[q].name;
      }
      std::vector<int> inside;
      idx.inside_parts(p, inside);
      for (const int q : inside)
        EXPECT_NE(std::find(refined.begin(), refined.end(), fine_scene.parts[static_cast<std::size_t>(q)].name),
                  refined.end());
    }
}

TEST(TessellationNeed, SceneKeysAreChecked) {
  const fs::path dir = testing::scratch_dir("tess-need-keys");
  write_harness(dir);
  const std::string base = testing::slurp(write_scene(dir, true));
  // The scene file with `from` replaced by `to`: the message of its refusal, or "".
  auto load_with = [&](const std::string& from, const std::string& to) {
    std::string t = base;
    t.replace(t.find(from), from.size(), to);
    testing::write_file(dir / "edited.toml", t);
    try {
      SceneLoadOptions lo;
      lo.load_parts = false;
      load_scene(dir / "edited.toml", lo);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(load_with("by_need = true", "by_need = true\ncoarse_deflection = 1.5"), "");
  EXPECT_NE(load_with("by_need = true", "by_need = true\ncoarse_deflection = 0.01").find("at least linear_deflection"),
            std::string::npos);
  EXPECT_NE(load_with("by_need = true", "by_need = 1").find("tessellation.by_need"), std::string::npos);
}

}  // namespace
}  // namespace loom
