// `mpirun -np K loom audit`: a small scene written as files (boxes as STL, a harness whose
// cables cross them, clamps), audited by one process and by 2 and 3 ranks (oversubscribed
// on this machine): the same findings. A bad part file read by one rank stops every rank
// with the rank, the file and the reason, and leaves no report; --max-memory refuses a
// plan with the figure needed.
#include "common/run_loom.hpp"
#include "common/support_fixtures.hpp"
#include "core/io/harness_xml.hpp"
#include "core/io/mesh_write.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace loom {
namespace {

namespace fs = std::filesystem;
using testing::run_loom;

/// Runs `loom ARGS` under mpirun with `ranks` processes (as root too, as CI runs it; more
/// ranks than cores allowed; a hung job ends after two minutes).
testing::LoomRun run_mpi(int ranks, const std::string& args) {
  setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  return testing::run_command("mpirun --oversubscribe --timeout 120 -np " + std::to_string(ranks) + " " + LOOM_EXE +
                              " " + args);
}

/// 16 boxes in a 4 × 4 grid, a harness of 5 cables that cross the grid at several heights
/// (through some boxes, past others), clamps along the first.
fs::path write_scene(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("loom-mpi-" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream toml(dir / "scene.toml");
  toml << "[scene]\nname = \"grid\"\nunits = \"mm\"\n[routing]\nclearance = 2.0\nclamp_spacing = 300.0\n"
       << "[harness]\nfile = \"harness.xml\"\n";
  for (int i = 0; i < 16; ++i) {
    const Vec3 lo(100.0 + 250.0 * (i % 4), 100.0 + 250.0 * (i / 4), 20.0 + 10.0 * (i % 3));
    const std::string file = "box" + std::to_string(i) + ".stl";
    write_mesh(dir / file, test::box_part("b", lo, lo + Vec3(80, 80, 60)).mesh);
    toml << "[[part]]\nname = \"box-" << i << "\"\nfile = \"" << file << "\"\n" << (i % 7 == 3 ? "role = \"keep_out\"\n" : "");
  }
  Harness h;
  h.name = "grid";
  for (int c = 0; c < 5; ++c) {
    const double y = 140.0 + 200.0 * c, z = 30.0 + 12.0 * c;
    const std::string a = "P" + std::to_string(c) + "a", b = "P" + std::to_string(c) + "b";
    h.ports.push_back({a, {0, y, z}, {1, 0, 0}, 0});
    h.ports.push_back({b, {1100, y + 30.0 * (c - 2), z}, {-1, 0, 0}, 0});
    Segment s;
    s.from = a, s.to = b, s.path = {{400, y + 20, z + 5}, {700, y - 20, z - 5}};
    h.segments.push_back(s);
    Cable cable;
    cable.id = "W" + std::to_string(c), cable.ports[0] = a, cable.ports[1] = b;
    cable.physical.diameter = 4.0 + c, cable.physical.min_bend_radius = 20.0;
    h.cables.push_back(cable);
  }
  for (int k = 1; k < 5; ++k) {
    Clamp cl;
    cl.id = "K" + std::to_string(k), cl.position = {220.0 * k, 140.0, 30.0}, cl.segment = 0;
    h.clamps.push_back(cl);
  }
  write_harness_xml(h, dir / "harness.xml");
  return dir;
}

nlohmann::json read_json(const fs::path& p) {
  std::ifstream f(p);
  return nlohmann::json::parse(f);
}

/// The findings of two report.json files agree: every clash and violation the same (kind,
/// cable, part or other cable), values within the audit tolerance; each cable's exact
/// smallest clearance too; clamps identical. (No finding of this scene lies within the
/// tolerance of its threshold, where either answer would be right.)
void expect_same_findings(const nlohmann::json& a, const nlohmann::json& b) {
  const double tol = a.at("tolerance");
  for (const char* list : {"clashes", "violations"}) {
    ASSERT_EQ(a.at(list).size(), b.at(list).size()) << list;
    for (std::size_t i = 0; i < a.at(list).size(); ++i) {
      nlohmann::json x = a[list][i], y = b[list][i];
      for (const char* number : {"clearance", "value"})
        if (x.contains(number) && x[number].is_number()) {
          EXPECT_NEAR(x[number].get<double>(), y.at(number).get<double>(), tol) << list << " " << i;
          x.erase(number), y.erase(number);
        }
      // Where on the cable, and whether a sample landed inside the part: decided by the
      // samples, which follow the nearest surface among the parts a process holds.
      for (const char* where : {"point", "s", "s_begin", "s_end", "s_other", "inside"}) x.erase(where), y.erase(where);
      EXPECT_EQ(x, y) << list << " " << i;
    }
  }
  ASSERT_EQ(a.at("cables").size(), b.at("cables").size());
  // A cable's smallest clearance is exact where it comes within the watched band of a part,
  // otherwise the smallest sampled value (an upper bound that depends on the samples).
  for (std::size_t c = 0; c < a["cables"].size(); ++c) {
    const auto &x = a["cables"][c], &y = b["cables"][c];
    EXPECT_EQ(x.at("min_clearance_exact"), y.at("min_clearance_exact")) << c;
    if (x["min_clearance_exact"] == true && x["min_clearance"].is_number()) {
      EXPECT_NEAR(x["min_clearance"].get<double>(), y["min_clearance"].get<double>(), tol) << c;
    }
  }
  EXPECT_EQ(a.at("clamps"), b.at("clamps"));
  EXPECT_EQ(a.at("triangles"), b.at("triangles"));
}

TEST(AuditMpi, RanksFindWhatOneProcessFinds) {
  const fs::path dir = write_scene("same");
  const auto one = run_loom("audit " + (dir / "scene.toml").string() + " --out " + (dir / "one").string());
  ASSERT_EQ(one.status, 1) << one.out;  // the cables cross boxes: clashes
  const nlohmann::json ref = read_json(dir / "one" / "report.json");
  ASSERT_GE(ref["clashes"].size(), 3u);
  for (int ranks : {2, 3}) {
    SCOPED_TRACE(std::to_string(ranks) + " ranks");
    const fs::path out = dir / ("ranks" + std::to_string(ranks));
    const auto run = run_mpi(ranks, "audit " + (dir / "scene.toml").string() + " --out " + out.string());
    EXPECT_EQ(run.status, 1) << run.out;
    const nlohmann::json rep = read_json(out / "report.json");
    expect_same_findings(ref, rep);
    ASSERT_EQ(rep.at("shards").size(), static_cast<std::size_t>(ranks));
    std::size_t triangles = 0;
    for (const auto& s : rep["shards"]) triangles += s.at("triangles").get<std::size_t>();
    EXPECT_EQ(triangles, rep.at("triangles").get<std::size_t>());  // every part owned once
    EXPECT_FALSE(fs::exists(out / "view.html"));
  }
}

TEST(AuditMpi, ABadPartFileStopsEveryRankNamingRankAndFile) {
  const fs::path dir = write_scene("bad");
  {
    std::ofstream bad(dir / "box5.stl", std::ios::trunc);
    bad << "solid broken\nfacet normal 0 0 1\nouter loop\nvertex 0 0\n";
  }
  const auto run = run_mpi(2, "audit " + (dir / "scene.toml").string() + " --out " + (dir / "out").string());
  EXPECT_EQ(run.status, 2) << run.out;
  EXPECT_NE(run.out.find("rank "), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("box5.stl"), std::string::npos) << run.out;
  EXPECT_FALSE(fs::exists(dir / "out" / "report.json"));
}

TEST(AuditMpi, MaxMemoryRefusesAPlanWithTheFigureNeeded) {
  const fs::path dir = write_scene("memory");
  const auto run =
      run_mpi(2, "audit " + (dir / "scene.toml").string() + " --max-memory 10K --out " + (dir / "out").string());
  EXPECT_EQ(run.status, 2) << run.out;
  EXPECT_NE(run.out.find("--max-memory"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("ranks of this size"), std::string::npos) << run.out;
  EXPECT_FALSE(fs::exists(dir / "out" / "report.json"));
  // Without mpirun there is no plan to limit: the option is refused, not ignored.
  const auto single = run_loom("audit " + (dir / "scene.toml").string() + " --max-memory 1G --out " +
                               (dir / "out").string());
  EXPECT_EQ(single.status, 2) << single.out;
  EXPECT_NE(single.out.find("sharded audit"), std::string::npos) << single.out;
  EXPECT_EQ(run_loom("audit " + (dir / "scene.toml").string() + " --max-memory lots").status, 2);
}

}  // namespace
}  // namespace loom
