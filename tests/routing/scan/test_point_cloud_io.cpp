// Point cloud reading: PLY ascii/binary LE/BE, XYZ, PCD ascii/binary/compressed,
// the real PCL sample clouds, malformed files with located errors.
#include "core/io/point_cloud_io.hpp"

#include "core/error.hpp"

#include <gtest/gtest.h>
#include "common/shared_data.hpp"
#include <liblzf/lzf.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include <unistd.h>

namespace loom {
namespace {

namespace fs = std::filesystem;
const fs::path kPcl = fs::path(LOOM_SHARED_DATA) / "pcl";

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// The header value of a PCD key, read independently of the reader under test.
std::size_t pcd_header_number(const fs::path& p, const std::string& key) {
  std::istringstream in(slurp(p));
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key + " ", 0) == 0) return std::stoul(line.substr(key.size() + 1));
  return 0;
}

template <typename T>
void put(std::string& out, T v, bool big_endian = false) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (big_endian) std::reverse(b, b + sizeof(T));
  out.append(b, sizeof(T));
}

/// Expects an InputError whose message contains every fragment.
void expect_error(const std::string& bytes, const std::string& name, std::vector<std::string> fragments) {
  try {
    parse_point_cloud(bytes, name);
    ADD_FAILURE() << "no error for " << name;
  } catch (const InputError& e) {
    for (const auto& f : fragments) EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what() << " lacks " << f;
  }
}

/// Naive LZF compressor (literal runs and back references found by brute force) — an
/// independent encoder to check the decoder against.
/// liblzf's decoder (what the PCD reader calls) with byte-vector sizes.
std::size_t lzf_decode(const std::uint8_t* in, std::size_t in_len, std::uint8_t* out, std::size_t out_len) {
  return ::lzf_decompress(in, static_cast<unsigned>(in_len), out, static_cast<unsigned>(out_len));
}

std::vector<std::uint8_t> lzf_compress_naive(const std::vector<std::uint8_t>& in) {
  std::vector<std::uint8_t> out, lit;
  auto flush = [&] {
    for (std::size_t i = 0; i < lit.size(); i += 32) {
      const std::size_t n = std::min<std::size_t>(32, lit.size() - i);
      out.push_back(static_cast<std::uint8_t>(n - 1));
      out.insert(out.end(), lit.begin() + static_cast<std::ptrdiff_t>(i), lit.begin() + static_cast<std::ptrdiff_t>(i + n));
    }
    lit.clear();
  };
  std::size_t i = 0;
  while (i < in.size()) {
    std::size_t best_len = 0, best_off = 0;
    for (std::size_t off = 1; off <= std::min<std::size_t>(i, 8192); ++off) {
      std::size_t l = 0;
      while (i + l < in.size() && l < 264 && in[i + l] == in[i + l - off]) ++l;
      if (l > best_len) {
        best_len = l;
        best_off = off;
      }
    }
    if (best_len >= 3) {
      flush();
      const std::size_t len = best_len - 2, off = best_off - 1;
      if (len < 7) {
        out.push_back(static_cast<std::uint8_t>((len << 5) | (off >> 8)));
      } else {
        out.push_back(static_cast<std::uint8_t>((7 << 5) | (off >> 8)));
        out.push_back(static_cast<std::uint8_t>(len - 7));
      }
      out.push_back(static_cast<std::uint8_t>(off & 0xff));
      i += best_len;
    } else {
      lit.push_back(in[i++]);
    }
  }
  flush();
  return out;
}

// ---- the real PCL clouds --------------------------------------------------------------

TEST(PointCloudIo, RealPclAsciiCloudsMatchTheirHeaders) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  for (const char* name : {"bunny.pcd", "bun0.pcd", "bun4.pcd", "curve3d.pcd"}) {
    const auto pc = read_point_cloud(kPcl / name);
    EXPECT_EQ(pc.format, PointCloudFormat::PcdAscii) << name;
    EXPECT_EQ(pc.declared, pcd_header_number(kPcl / name, "POINTS")) << name;
    EXPECT_EQ(pc.points.size(), pc.declared) << name;
    EXPECT_EQ(pc.dropped_nonfinite, 0u) << name;
  }
  // First point of bun0.pcd (7 fields, x y z first), from the file.
  const auto pc = read_point_cloud(kPcl / "bun0.pcd");
  EXPECT_DOUBLE_EQ(pc.points[0].x(), 0.0054215998);
  EXPECT_DOUBLE_EQ(pc.points[0].y(), 0.11349);
  EXPECT_DOUBLE_EQ(pc.points[0].z(), 0.040748999);
}

