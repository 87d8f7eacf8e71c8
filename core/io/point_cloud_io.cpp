#include "core/io/point_cloud_io.hpp"

#include "core/error.hpp"
#include "core/io/atomic_file.hpp"
#include "core/io/input_file.hpp"
#include "core/io/mesh_file_checks.hpp"

#include <liblzf/lzf.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string_view>

namespace loom {

const char* to_string(PointCloudFormat f) {
  switch (f) {
    case PointCloudFormat::PlyAscii: return "ply-ascii";
    case PointCloudFormat::PlyBinaryLittleEndian: return "ply-binary-little-endian";
    case PointCloudFormat::PlyBinaryBigEndian: return "ply-binary-big-endian";
    case PointCloudFormat::Xyz: return "xyz";
    case PointCloudFormat::PcdAscii: return "pcd-ascii";
    case PointCloudFormat::PcdBinary: return "pcd-binary";
    case PointCloudFormat::PcdBinaryCompressed: return "pcd-binary-compressed";
  }
  return "unknown";
}

namespace {

[[noreturn]] void fail(const std::string& file, int line, const std::string& element,
                       const std::string& reason) {
  throw InputError(SourceLocation{file, line, element}, reason);
}

[[noreturn]] void fail_at_byte(const std::string& file, std::size_t byte, const std::string& element,
                               const std::string& reason) {
  fail(file, 0, element, "byte " + std::to_string(byte) + ": " + reason);
}

/// Line-by-line cursor over text with 1-based line numbers.
struct LineReader {
  std::string_view text;
  std::size_t pos = 0;
  int line = 0;
  bool next(std::string_view& out) {
    if (pos >= text.size()) return false;
    std::size_t e = text.find('\n', pos);
    if (e == std::string_view::npos) e = text.size();
    out = text.substr(pos, e - pos);
    if (!out.empty() && out.back() == '\r') out.remove_suffix(1);
    pos = e + 1;
    ++line;
    return true;
  }
};

bool is_sep(char c) { return c == ' ' || c == '\t' || c == ',' || c == ';' || c == '\r'; }

/// Splits on whitespace (and , ; for XYZ).
std::vector<std::string_view> tokens(std::string_view s, bool commas) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  auto sep = [&](char c) { return commas ? is_sep(c) : (c == ' ' || c == '\t' || c == '\r'); };
  while (i < s.size()) {
    while (i < s.size() && sep(s[i])) ++i;
    std::size_t j = i;
    while (j < s.size() && !sep(s[j])) ++j;
    if (j > i) out.push_back(s.substr(i, j - i));
    i = j;
  }
  return out;
}

bool parse_double(std::string_view t, double& v) {
  if (!t.empty() && t.front() == '+') t.remove_prefix(1);
  if (t.empty()) return false;
  auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (r.ec == std::errc::result_out_of_range) {  // denormal or huge: fall back to strtod
    v = std::strtod(std::string(t).c_str(), nullptr);
    return true;
  }
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

bool parse_count(std::string_view t, std::size_t& v) {
  auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

std::string lower(std::string_view s) {
  std::string r(s);
  std::transform(r.begin(), r.end(), r.begin(), [](unsigned char c) { return std::tolower(c); });
  return r;
}

void add_point(PointCloud& pc, double x, double y, double z) {
  if (std::isfinite(x) && std::isfinite(y) && std::isfinite(z))
    pc.points.emplace_back(x, y, z);
  else
    ++pc.dropped_nonfinite;
}

void require_points(const PointCloud& pc, const std::string& file) {
  if (pc.points.empty())
    fail(file, 0, "", pc.dropped_nonfinite ? "no finite points (" + std::to_string(pc.dropped_nonfinite) +
                                                   " points with NaN/inf coordinates)"
                                             : "no points");
}

// ---------------------------------------------------------------------------------------
// Binary scalar decoding shared by PLY and PCD.

enum class Scalar { I8, U8, I16, U16, I32, U32, I64, U64, F32, F64 };

int scalar_size(Scalar s) {
  switch (s) {
    case Scalar::I8: case Scalar::U8: return 1;
    case Scalar::I16: case Scalar::U16: return 2;
    case Scalar::I32: case Scalar::U32: case Scalar::F32: return 4;
    default: return 8;
  }
}

template <typename T>
T load(const std::uint8_t* p, bool swap) {
  std::uint8_t b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (swap) std::reverse(b, b + sizeof(T));
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}

double decode(Scalar s, const std::uint8_t* p, bool swap) {
  switch (s) {
    case Scalar::I8: return static_cast<std::int8_t>(p[0]);
    case Scalar::U8: return p[0];
    case Scalar::I16: return load<std::int16_t>(p, swap);
    case Scalar::U16: return load<std::uint16_t>(p, swap);
    case Scalar::I32: return load<std::int32_t>(p, swap);
    case Scalar::U32: return load<std::uint32_t>(p, swap);
    case Scalar::I64: return static_cast<double>(load<std::int64_t>(p, swap));
    case Scalar::U64: return static_cast<double>(load<std::uint64_t>(p, swap));
    case Scalar::F32: return load<float>(p, swap);
    case Scalar::F64: return load<double>(p, swap);
  }
  return 0.0;
}

constexpr bool host_little_endian() {
  return true;  // every platform loom builds on (x86-64, aarch64) is little endian
}

// ---------------------------------------------------------------------------------------
// PLY

bool ply_scalar(std::string_view t, Scalar& s) {
  static const std::pair<const char*, Scalar> names[] = {
      {"char", Scalar::I8},    {"int8", Scalar::I8},     {"uchar", Scalar::U8},   {"uint8", Scalar::U8},
      {"short", Scalar::I16},  {"int16", Scalar::I16},   {"ushort", Scalar::U16}, {"uint16", Scalar::U16},
      {"int", Scalar::I32},    {"int32", Scalar::I32},   {"uint", Scalar::U32},   {"uint32", Scalar::U32},
      {"float", Scalar::F32},  {"float32", Scalar::F32}, {"double", Scalar::F64}, {"float64", Scalar::F64}};
  for (const auto& [n, v] : names)
    if (t == n) { s = v; return true; }
  return false;
}

struct PlyProperty {
  std::string name;
  Scalar type = Scalar::F32;
  bool is_list = false;
  Scalar count_type = Scalar::U8;
};

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PlyProperty> props;
  int line = 0;
};

PointCloud parse_ply(const std::string& bytes, const std::string& file) {
  LineReader lr{bytes};
  std::string_view ln;
  lr.next(ln);  // "ply"
  PointCloud pc;
  bool have_format = false;
  std::vector<PlyElement> elems;
  bool ended = false;
  while (lr.next(ln)) {
    auto tk = tokens(ln, false);
    if (tk.empty()) continue;
    if (tk[0] == "comment" || tk[0] == "obj_info") continue;
    if (tk[0] == "format") {
      if (tk.size() < 2) fail(file, lr.line, "format", "missing format name");
      if (tk[1] == "ascii") pc.format = PointCloudFormat::PlyAscii;
      else if (tk[1] == "binary_little_endian") pc.format = PointCloudFormat::PlyBinaryLittleEndian;
      else if (tk[1] == "binary_big_endian") pc.format = PointCloudFormat::PlyBinaryBigEndian;
      else fail(file, lr.line, "format", "unknown PLY format '" + std::string(tk[1]) + "'");
      have_format = true;
    } else if (tk[0] == "element") {
      PlyElement e;
      if (tk.size() != 3 || !parse_count(tk[2], e.count))
        fail(file, lr.line, "element", "expected 'element NAME COUNT'");
      e.name = std::string(tk[1]);
      e.line = lr.line;
      elems.push_back(std::move(e));
    } else if (tk[0] == "property") {
      if (elems.empty()) fail(file, lr.line, "property", "property before any element");
      PlyProperty p;
      if (tk.size() == 5 && tk[1] == "list") {
        p.is_list = true;
        if (!ply_scalar(tk[2], p.count_type) || !ply_scalar(tk[3], p.type))
          fail(file, lr.line, "property", "unknown list types '" + std::string(ln) + "'");
        p.name = std::string(tk[4]);
      } else if (tk.size() == 3) {
        if (!ply_scalar(tk[1], p.type))
          fail(file, lr.line, "property", "unknown type '" + std::string(tk[1]) + "'");
        p.name = std::string(tk[2]);
      } else {
        fail(file, lr.line, "property", "expected 'property TYPE NAME'");
      }
      elems.back().props.push_back(std::move(p));
    } else if (tk[0] == "end_header") {
      ended = true;
      break;
    } else {
      fail(file, lr.line, std::string(tk[0]), "unknown PLY header keyword");
    }
  }
  if (!have_format) fail(file, lr.line, "format", "PLY header has no format line");
  if (!ended) fail(file, lr.line, "end_header", "PLY header does not end (truncated file?)");

  int vi = -1;
  for (std::size_t i = 0; i < elems.size(); ++i)
    if (elems[i].name == "vertex") { vi = static_cast<int>(i); break; }
  if (vi < 0) fail(file, 0, "element vertex", "PLY file has no vertex element");
  const PlyElement& ve = elems[static_cast<std::size_t>(vi)];
  int ix = -1, iy = -1, iz = -1;
  for (std::size_t k = 0; k < ve.props.size(); ++k) {
    const auto& p = ve.props[k];
    int* slot = p.name == "x" ? &ix : p.name == "y" ? &iy : p.name == "z" ? &iz : nullptr;
    if (!slot) continue;
    if (p.is_list) fail(file, ve.line, "property " + p.name, "coordinate is a list property");
    *slot = static_cast<int>(k);
  }
  if (ix < 0 || iy < 0 || iz < 0) fail(file, ve.line, "element vertex", "vertex element lacks x, y or z");
  // Every element's count against the bytes after the header, before anything is reserved
  // or looped over: an instance takes at least a line (ASCII) or its fixed properties' bytes
  // (binary; a list at least its length field). A binary element without properties takes
  // none, yet skipping a huge count of them would loop without end: its count must fit too.
  {
    std::vector<PlyElementExtent> extents;
    for (const PlyElement& e : elems) {
      PlyElementExtent x{e.name, e.count, 0, e.line};
      for (const auto& p : e.props) x.min_bytes += static_cast<std::uint64_t>(scalar_size(p.is_list ? p.count_type : p.type));
      extents.push_back(x);
    }
    check_ply_extents(extents, pc.format == PointCloudFormat::PlyAscii, bytes.size() - std::min(lr.pos, bytes.size()),
                      file);
  }
  pc.declared = ve.count;
  pc.points.reserve(ve.count);

  if (pc.format == PointCloudFormat::PlyAscii) {
    // Elements before the vertex element: one line per instance.
    for (int e = 0; e < vi; ++e)
      for (std::size_t i = 0; i < elems[static_cast<std::size_t>(e)].count; ++i)
        if (!lr.next(ln)) fail(file, lr.line, elems[static_cast<std::size_t>(e)].name, "truncated data");
    for (std::size_t i = 0; i < ve.count; ++i) {
      if (!lr.next(ln))
        fail(file, lr.line + 1, "vertex", "truncated data: " + std::to_string(i) + " of " +
                                              std::to_string(ve.count) + " vertices");
      auto tk = tokens(ln, false);
      // Count the values this vertex must have (lists carry their own length).
      std::size_t t = 0;
      double c[3] = {0, 0, 0};
      for (std::size_t k = 0; k < ve.props.size(); ++k) {
        const auto& p = ve.props[k];
        if (t >= tk.size()) fail(file, lr.line, "vertex", "too few values on the line");
        if (p.is_list) {
          std::size_t n = 0;
          if (!parse_count(tk[t], n)) fail(file, lr.line, "vertex", "bad list length '" + std::string(tk[t]) + "'");
          if (n > tk.size() - t - 1)
            fail(file, lr.line, "vertex", "list length " + std::to_string(n) + " is more than the values on the line");
          t += 1 + n;
          continue;
        }
        double v;
        if (!parse_double(tk[t], v)) fail(file, lr.line, "vertex", "bad number '" + std::string(tk[t]) + "'");
        if (static_cast<int>(k) == ix) c[0] = v;
        if (static_cast<int>(k) == iy) c[1] = v;
        if (static_cast<int>(k) == iz) c[2] = v;
        ++t;
      }
      if (t > tk.size()) fail(file, lr.line, "vertex", "too few values on the line");
      add_point(pc, c[0], c[1], c[2]);
    }
  } else {
    const bool swap = (pc.format == PointCloudFormat::PlyBinaryBigEndian) == host_little_endian();
    const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
    std::size_t pos = lr.pos, end = bytes.size();
    auto need = [&](std::size_t n, const std::string& what) {
      if (pos + n > end) fail_at_byte(file, pos, what, "truncated data");
    };
    auto skip_record = [&](const PlyElement& e) {
      for (const auto& p : e.props) {
        if (p.is_list) {
          need(static_cast<std::size_t>(scalar_size(p.count_type)), e.name);
          const double n = decode(p.count_type, data + pos, swap);
          if (n < 0) fail_at_byte(file, pos, e.name, "negative list length");
          pos += static_cast<std::size_t>(scalar_size(p.count_type));
          // Before the conversion (7.7e31 from a float count does not fit a size_t): each
          // value takes a byte at least. NaN fails here too.
          if (!(n <= static_cast<double>(end - pos)))
            fail_at_byte(file, pos, e.name, "truncated data: a list length beyond the bytes left");
          const std::size_t bytes_n = static_cast<std::size_t>(n) * static_cast<std::size_t>(scalar_size(p.type));
          need(bytes_n, e.name);
          pos += bytes_n;
        } else {
          need(static_cast<std::size_t>(scalar_size(p.type)), e.name);
          pos += static_cast<std::size_t>(scalar_size(p.type));
        }
      }
    };
    for (int e = 0; e < vi; ++e)
      for (std::size_t i = 0; i < elems[static_cast<std::size_t>(e)].count; ++i)
        skip_record(elems[static_cast<std::size_t>(e)]);
    // Vertex records: fixed layout unless the vertex element has list properties.
    bool fixed = std::none_of(ve.props.begin(), ve.props.end(), [](const PlyProperty& p) { return p.is_list; });
    std::vector<std::size_t> off(ve.props.size(), 0);
    std::size_t rec = 0;
    for (std::size_t k = 0; k < ve.props.size(); ++k) {
      off[k] = rec;
      rec += static_cast<std::size_t>(scalar_size(ve.props[k].type));
    }
    const auto kx = static_cast<std::size_t>(ix), ky = static_cast<std::size_t>(iy), kz = static_cast<std::size_t>(iz);
    for (std::size_t i = 0; i < ve.count; ++i) {
      if (fixed) {
        if (pos + rec > end)
          fail_at_byte(file, pos, "vertex", "truncated data: " + std::to_string(i) + " of " +
                                                std::to_string(ve.count) + " vertices");
        const std::uint8_t* r = data + pos;
        add_point(pc, decode(ve.props[kx].type, r + off[kx], swap), decode(ve.props[ky].type, r + off[ky], swap),
                  decode(ve.props[kz].type, r + off[kz], swap));
        pos += rec;
      } else {
        double c[3] = {0, 0, 0};
        for (std::size_t k = 0; k < ve.props.size(); ++k) {
          const auto& p = ve.props[k];
          if (p.is_list) {
            PlyElement one{"vertex", 1, {p}, 0};
            skip_record(one);
            continue;
          }
          need(static_cast<std::size_t>(scalar_size(p.type)), "vertex");
          const double v = decode(p.type, data + pos, swap);
          if (k == kx) c[0] = v;
          if (k == ky) c[1] = v;
          if (k == kz) c[2] = v;
          pos += static_cast<std::size_t>(scalar_size(p.type));
        }
        add_point(pc, c[0], c[1], c[2]);
      }
    }
  }
  require_points(pc, file);
  return pc;
}

// ---------------------------------------------------------------------------------------
// PCD

struct PcdField {
  std::string name;
  int size = 4;
  char type = 'F';
  std::size_t count = 1;
  Scalar scalar = Scalar::F32;
};

Scalar pcd_scalar(char type, int size, const std::string& file, int line) {
  if (type == 'F' && size == 4) return Scalar::F32;
  if (type == 'F' && size == 8) return Scalar::F64;
  if (type == 'I' && size == 1) return Scalar::I8;
  if (type == 'I' && size == 2) return Scalar::I16;
  if (type == 'I' && size == 4) return Scalar::I32;
  if (type == 'I' && size == 8) return Scalar::I64;
  if (type == 'U' && size == 1) return Scalar::U8;
  if (type == 'U' && size == 2) return Scalar::U16;
  if (type == 'U' && size == 4) return Scalar::U32;
  if (type == 'U' && size == 8) return Scalar::U64;
  fail(file, line, "TYPE", std::string("unsupported field type ") + type + " of size " + std::to_string(size));
}

/// Largest ratio of LZF output to input: a back reference of 264 bytes costs 3 bytes.
constexpr std::uint64_t kLzfMaxExpansion = 88;

PointCloud parse_pcd(const std::string& bytes, const std::string& file) {
  LineReader lr{bytes};
  std::string_view ln;
  std::vector<PcdField> fields;
  std::vector<int> sizes;
  std::vector<char> types;
  std::vector<std::size_t> counts;
  std::size_t width = 0, height = 1, points = 0;
  bool have_points = false, have_width = false;
  std::string data;
  int fields_line = 0;
  while (lr.next(ln)) {
    auto tk = tokens(ln, false);
    if (tk.empty() || tk[0].front() == '#') continue;
    const std::string key = lower(tk[0]);
    if (key == "version" || key == "viewpoint") continue;
    if (key == "fields" || key == "columns") {
      fields_line = lr.line;
      for (std::size_t i = 1; i < tk.size(); ++i) fields.push_back(PcdField{std::string(tk[i])});
    } else if (key == "size") {
      for (std::size_t i = 1; i < tk.size(); ++i) {
        std::size_t v;
        if (!parse_count(tk[i], v)) fail(file, lr.line, "SIZE", "bad size '" + std::string(tk[i]) + "'");
        sizes.push_back(static_cast<int>(v));
      }
    } else if (key == "type") {
      for (std::size_t i = 1; i < tk.size(); ++i) {
        if (tk[i].size() != 1) fail(file, lr.line, "TYPE", "bad type '" + std::string(tk[i]) + "'");
        types.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(tk[i][0]))));
      }
    } else if (key == "count") {
      for (std::size_t i = 1; i < tk.size(); ++i) {
        std::size_t v;
        if (!parse_count(tk[i], v) || v == 0) fail(file, lr.line, "COUNT", "bad count '" + std::string(tk[i]) + "'");
        counts.push_back(v);
      }
    } else if (key == "width") {
      if (tk.size() != 2 || !parse_count(tk[1], width)) fail(file, lr.line, "WIDTH", "bad width");
      have_width = true;
    } else if (key == "height") {
      if (tk.size() != 2 || !parse_count(tk[1], height)) fail(file, lr.line, "HEIGHT", "bad height");
    } else if (key == "points") {
      if (tk.size() != 2 || !parse_count(tk[1], points)) fail(file, lr.line, "POINTS", "bad point count");
      have_points = true;
    } else if (key == "data") {
      if (tk.size() != 2) fail(file, lr.line, "DATA", "expected 'DATA ascii|binary|binary_compressed'");
      data = lower(tk[1]);
      break;
    } else {
      fail(file, lr.line, std::string(tk[0]), "unknown PCD header keyword");
    }
  }
  const int hdr_line = lr.line;
  if (data.empty()) fail(file, hdr_line, "DATA", "PCD header has no DATA line (truncated file?)");
  if (fields.empty()) fail(file, hdr_line, "FIELDS", "PCD header has no FIELDS");
  if (sizes.size() != fields.size()) fail(file, hdr_line, "SIZE", "SIZE does not list one size per field");
  if (types.size() != fields.size()) fail(file, hdr_line, "TYPE", "TYPE does not list one type per field");
  if (counts.empty()) counts.assign(fields.size(), 1);
  if (counts.size() != fields.size()) fail(file, hdr_line, "COUNT", "COUNT does not list one count per field");
  // Header numbers come from the file: every product below is checked against overflow
  // (a wrapped WIDTH*HEIGHT or record size would pass the size checks and read out of bounds).
  const std::size_t data_bytes = bytes.size() - std::min(lr.pos, bytes.size());
  if (height != 0 && width > SIZE_MAX / height)
    fail(file, hdr_line, "WIDTH", "WIDTH " + std::to_string(width) + " x HEIGHT " + std::to_string(height) +
                                      " overflows");
  if (!have_points) {
    if (!have_width) fail(file, hdr_line, "POINTS", "PCD header has neither POINTS nor WIDTH");
    points = width * height;
  }
  if (have_width && width * height != points)
    fail(file, hdr_line, "POINTS", "POINTS " + std::to_string(points) + " != WIDTH*HEIGHT " +
                                       std::to_string(width * height));
  int ix = -1, iy = -1, iz = -1;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    fields[i].size = sizes[i];
    fields[i].type = types[i];
    fields[i].count = counts[i];
    fields[i].scalar = pcd_scalar(types[i], sizes[i], file, hdr_line);
    if (fields[i].name == "x") ix = static_cast<int>(i);
    if (fields[i].name == "y") iy = static_cast<int>(i);
    if (fields[i].name == "z") iz = static_cast<int>(i);
  }
  if (ix < 0 || iy < 0 || iz < 0) fail(file, fields_line, "FIELDS", "PCD fields lack x, y or z");

  // Value index (ascii) and byte offset (binary) of each field within one point.
  std::vector<std::size_t> vidx(fields.size()), boff(fields.size());
  std::size_t nvals = 0, rec = 0;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    vidx[i] = nvals;
    boff[i] = rec;
    const auto size = static_cast<std::size_t>(fields[i].size);  // 1..8, checked above
    // A wrapped value count or record size would pass the checks below and index past the
    // values of a line or the bytes of the file.
    if (fields[i].count > (SIZE_MAX - rec) / size)
      fail(file, hdr_line, "COUNT", "field '" + fields[i].name + "' has COUNT " + std::to_string(fields[i].count) +
                                        ": the size of one point overflows");
    nvals += fields[i].count;
    rec += fields[i].count * size;
  }
  // The encoding before the counts are judged by it: an unknown one ("DATA 0") was refused
  // only after 1.8·10¹² points had been reserved.
  if (data != "ascii" && data != "binary" && data != "binary_compressed")
    fail(file, hdr_line, "DATA", "unknown PCD data encoding '" + data + "'");
  // Points against the data, before anything is reserved: a point takes at least a line
  // (ascii), its record (binary), or its share of the uncompressed size (checked below).
  if ((data == "ascii" && points > data_bytes) || (data == "binary" && rec > 0 && points > data_bytes / rec))
    fail(file, hdr_line, "POINTS", "declares " + std::to_string(points) + " points, more than the " +
                                       std::to_string(data_bytes) + " bytes of data can hold (truncated data?)");
  if (data == "binary_compressed" && rec > 0 &&
      (points > UINT32_MAX / rec || points > kLzfMaxExpansion * data_bytes / rec))
    fail(file, hdr_line, "POINTS", "declares " + std::to_string(points) + " points of " + std::to_string(rec) +
                                       " bytes: more than the " + std::to_string(data_bytes) +
                                       " bytes of compressed data can expand to (LZF, at most " +
                                       std::to_string(kLzfMaxExpansion) + "x, 32-bit sizes)");
  PointCloud pc;
  pc.declared = points;
  pc.points.reserve(points);
  const auto fx = static_cast<std::size_t>(ix), fy = static_cast<std::size_t>(iy), fz = static_cast<std::size_t>(iz);

  if (data == "ascii") {
    pc.format = PointCloudFormat::PcdAscii;
    std::size_t i = 0;
    while (i < points && lr.next(ln)) {
      auto tk = tokens(ln, false);
      if (tk.empty()) continue;
      if (tk.size() < nvals)
        fail(file, lr.line, "DATA", "expected " + std::to_string(nvals) + " values, found " + std::to_string(tk.size()));
      double c[3];
      const std::size_t at[3] = {vidx[fx], vidx[fy], vidx[fz]};
      for (int k = 0; k < 3; ++k)
        if (!parse_double(tk[at[k]], c[k])) fail(file, lr.line, "DATA", "bad number '" + std::string(tk[at[k]]) + "'");
      add_point(pc, c[0], c[1], c[2]);
      ++i;
    }
    if (i < points)
      fail(file, lr.line + 1, "DATA", "truncated data: " + std::to_string(i) + " of " + std::to_string(points) + " points");
  } else if (data == "binary") {
    pc.format = PointCloudFormat::PcdBinary;
    const auto* d = reinterpret_cast<const std::uint8_t*>(bytes.data());
    const std::size_t start = lr.pos;
    if (start + points * rec > bytes.size())
      fail_at_byte(file, bytes.size(), "DATA", "truncated data: " + std::to_string(points) + " points of " +
                                                   std::to_string(rec) + " bytes need " +
                                                   std::to_string(points * rec) + " bytes after the header at byte " +
                                                   std::to_string(start));
    for (std::size_t i = 0; i < points; ++i) {
      const std::uint8_t* r = d + start + i * rec;
      add_point(pc, decode(fields[fx].scalar, r + boff[fx], false), decode(fields[fy].scalar, r + boff[fy], false),
                decode(fields[fz].scalar, r + boff[fz], false));
    }
  } else if (data == "binary_compressed") {
    pc.format = PointCloudFormat::PcdBinaryCompressed;
    const auto* d = reinterpret_cast<const std::uint8_t*>(bytes.data());
    const std::size_t start = lr.pos;
    if (start + 8 > bytes.size()) fail_at_byte(file, start, "DATA", "truncated data: missing compressed sizes");
    const auto csize = load<std::uint32_t>(d + start, false);
    const auto usize = load<std::uint32_t>(d + start + 4, false);
    if (start + 8 + csize > bytes.size())
      fail_at_byte(file, start + 8, "DATA", "truncated data: compressed block of " + std::to_string(csize) +
                                                " bytes but only " + std::to_string(bytes.size() - start - 8) + " left");
    if (usize != points * rec)
      fail_at_byte(file, start + 4, "DATA", "uncompressed size " + std::to_string(usize) + " != " +
                                                std::to_string(points) + " points x " + std::to_string(rec) + " bytes");
    if (static_cast<std::uint64_t>(usize) > kLzfMaxExpansion * static_cast<std::uint64_t>(csize))
      fail_at_byte(file, start + 4, "DATA", "uncompressed size " + std::to_string(usize) + " is more than LZF can " +
                                                "expand the " + std::to_string(csize) + " compressed bytes to (at most " +
                                                std::to_string(kLzfMaxExpansion) + "x)");
    std::vector<std::uint8_t> buf(usize);
    if (usize > 0 && lzf_decompress(d + start + 8, static_cast<unsigned>(csize), buf.data(), static_cast<unsigned>(buf.size())) != usize)
      fail_at_byte(file, start + 8, "DATA", "corrupt LZF compressed data");
    // Field-major layout: all values of field 0, then of field 1, ...
    std::vector<std::size_t> foff(fields.size());
    std::size_t acc = 0;
    for (std::size_t i = 0; i < fields.size(); ++i) {
      foff[i] = acc;
      acc += points * fields[i].count * static_cast<std::size_t>(fields[i].size);
    }
    auto at = [&](std::size_t f, std::size_t i) {
      return decode(fields[f].scalar, buf.data() + foff[f] + i * fields[f].count * static_cast<std::size_t>(fields[f].size), false);
    };
    for (std::size_t i = 0; i < points; ++i) add_point(pc, at(fx, i), at(fy, i), at(fz, i));
  } else {
    fail(file, hdr_line, "DATA", "unknown PCD data encoding '" + data + "'");
  }
  require_points(pc, file);
  return pc;
}

