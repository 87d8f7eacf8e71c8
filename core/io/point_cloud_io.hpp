#pragma once
/// Reading scanned point clouds: PLY (ascii, binary little/big endian), XYZ text
/// and PCD (ascii, binary, binary_compressed/LZF). Only x, y, z are kept; every other
/// property is skipped. Points with a non-finite coordinate (organised PCD clouds mark
/// missing pixels with NaN) are dropped and counted. Coordinates are as stored in the file
/// (the scanner's frame and units).

#include "core/geometry.hpp"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace loom {

/// The file formats read_point_cloud understands.
enum class PointCloudFormat {
  PlyAscii,
  PlyBinaryLittleEndian,
  PlyBinaryBigEndian,
  Xyz,
  PcdAscii,
  PcdBinary,
  PcdBinaryCompressed,
};

/// Name of a format for reports ("ply-ascii", "pcd-binary-compressed", ...).
const char* to_string(PointCloudFormat f);

/// A point cloud as read: finite points only, plus what was dropped.
struct PointCloud {
  std::vector<Vec3> points;            ///< finite points, file order, file units
  std::size_t declared = 0;            ///< point count stated by the header (XYZ: lines read)
  std::size_t dropped_nonfinite = 0;   ///< points with a NaN/inf coordinate, dropped
  PointCloudFormat format = PointCloudFormat::Xyz;
};

/// Reads a point cloud; the format comes from the content (PLY/PCD magic) and otherwise
/// from the extension (.xyz/.txt/.pts/.asc = XYZ text). Throws InputError naming the file,
/// the line (text) or byte offset (binary) and the reason: unknown format, bad header,
/// truncated data, malformed number, corrupt compressed block, no finite points.
PointCloud read_point_cloud(const std::filesystem::path& path);

/// Same, from the bytes of a file; `name_for_errors` stands in for the file name (its
/// extension is used for format detection like a path's).
PointCloud parse_point_cloud(const std::string& bytes, const std::string& name_for_errors);

/// Writes points as a PLY file (binary little endian, or ascii), atomically.
void write_point_cloud_ply(const std::filesystem::path& path, const std::vector<Vec3>& points,
                           bool binary = true);

}  // namespace loom