TEST(PointCloudIo, RealPclCompressedCloudsDecompress) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  const auto milk = read_point_cloud(kPcl / "milk.pcd");
  EXPECT_EQ(milk.format, PointCloudFormat::PcdBinaryCompressed);
  EXPECT_EQ(milk.declared, pcd_header_number(kPcl / "milk.pcd", "POINTS"));
  EXPECT_EQ(milk.points.size() + milk.dropped_nonfinite, milk.declared);
  AABB box;
  for (const auto& p : milk.points) box.extend(p);
  EXPECT_LT(box.diagonal(), 10.0);  // a milk carton in metres, not garbage
  EXPECT_GT(box.diagonal(), 0.01);

  const fs::path table = kPcl / "table_scene_mug_stereo_textured.pcd";
  const auto t = read_point_cloud(table);
  EXPECT_EQ(t.format, PointCloudFormat::PcdBinaryCompressed);
  EXPECT_EQ(t.declared, 640u * 480u);
  EXPECT_EQ(t.declared, pcd_header_number(table, "POINTS"));
  EXPECT_GT(t.dropped_nonfinite, 0u);  // organised cloud: missing pixels are NaN
  EXPECT_EQ(t.points.size() + t.dropped_nonfinite, t.declared);
  for (const auto& p : t.points) ASSERT_TRUE(p.allFinite());
}

TEST(PointCloudIo, RealPlyWithExtraPropertiesAndFaces) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  const auto pc = read_point_cloud(fs::path(LOOM_SHARED_DATA) / "trimesh" / "bunny.ply");
  EXPECT_EQ(pc.format, PointCloudFormat::PlyAscii);
  EXPECT_EQ(pc.points.size(), 8171u);
  EXPECT_DOUBLE_EQ(pc.points[0].x(), -0.036872);
  EXPECT_DOUBLE_EQ(pc.points[0].y(), 0.127727);
  EXPECT_DOUBLE_EQ(pc.points[0].z(), 0.00440925);
}

// ---- LZF -------------------------------------------------------------------------------

TEST(PointCloudIo, LzfDecoderInvertsAnIndependentEncoder) {
  std::mt19937 rng(5);
  for (int kind = 0; kind < 3; ++kind) {
    std::vector<std::uint8_t> data(3000);
    for (std::size_t i = 0; i < data.size(); ++i)
      data[i] = kind == 0 ? static_cast<std::uint8_t>(rng()) : kind == 1 ? static_cast<std::uint8_t>(i % 7)
                                                                        : static_cast<std::uint8_t>((i / 300) * 3);
    const auto comp = lzf_compress_naive(data);
    std::vector<std::uint8_t> out(data.size());
    ASSERT_EQ(lzf_decode(comp.data(), comp.size(), out.data(), out.size()), data.size()) << kind;
    EXPECT_EQ(out, data) << kind;
    // Too small an output buffer or a cut input is detected, not overrun.
    std::vector<std::uint8_t> small(data.size() - 1);
    EXPECT_EQ(lzf_decode(comp.data(), comp.size(), small.data(), small.size()), 0u);
  }
  const std::uint8_t bad_ref[] = {0x20, 0x10};  // back reference before the start
  std::uint8_t out[16];
  EXPECT_EQ(lzf_decode(bad_ref, 2, out, 16), 0u);
  const std::uint8_t cut_literal[] = {0x05, 'a', 'b'};  // literal of 6 with 2 bytes
  EXPECT_EQ(lzf_decode(cut_literal, 3, out, 16), 0u);
}

// ---- generated files in every format ------------------------------------------------------

const std::vector<Vec3> kPts = {{1.5, -2.25, 3.0}, {0.0, 1e-3, -7.125}, {100.5, 200.25, -300.75}};