// ---------------------------------------------------------------------------------------
// XYZ

PointCloud parse_xyz(const std::string& bytes, const std::string& file) {
  PointCloud pc;
  pc.format = PointCloudFormat::Xyz;
  LineReader lr{bytes};
  std::string_view ln;
  while (lr.next(ln)) {
    std::size_t cut = std::min(ln.find('#'), ln.find("//"));
    if (cut != std::string_view::npos) ln = ln.substr(0, cut);
    auto tk = tokens(ln, true);
    if (tk.empty()) continue;
    if (tk.size() < 3) fail(file, lr.line, "", "expected 'x y z', found " + std::to_string(tk.size()) + " value(s)");
    double c[3];
    for (int k = 0; k < 3; ++k)
      if (!parse_double(tk[static_cast<std::size_t>(k)], c[k]))
        fail(file, lr.line, "", "bad number '" + std::string(tk[static_cast<std::size_t>(k)]) + "'");
    ++pc.declared;
    add_point(pc, c[0], c[1], c[2]);
  }
  require_points(pc, file);
  return pc;
}

}  // namespace

PointCloud parse_point_cloud(const std::string& bytes, const std::string& name) {
  if (bytes.empty()) fail(name, 0, "", "empty file: no points");
  if (bytes.compare(0, 3, "ply") == 0 && bytes.size() > 3 && (bytes[3] == '\n' || bytes[3] == '\r'))
    return parse_ply(bytes, name);
  const std::string ext = lower(std::filesystem::path(name).extension().string());
  auto starts = [&](const char* s) { return bytes.compare(0, std::strlen(s), s) == 0; };
  if (ext == ".pcd" || starts("# .PCD") || starts("VERSION") || starts("FIELDS")) return parse_pcd(bytes, name);
  if (ext == ".ply") fail(name, 1, "", "not a PLY file (no 'ply' magic line)");
  if (ext == ".xyz" || ext == ".txt" || ext == ".pts" || ext == ".asc" || ext == ".csv") return parse_xyz(bytes, name);
  fail(name, 0, "", "unknown point cloud format (expected PLY, PCD or XYZ text: .ply .pcd .xyz .txt .pts .asc)");
}

PointCloud read_point_cloud(const std::filesystem::path& path) {
  require_input_file(path, "point cloud file");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path.string(), 0, "", "cannot open point cloud file");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) fail(path.string(), 0, "", "read error");
  return parse_point_cloud(bytes, path.string());
}

void write_point_cloud_ply(const std::filesystem::path& path, const std::vector<Vec3>& points, bool binary) {
  AtomicFile f(path, binary);
  auto& o = f.stream();
  o << "ply\nformat " << (binary ? "binary_little_endian" : "ascii") << " 1.0\n"
    << "comment written by loom\nelement vertex " << points.size()
    << "\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
  if (binary) {
    for (const auto& p : points) o.write(reinterpret_cast<const char*>(p.data()), 3 * sizeof(double));
  } else {
    for (const auto& p : points)
      o << full_precision(p.x()) << ' ' << full_precision(p.y()) << ' ' << full_precision(p.z()) << '\n';
  }
  f.commit();
}

}  // namespace loom
