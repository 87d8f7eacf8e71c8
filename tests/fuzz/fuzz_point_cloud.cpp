// libFuzzer entry point for one point-cloud format (LOOM_FUZZ_CLOUD_EXT: ".ply", ".pcd" or
// ".xyz"), through the in-memory reader parse_point_cloud with a file name of that
// extension (the format comes from the content's magic, else from the extension). A cloud
// it accepts must keep point_cloud_io.hpp's promises: at least one point, every kept point
// finite, and every declared point either kept or counted as dropped.
#include "fuzz_support.hpp"

#include "core/io/point_cloud_io.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

#ifndef LOOM_FUZZ_CLOUD_EXT
#error "LOOM_FUZZ_CLOUD_EXT (the point cloud file extension, e.g. \".pcd\") must be defined"
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  loom::fuzz::expect_only_input_errors([&] {
    const loom::PointCloud pc = loom::parse_point_cloud(bytes, std::string("fuzz") + LOOM_FUZZ_CLOUD_EXT);
    if (pc.points.empty()) loom::fuzz::finding("a point cloud without points was accepted");
    for (const loom::Vec3& p : pc.points)
      if (!p.allFinite()) loom::fuzz::finding("a point with a non-finite coordinate was kept");
    if (pc.points.size() + pc.dropped_nonfinite != pc.declared)
      loom::fuzz::finding(std::string(loom::to_string(pc.format)) + ": " + std::to_string(pc.points.size()) +
                          " points kept + " + std::to_string(pc.dropped_nonfinite) + " dropped != " +
                          std::to_string(pc.declared) + " declared");
  });
  return 0;
}