std::string ply_binary(bool big, bool dbl, bool face_first) {
  std::string h = std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") + " 1.0\n";
  h += "comment generated\n";
  if (face_first) h += "element face 2\nproperty list uchar int vertex_indices\n";
  h += "element vertex 3\nproperty uchar red\n";
  h += dbl ? "property double x\nproperty double y\nproperty double z\n" : "property float x\nproperty float y\nproperty float z\n";
  h += "property list uchar float extra\nproperty short s\n";
  if (!face_first) h += "element face 1\nproperty list uchar int vertex_indices\n";
  h += "end_header\n";
  if (face_first) {
    put<std::uint8_t>(h, 3);
    for (int k = 0; k < 3; ++k) put<std::int32_t>(h, k, big);
    put<std::uint8_t>(h, 0);
  }
  for (const auto& p : kPts) {
    put<std::uint8_t>(h, 200);
    for (int k = 0; k < 3; ++k) dbl ? put<double>(h, p[k], big) : put<float>(h, static_cast<float>(p[k]), big);
    put<std::uint8_t>(h, 2);
    put<float>(h, 1.0f, big);
    put<float>(h, 2.0f, big);
    put<std::int16_t>(h, -5, big);
  }
  if (!face_first) {
    put<std::uint8_t>(h, 3);
    for (int k = 0; k < 3; ++k) put<std::int32_t>(h, k, big);
  }
  return h;
}

TEST(PointCloudIo, PlyBinaryBothEndiansFloatAndDoubleWithSkippedProperties) {
  for (bool big : {false, true})
    for (bool dbl : {false, true})
      for (bool face_first : {false, true}) {
        const auto pc = parse_point_cloud(ply_binary(big, dbl, face_first), "gen.ply");
        EXPECT_EQ(pc.format, big ? PointCloudFormat::PlyBinaryBigEndian : PointCloudFormat::PlyBinaryLittleEndian);
        ASSERT_EQ(pc.points.size(), 3u);
        for (std::size_t i = 0; i < 3; ++i)
          for (int k = 0; k < 3; ++k)
            EXPECT_EQ(pc.points[i][k], dbl ? kPts[i][k] : static_cast<double>(static_cast<float>(kPts[i][k])));
      }
}

TEST(PointCloudIo, PlyAsciiXyzAndPcdAscii) {
  const std::string ply =
      "ply\r\nformat ascii 1.0\r\nelement vertex 2\r\nproperty float nx\r\nproperty float x\r\nproperty float y\r\n"
      "property float z\r\nproperty list uchar int idx\r\nend_header\r\n9 1 2 3 2 7 8\r\n9 4 5 6 0\r\n";
  auto pc = parse_point_cloud(ply, "a.ply");
  ASSERT_EQ(pc.points.size(), 2u);
  EXPECT_EQ(pc.points[1], Vec3(4, 5, 6));

  const std::string xyz = "# scanner export\n1 2 3 255 0 0\n\n4,5,6 // trailing comment\n  +7e0\t8.5\t-9  \n";
  pc = parse_point_cloud(xyz, "scan.xyz");
  EXPECT_EQ(pc.format, PointCloudFormat::Xyz);
  ASSERT_EQ(pc.points.size(), 3u);
  EXPECT_EQ(pc.points[2], Vec3(7, 8.5, -9));

  const std::string pcd =
      "# .PCD v0.7\nVERSION 0.7\nFIELDS normal x y z\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 3 1 1 1\nWIDTH 3\nHEIGHT 1\n"
      "POINTS 3\nDATA ascii\n0 0 1 1 2 3\n0 0 1 nan nan nan\n0 0 1 4 5 6\n";
  pc = parse_point_cloud(pcd, "c.pcd");
  EXPECT_EQ(pc.format, PointCloudFormat::PcdAscii);
  ASSERT_EQ(pc.points.size(), 2u);
  EXPECT_EQ(pc.dropped_nonfinite, 1u);
  EXPECT_EQ(pc.points[1], Vec3(4, 5, 6));
}

std::string pcd_header(const std::string& data, std::size_t n) {
  return "VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 8 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH " + std::to_string(n) +
         "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(n) + "\nDATA " + data + "\n";
}

TEST(PointCloudIo, PcdBinaryAndCompressedWithMixedFieldSizes) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<Vec3> pts = kPts;
  pts.emplace_back(nan, 1, 2);
  std::string bin = pcd_header("binary", pts.size());
  for (const auto& p : pts) {
    put<float>(bin, static_cast<float>(p.x()));
    put<float>(bin, static_cast<float>(p.y()));
    put<double>(bin, p.z());
    put<std::uint32_t>(bin, 0xffffff);
  }
  auto pc = parse_point_cloud(bin, "b.pcd");
  EXPECT_EQ(pc.format, PointCloudFormat::PcdBinary);
  ASSERT_EQ(pc.points.size(), 3u);
  EXPECT_EQ(pc.dropped_nonfinite, 1u);
  EXPECT_EQ(pc.points[2].z(), kPts[2].z());
  EXPECT_EQ(pc.points[2].x(), static_cast<double>(static_cast<float>(kPts[2].x())));

  // Compressed: field-major layout, LZF with the independent encoder.
  std::vector<std::uint8_t> raw;
  auto app = [&](const void* v, std::size_t n) {
    const auto* b = static_cast<const std::uint8_t*>(v);
    raw.insert(raw.end(), b, b + n);
  };
  for (const auto& p : pts) { const float f = static_cast<float>(p.x()); app(&f, 4); }
  for (const auto& p : pts) { const float f = static_cast<float>(p.y()); app(&f, 4); }
  for (const auto& p : pts) { const double f = p.z(); app(&f, 8); }
  for (std::size_t i = 0; i < pts.size(); ++i) { const std::uint32_t c = 7; app(&c, 4); }
  const auto comp = lzf_compress_naive(raw);
  std::string cz = pcd_header("binary_compressed", pts.size());
  put<std::uint32_t>(cz, static_cast<std::uint32_t>(comp.size()));
  put<std::uint32_t>(cz, static_cast<std::uint32_t>(raw.size()));
  cz.append(reinterpret_cast<const char*>(comp.data()), comp.size());
  const auto pz = parse_point_cloud(cz, "z.pcd");
  EXPECT_EQ(pz.format, PointCloudFormat::PcdBinaryCompressed);
  EXPECT_EQ(pz.points, pc.points);
  EXPECT_EQ(pz.dropped_nonfinite, 1u);
  // Corrupt compressed data and a short block are located errors.
  std::string bad = cz;
  bad[bad.size() - comp.size()] = static_cast<char>(0xE0);  // a back reference at the start
  expect_error(bad, "z.pcd", {"z.pcd", "byte", "corrupt"});
  expect_error(cz.substr(0, cz.size() - 3), "z.pcd", {"z.pcd", "byte", "truncated"});
}

// ---- malformed -----------------------------------------------------------------------------

TEST(PointCloudIo, MalformedFilesGiveLocatedInputErrors) {
  expect_error("", "e.xyz", {"e.xyz", "no points"});
  expect_error("# only a comment\n", "c.xyz", {"c.xyz", "no points"});
  expect_error("1 2 3\n4 5\n", "t.xyz", {"t.xyz:2", "expected 'x y z'"});
  expect_error("1 2 3\n4 5 abc\n", "t.xyz", {"t.xyz:2", "bad number"});
  expect_error("nan 0 0\n", "n.xyz", {"n.xyz", "no finite points"});
  expect_error("hello", "x.bin", {"x.bin", "unknown point cloud format"});
  expect_error("solid x\n", "x.ply", {"x.ply", "not a PLY"});
  expect_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", "h.ply", {"h.ply", "end_header"});
  expect_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n", "h.ply",
               {"h.ply:3", "lacks x, y or z"});
  expect_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n", "h.ply", {"h.ply:4", "unknown type"});
  expect_error("ply\nformat zip 1.0\nend_header\n", "h.ply", {"h.ply:2", "unknown PLY format"});
  expect_error("ply\nformat ascii 1.0\nbogus line\nend_header\n", "h.ply", {"h.ply:3", "unknown PLY header keyword"});
  expect_error("ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int i\nend_header\n3 0 1 2\n", "h.ply",
               {"no vertex element"});
  const std::string ascii =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n4 5 6\n";
  expect_error(ascii, "t.ply", {"t.ply:10", "truncated data: 2 of 3"});
  const std::string bin = ply_binary(false, true, true);
  expect_error(bin.substr(0, bin.size() - 4), "t.ply", {"t.ply", "byte", "truncated"});
  const std::string big = ply_binary(true, false, true);
  expect_error(big.substr(0, big.size() - 10), "t.ply", {"t.ply", "byte", "truncated"});
  std::string pcd = pcd_header("binary", 4);
  pcd += std::string(20, '\0');
  expect_error(pcd, "p.pcd", {"p.pcd", "byte", "truncated"});
  expect_error("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nPOINTS 3\nDATA ascii\n", "p.pcd",
               {"p.pcd", "POINTS 3 != WIDTH*HEIGHT 2"});
  expect_error("VERSION 0.7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nPOINTS 1\nDATA ascii\n1 2\n", "p.pcd", {"p.pcd:2", "lack x, y or z"});
  expect_error("VERSION 0.7\nFIELDS x y z\nSIZE 4 4\nTYPE F F F\nPOINTS 1\nDATA ascii\n1 2 3\n", "p.pcd", {"SIZE"});
  expect_error("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 2\nDATA ascii\n1 2 3\n", "p.pcd",
               {"p.pcd:8", "truncated data: 1 of 2"});
  expect_error("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1\nDATA gzip\n", "p.pcd", {"unknown PCD data"});
  expect_error("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1\n", "p.pcd", {"no DATA"});
  EXPECT_THROW(read_point_cloud("/nonexistent/cloud.ply"), InputError);
}

// Header counts are checked against the bytes that follow before anything is reserved or
// looped over: a 4e9-vertex header reserved 96 GB (std::bad_alloc, naming no file), a
// binary element without properties declaring 1e18 instances was skipped one by one (a
// hang), a PCD COUNT of 2^64-1 wrapped the value count and indexed past a line's values,
// and a compressed block claiming 4 GB was allocated from 4 compressed bytes.
TEST(PointCloudIo, DeclaredCountsBeyondTheDataAreRefused) {
  const std::string vertex3 = "property float x\nproperty float y\nproperty float z\n";
  expect_error("ply\nformat ascii 1.0\nelement vertex 4000000000\n" + vertex3 + "end_header\n0 0 0\n", "a.ply",
               {"a.ply:3", "element vertex", "declares 4000000000 instances", "bytes after the header"});
  std::string bin = "ply\nformat binary_little_endian 1.0\nelement junk 1000000000000000000\nelement vertex 1\n" +
                    vertex3 + "end_header\n" + std::string(12, '\0');
  expect_error(bin, "b.ply", {"b.ply:3", "element junk", "declares 1000000000000000000 instances"});
  expect_error("ply\nformat ascii 1.0\nelement vertex 1\n" + vertex3 +
                   "property list uchar int l\nend_header\n0 0 0 255 1\n",
               "l.ply", {"l.ply:9", "list length 255 is more than the values on the line"});
  const std::string pcd = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n";
  expect_error(pcd + "POINTS 4000000000\nDATA ascii\n0 0 0\n", "p.pcd", {"p.pcd:6", "POINTS", "declares 4000000000 points"});
  expect_error(pcd + "POINTS 4000000000\nDATA binary\n" + std::string(24, '\0'), "p.pcd", {"declares 4000000000 points"});
  expect_error("VERSION 0.7\nFIELDS pad x y z\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 18446744073709551615 1 1 1\nPOINTS 1\n"
               "DATA ascii\n0 0 0\n",
               "c.pcd", {"c.pcd:7", "COUNT", "field 'pad'", "overflows"});
  expect_error(pcd + "WIDTH 4294967296\nHEIGHT 4294967296\nPOINTS 0\nDATA ascii\n", "w.pcd", {"WIDTH", "overflows"});
  std::string compressed = pcd + "POINTS 357913941\nDATA binary_compressed\n";
  put<std::uint32_t>(compressed, 4);
  put<std::uint32_t>(compressed, 4294967292u);
  compressed += std::string(4, '\0');
  expect_error(compressed, "z.pcd", {"z.pcd:6", "POINTS", "more than the 12 bytes of compressed data can expand to"});
}

// A directory or a device is not a point cloud (/dev/zero was read until memory ran out).
TEST(PointCloudIo, NonRegularFilesAreRefused) {
  const fs::path dir = fs::temp_directory_path() / "loom_pc_dir.xyz";
  fs::create_directories(dir);
  for (const fs::path& p : {dir, fs::path("/dev/zero")}) {
    if (!fs::exists(p)) continue;
    try {
      read_point_cloud(p);
      ADD_FAILURE() << p;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(p.string() + ": not a regular file"), std::string::npos) << e.what();
    }
  }
  fs::remove_all(dir);
}

// ---- round trip property -----------------------------------------------------------------

RC_GTEST_PROP(PointCloudIoProperty, PlyWriteReadRoundTripsExactly, (bool binary)) {
  const auto n = *rc::gen::inRange<std::size_t>(1, 200);
  std::vector<Vec3> pts;
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = *rc::gen::container<std::vector<int>>(3, rc::gen::inRange(-1000000, 1000000));
    pts.emplace_back(c[0] * 1.37e-3, c[1] / 7.0, c[2] * 1e5);
  }
  const fs::path p = fs::temp_directory_path() / ("loom_pc_rt_" + std::to_string(::getpid()) + ".ply");
  write_point_cloud_ply(p, pts, binary);
  const auto pc = read_point_cloud(p);
  fs::remove(p);
  RC_ASSERT(pc.points == pts);
  RC_ASSERT(pc.declared == n);
}

}  // namespace
}  // namespace loom
