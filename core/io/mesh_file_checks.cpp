#include "core/io/mesh_file_checks.hpp"

#include "core/error.hpp"
#include "core/io/input_file.hpp"
#include "core/io/mesh_node_checks.hpp"
#include "core/io/stl_file_checks.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <climits>
#include <charconv>
#include <cstring>
#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace loom {

namespace {

std::vector<std::string> words(const std::string& line) {
  std::istringstream is(line);
  std::vector<std::string> w;
  for (std::string t; is >> t;) w.push_back(t);
  return w;
}

/// A decimal count; false for anything else. Values beyond 64 bits saturate (they are
/// refused by the size checks like any other count the file cannot hold).
bool parse_count(const std::string& t, std::uint64_t& v) {
  if (t.empty() || !std::isdigit(static_cast<unsigned char>(t[0]))) return false;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (r.ec == std::errc::result_out_of_range) {
    v = UINT64_MAX;
    return true;
  }
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

// --- PLY ---------------------------------------------------------------------------------

/// Bytes of one PLY scalar type, 0 if the name is unknown.
std::uint64_t ply_scalar_bytes(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

/// One property of a PLY element: a scalar of `bytes`, or a list whose length field takes
/// `count_bytes` and each of whose items takes `bytes`.
struct PlyProperty {
  bool list = false;
  std::uint64_t count_bytes = 0;
  bool count_signed = false;  ///< the length field's type is signed (a negative length is corrupt)
  std::uint64_t bytes = 0;
  bool floating = false;  ///< the values are float or double
  bool value_signed = false;  ///< integer values of a signed type
  std::string name;
};

/// True for the list of a face's vertex indices, as Assimp reads it.
bool vertex_index_list(const std::string& element, const PlyProperty& p) {
  return element == "face" && p.list && !p.floating && (p.name == "vertex_indices" || p.name == "vertex_index");
}

/// Refuses a face's vertex index outside [0, vertices). Why: Assimp takes the index as
/// given, and one far outside the vertex list corrupted its heap (ASan, libFuzzer).
void check_vertex_index(const std::filesystem::path& path, int line, std::uint64_t instance, long long index,
                        std::uint64_t vertices) {
  if (index >= 0 && static_cast<std::uint64_t>(index) < vertices) return;
  throw InputError({path.string(), line, "element face instance " + std::to_string(instance)},
                   "vertex index " + std::to_string(index) + " is not one of the " + std::to_string(vertices) +
                       " vertices" + (vertices > 0 ? " (0.." + std::to_string(vertices - 1) + ")" : std::string()));
}

/// The vertex count a PLY header declares (its "vertex" element), if it has one.
std::optional<std::uint64_t> ply_vertex_count(const std::vector<PlyElementExtent>& extents) {
  for (const PlyElementExtent& e : extents)
    if (e.name == "vertex") return e.count;
  return std::nullopt;
}

/// Whether a PLY integer type is signed.
bool ply_scalar_signed(const std::string& t) {
  return t == "char" || t == "int8" || t == "short" || t == "int16" || t == "int" || t == "int32";
}

/// A PLY header as the checks need it: where the data starts and each element's layout.
struct PlyLayout {
  enum class Format { Ascii, BinaryLittle, BinaryBig } format = Format::Ascii;
  std::uint64_t data_at = 0;  ///< byte offset of the first byte after the header
  int header_lines = 0;       ///< lines of the header, end_header's included
  std::vector<PlyElementExtent> extents;
  std::vector<std::vector<PlyProperty>> properties;  ///< per element
};

/// 1-based line of byte `at` of `text`.
int line_at(const std::string& text, std::size_t at) {
  return static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n')) + 1;
}

/// How many instances Assimp reads of PLY element `name` declared with `declared`. Assimp
/// reads the count after the names it knows; for any other name it stores the name but reads
/// the count from the name's own leading digits (32-bit, wrapping; 0 for a name without
/// any), and for TextureFile it reads none.
std::uint64_t assimp_ply_element_count(const std::string& name, std::uint64_t declared) {
  if (name == "vertex" || name == "face" || name == "tristrips" || name == "edge" || name == "material")
    return declared;
  std::uint32_t digits = 0;
  for (std::size_t i = 0; i < name.size() && name[i] >= '0' && name[i] <= '9'; ++i)
    digits = digits * 10u + static_cast<std::uint32_t>(name[i] - '0');
  return name == "TextureFile" ? 0 : digits;
}

/// Throws InputError where Assimp would read a different number of instances of an element
/// than its header line declares, unless that element and every one after it are read as
/// empty (their data then goes unread, as loom needs none of it). Why: "element 5555…5face 4"
/// made Assimp reserve 3.8·10⁹ instances (91 GB), and an unknown element with instances
/// before the faces had its data read as faces.
void check_ply_element_counts(const std::vector<PlyElementExtent>& extents, const std::filesystem::path& path) {
  for (std::size_t i = 0; i < extents.size(); ++i) {
    const PlyElementExtent& e = extents[i];
    const std::uint64_t read = assimp_ply_element_count(e.name, e.count);
    if (read == e.count) continue;
    bool rest_unread = read == 0;
    for (std::size_t j = i + 1; rest_unread && j < extents.size(); ++j)
      rest_unread = assimp_ply_element_count(extents[j].name, extents[j].count) == 0;
    if (rest_unread) continue;
    throw InputError({path.string(), e.line, "element " + printable(e.name)},
                     "declares " + std::to_string(e.count) + " instance(s), but Assimp, which reads PLY meshes for "
                     "loom, would read " + std::to_string(read) + " (it takes the count of an element other than "
                     "vertex, face, tristrips, edge and material from the start of its name); rename the element "
                     "or move it after the mesh's elements");
  }
}

/// Throws InputError unless the PLY header in `head` (the file's first bytes, `whole` if
/// they are all of it) ends, holding no NUL byte. Why: Assimp's line reader looks for a
/// newline past the end of its buffer: a header without end_header spun forever, one with a
/// NUL read out of bounds (SIGSEGV).
/// Where the header's end_header keyword starts, as Assimp finds it: the first word of a
/// line (after blanks), followed by a blank or the line's end; npos if no line holds it.
/// Why not any "end_header": Assimp reads "end_headerrty" as another header line and, with
/// no real end after it, spun forever at the end of the file.
std::size_t find_end_header(const std::string& head) {
  constexpr std::size_t kLen = 10;  // "end_header"
  for (std::size_t line = 0; line < head.size();) {
    std::size_t at = head.find_first_not_of(" \t", line);
    // Not strchr(" \t\r\n", c): it finds a NUL byte too (the literal's terminator), and
    // "end_header\0" then passed for the end while Assimp read the data from elsewhere.
    const auto blank_or_end = [&](std::size_t i) {
      return i == head.size() || head[i] == ' ' || head[i] == '\t' || head[i] == '\r' || head[i] == '\n';
    };
    if (at != std::string::npos && head.compare(at, kLen, "end_header") == 0 && blank_or_end(at + kLen)) return at;
    const std::size_t nl = head.find('\n', line);
    if (nl == std::string::npos) break;
    line = nl + 1;
  }
  return std::string::npos;
}

void check_ply_header_ends(const std::string& head, bool whole, const std::filesystem::path& path) {
  const std::size_t end = find_end_header(head);
  const std::size_t nul = head.find('\0');
  if (nul < end)
    throw InputError({path.string(), line_at(head, nul), "PLY header"}, "holds a NUL byte (a binary or corrupt file?)");
  if (end != std::string::npos && head.find('\n', end) != std::string::npos) return;
  if (!whole)
    throw InputError({path.string(), 0, "PLY header"},
                     "no end_header in the first " + std::to_string(head.size()) + " bytes (not a PLY header)");
  const std::size_t last = head.empty() || head.back() != '\n' ? head.size() : head.size() - 1;
  throw InputError({path.string(), line_at(head, last), "end_header"}, "PLY header does not end (truncated file?)");
}

/// One `property` line of a PLY header (words `w`, line `line_no`) into `p`. Throws
/// InputError for a type that is not a PLY type.
PlyProperty read_ply_property(const std::vector<std::string>& w, int line_no, const std::filesystem::path& path) {
  PlyProperty p;
  p.list = w.size() == 5 && w[1] == "list";
  if (!p.list && w.size() != 3)
    throw InputError({path.string(), line_no, "property"},
                     "expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'");
  p.count_bytes = p.list ? ply_scalar_bytes(w[2]) : 0;
  p.count_signed = p.list && ply_scalar_signed(w[2]);
  const std::string& type = p.list ? w[3] : w[1];
  p.bytes = ply_scalar_bytes(type);
  p.floating = type.rfind("float", 0) == 0 || type == "double";
  p.value_signed = ply_scalar_signed(type);
  p.name = w.back();
  // A list's length is a whole number: a float or double count was read by Assimp as a
  // float and by this check as an integer, so the two walked different faces, and Assimp's
  // aborted its triangulation (ai_assert).
  if (p.list && (w[2].rfind("float", 0) == 0 || w[2] == "double"))
    throw InputError({path.string(), line_no, "property"},
                     "a list's count type must be an integer type (char uchar short ushort int uint, or int8 ... "
                     "uint32), not '" + printable(w[2]) + "'");
  // Assimp reads an unknown type as a property of no bytes and goes on with the data
  // misaligned, into faces that abort its triangulation (ai_assert).
  const std::string& bad = p.list && p.count_bytes == 0 ? w[2] : type;
  if (p.bytes == 0 || (p.list && p.count_bytes == 0))
    throw InputError({path.string(), line_no, "property"},
                     "'" + printable(bad) + "' is not a PLY type (char uchar short ushort int uint float double, "
                     "or int8 ... float64)");
  return p;
}

/// The header of a PLY file. Every header line must be one this check understands: Assimp
/// reads what it does not understand its own way (a `format` line it cannot parse left
/// the data misaligned, into faces that abort its triangulation), so anything else is
/// refused here, naming the line.
void read_ply_layout(const std::filesystem::path& path, PlyLayout& out) {
  constexpr std::size_t kMaxHeader = 1 << 20;  // PLY headers are a few hundred bytes
  const std::string head = file_bytes(path, kMaxHeader);
  // Assimp looks for the magic anywhere in the first bytes and then reads on from there
  // (a file of "\0\0\xc0\x7fply\n..." hung in its reader): only a file that starts with it
  // is a PLY file.
  if (head.compare(0, 3, "ply") != 0)
    throw InputError({path.string(), 1, "PLY header"}, "the file does not start with 'ply' (not a PLY file)");
  check_ply_header_ends(head, head.size() < kMaxHeader, path);
  const std::size_t end = find_end_header(head);
  const std::size_t data_at = head.find('\n', end);
  out.data_at = data_at + 1;
  out.header_lines = line_at(head, data_at);
  std::istringstream is(head.substr(0, end));
  int line_no = 0;
  bool has_format = false;
  int comment_in_element = 0;  // line of a comment or obj_info since the last element line
  std::string comment_word;
  for (std::string line; std::getline(is, line);) {
    ++line_no;
    const auto w = words(line);
    auto refuse = [&](const std::string& what, const std::string& why) {
      throw InputError({path.string(), line_no, what}, why);
    };
    // Assimp separates header words by spaces and tabs only: "property\ffloat y" was a line
    // it skipped while this check read a property, so the two laid out the data apart
    // (and Assimp's triangulation aborted).
    if (const std::size_t odd = line.find_first_of("\f\v"); odd != std::string::npos && !w.empty() &&
        w[0] != "comment" && w[0] != "obj_info")
      refuse("PLY header", "words separated by a form feed or vertical tab (byte " + std::to_string(int(line[odd])) +
                               "): only spaces and tabs separate them");
    // A form feed ends a header line for Assimp, comments included: "comment xelement
    // face 0000…1557 ..." was a comment to this check and an element of 2³²-wrapped count
    // to Assimp, which read it for minutes.
    if (const std::size_t ff = line.find('\f'); ff != std::string::npos)
      refuse("PLY header", "a form feed inside the line (column " + std::to_string(ff + 1) +
                               "): Assimp ends a line there, even a comment");
    // Assimp also ends a header line at a carriage return: "property float \rz" was a
    // property without a name to it and a line "z", while this check read "property float
    // z" (the data laid out apart; Assimp's triangulation aborted). A comment is no
    // exception: what follows the return would be read as a line of its own. Only the
    // return of a CRLF line end is a line's last byte.
    if (const std::size_t cr = line.find('\r'); cr != std::string::npos && cr + 1 < line.size())
      refuse("PLY header", "a carriage return inside the line (byte 13 at column " + std::to_string(cr + 1) +
                               "): only line ends may hold one");
    // Assimp ends an element's properties at a comment: "property float x / comment /
    // property float y" was an element of x alone to it, three floats to this check (its
    // data read apart, the triangulation aborted; in ASCII, a mesh of no triangles).
    if (!w.empty() && (w[0] == "comment" || w[0] == "obj_info") && !out.extents.empty() && comment_in_element == 0) {
      comment_in_element = line_no;
      comment_word = w[0];
    }
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info" || (line_no == 1 && w[0] == "ply")) continue;
    if (w[0] == "format") {
      const std::string name = w.size() >= 2 ? w[1] : std::string();
      if (name == "ascii") out.format = PlyLayout::Format::Ascii;
      else if (name == "binary_little_endian") out.format = PlyLayout::Format::BinaryLittle;
      else if (name == "binary_big_endian") out.format = PlyLayout::Format::BinaryBig;
      else refuse("format", "'" + printable(name) + "' is not a PLY format (ascii, binary_little_endian, binary_big_endian)");
      if (w.size() != 3 || has_format) refuse("format", "expected one 'format " + name + " 1.0' line");
      has_format = true;
    } else if (w[0] == "element") {
      PlyElementExtent e;
      comment_in_element = 0;
      if (w.size() != 3 || !parse_count(w[2], e.count)) refuse("element", "expected 'element NAME COUNT' with a whole COUNT");
      // Assimp keeps one list per element name: a second "element vertex 9" after "element
      // vertex 8" had its values written past the end of the first one's (heap corruption).
      for (const PlyElementExtent& before : out.extents)
        if (before.name == w[1])
          refuse("element " + printable(w[1]), "declared again (first at line " + std::to_string(before.line) +
                                                   "): each element name may be declared once");
      e.name = w[1];
      e.line = line_no;
      out.extents.push_back(e);
      out.properties.emplace_back();
    } else if (w[0] == "property") {
      if (out.extents.empty()) refuse("property", "a property before any element");
      if (comment_in_element != 0)
        refuse("property", "a property after the " + comment_word + " line " +
                               std::to_string(comment_in_element) + ", inside element " +
                               printable(out.extents.back().name) +
                               ": Assimp ends an element's properties at such a line (move it before the element)");
      const PlyProperty p = read_ply_property(w, line_no, path);
      out.extents.back().min_bytes += p.list ? p.count_bytes : p.bytes;
      out.properties.back().push_back(p);
    } else {
      refuse(printable(w[0]), "'" + printable(w[0]) +
                                  "' is not a PLY header keyword (format, element, property, comment, obj_info, end_header)");
    }
  }
  if (!has_format) throw InputError({path.string(), 1, "format"}, "the PLY header has no format line");
  check_ply_element_counts(out.extents, path);
}

/// Sequential reads over a file in blocks, so that walking a large PLY body costs one pass
/// and a block of memory.
class ByteCursor {
 public:
  ByteCursor(const std::filesystem::path& path, std::uint64_t at, std::uint64_t size)
      : in_(path, std::ios::binary), pos_(at), size_(size) {
    in_.seekg(static_cast<std::streamoff>(at));
  }
  /// Bytes left after the current position.
  std::uint64_t left() const { return size_ - pos_; }
  /// Moves on by n bytes (n ≤ left()).
  void skip(std::uint64_t n) {
    const std::uint64_t buffered = block_.size() - at_;
    if (n <= buffered) {
      at_ += static_cast<std::size_t>(n);
    } else {
      block_.clear();
      at_ = 0;
      in_.seekg(static_cast<std::streamoff>(pos_ + n));
    }
    pos_ += n;
  }
  /// The next n ≤ 8 bytes (n ≤ left()), in file order.
  std::array<unsigned char, 8> take(std::size_t n) {
    std::array<unsigned char, 8> b{};
    for (std::size_t k = 0; k < n; ++k) {
      if (at_ == block_.size()) refill();
      b[k] = static_cast<unsigned char>(block_[at_++]);
    }
    pos_ += n;
    return b;
  }

 private:
  void refill() {
    constexpr std::size_t kBlock = 1 << 20;
    block_.resize(static_cast<std::size_t>(std::min<std::uint64_t>(kBlock, size_ - pos_)));
    in_.read(block_.data(), static_cast<std::streamsize>(block_.size()));
    block_.resize(static_cast<std::size_t>(std::max<std::streamsize>(in_.gcount(), 0)));
    at_ = 0;
    if (block_.empty()) throw std::runtime_error("read past the end of the file");  // size changed under us
  }
  std::ifstream in_;
  std::string block_;
  std::size_t at_ = 0;
  std::uint64_t pos_ = 0, size_ = 0;
};

/// A binary integer of `bytes` ≤ 8 bytes as its PLY type reads it (unsigned values beyond
/// the range of long long saturate: no vertex list is that long).
long long ply_binary_int(const std::array<unsigned char, 8>& b, std::size_t bytes, bool big_endian, bool is_signed) {
  std::uint64_t u = 0;
  for (std::size_t k = 0; k < bytes; ++k) u = (u << 8) | b[big_endian ? k : bytes - 1 - k];
  const bool negative = is_signed && ((u >> (8 * bytes - 1)) & 1u);
  if (negative && bytes < 8) u |= ~std::uint64_t{0} << (8 * bytes);  // sign extension
  if (!negative && u > static_cast<std::uint64_t>(LLONG_MAX)) return LLONG_MAX;
  long long v = 0;
  std::memcpy(&v, &u, sizeof v);  // two's complement, without an implementation-defined cast
  return v;
}

/// A binary list length of `bytes` bytes as the integer the header names, in decimal
/// ("-1" for a signed field with its top bit set); `value` is UINT64_MAX for a negative one
/// (no file holds a negative length).
std::string list_length_text(const std::array<unsigned char, 8>& b, std::size_t bytes, bool big_endian,
                             bool is_signed, std::uint64_t& value) {
  const long long v = ply_binary_int(b, bytes, big_endian, is_signed);
  value = v < 0 ? UINT64_MAX : static_cast<std::uint64_t>(v);
  return std::to_string(v);
}

[[noreturn]] void bad_list(const std::filesystem::path& path, const PlyElementExtent& e, std::uint64_t instance,
                           const std::string& length, std::uint64_t left) {
  const std::string where = "element " + e.name + " instance " + std::to_string(instance);
  if (!length.empty() && length[0] == '-')
    throw InputError({path.string(), e.line, where}, "list length " + length + " is negative (a corrupt file?)");
  throw InputError({path.string(), e.line, where},
                   "list length " + length + " is more than the " + std::to_string(left) +
                       " bytes left in the file can hold (a truncated or corrupt file?)");
}

/// Refuses a face of no vertices. Why: every count then agrees with the data, yet Assimp's
/// triangulation aborts on it (ai_assert numOut != mNumFaces, SIGABRT).
void check_face_length(const std::filesystem::path& path, const PlyElementExtent& e, int line, std::uint64_t instance,
                       std::uint64_t n) {
  if (n == 0 && e.name == "face")
    throw InputError({path.string(), line, "element face instance " + std::to_string(instance)},
                     "a face of no vertices");
}

/// Every binary list length against the bytes left after it. Why: Assimp allocates a list
/// by its length field before reading it, so a 100-byte file with a face of 10⁸ indices
/// took 830 MB and one of 4·10⁹ ended in std::bad_alloc. Elements without lists are
/// skipped whole.
void check_ply_binary_lists(const std::filesystem::path& path, const PlyLayout& layout, std::uint64_t size) {
  const bool big = layout.format == PlyLayout::Format::BinaryBig;
  const std::optional<std::uint64_t> vertices = ply_vertex_count(layout.extents);
  ByteCursor cur(path, layout.data_at, size);
  for (std::size_t i = 0; i < layout.extents.size(); ++i) {
    const PlyElementExtent& e = layout.extents[i];
    const auto& props = layout.properties[i];
    const bool has_list = std::any_of(props.begin(), props.end(), [](const PlyProperty& p) { return p.list; });
    if (!has_list) {
      if (e.count > cur.left() / std::max<std::uint64_t>(e.min_bytes, 1)) return;  // the extent check's job
      cur.skip(e.count * e.min_bytes);
      continue;
    }
    for (std::uint64_t k = 0; k < e.count; ++k)
      for (const PlyProperty& p : props) {
        if (!p.list) {
          if (p.bytes > cur.left()) return;  // a short file: Assimp reports it
          cur.skip(p.bytes);
          continue;
        }
        if (p.count_bytes > cur.left()) return;
        const auto raw = cur.take(static_cast<std::size_t>(p.count_bytes));
        std::uint64_t n = 0;
        const std::string text =
            list_length_text(raw, static_cast<std::size_t>(p.count_bytes), big, p.count_signed, n);
        if (n > cur.left() / p.bytes) bad_list(path, e, k, text, cur.left());
        check_face_length(path, e, e.line, k, n);
        if (!(vertices && vertex_index_list(e.name, p))) {
          cur.skip(n * p.bytes);
          continue;
        }
        for (std::uint64_t v = 0; v < n; ++v) {
          const auto bytes = static_cast<std::size_t>(p.bytes);
          check_vertex_index(path, e.line, k, ply_binary_int(cur.take(bytes), bytes, big, p.value_signed), *vertices);
        }
      }
  }
}

/// Whether `t` reads whole as a value of a PLY property of `bytes` bytes: an integer
/// (optional sign, digits) for the integer types, a finite decimal number for float and
/// double. Why: Assimp's ASCII reader neither checks a token nor moves past one it cannot
/// read, so "-inf" or "1.5" for an index left the values that follow misaligned.
bool ply_ascii_value(const std::string& t, bool floating, std::string& why) {
  if (floating) {
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (end != t.c_str() + t.size()) why = "is not a number";
    else if (!std::isfinite(v)) why = "is not a finite number";
    return why.empty();
  }
  const std::size_t digits = t[0] == '-' || t[0] == '+' ? 1 : 0;
  const bool ok = t.size() > digits &&
                  std::all_of(t.begin() + static_cast<std::ptrdiff_t>(digits), t.end(),
                              [](unsigned char c) { return std::isdigit(c); });
  if (!ok) why = "is not an integer";
  return ok;
}

/// The words of an ASCII PLY line, split where Assimp's reader splits them.
std::vector<std::string> ply_words(const std::string& line) {
  std::vector<std::string> w;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const std::size_t from = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > from) w.push_back(line.substr(from, i - from));
  }
  return w;
}

/// Every instance of every element of an ASCII PLY, against its properties: Assimp reads one
/// instance per line and takes a missing value as 0 (a vertex at the origin, a face of no
/// vertices that then failed an assertion: SIGABRT), so each line must hold exactly its
/// properties' values, each a number of its type, and every declared instance must be there.
/// A list's length is checked against the bytes left before anything else (Assimp allocates
/// the list first: "4000000000 0 1 2" ended in std::bad_alloc).
void check_ply_ascii_body(const std::filesystem::path& path, const PlyLayout& layout, std::uint64_t size) {
  const std::optional<std::uint64_t> vertices = ply_vertex_count(layout.extents);
  std::ifstream in(path, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(layout.data_at));
  std::uint64_t line_at_byte = layout.data_at;
  int line_no = layout.header_lines;
  std::string line;
  for (std::size_t i = 0; i < layout.extents.size(); ++i) {
    const PlyElementExtent& e = layout.extents[i];
    const auto& props = layout.properties[i];
    for (std::uint64_t k = 0; k < e.count; ++k) {
      const std::string where = "element " + e.name + " instance " + std::to_string(k);
      if (!std::getline(in, line))
        throw InputError({path.string(), e.line, "element " + e.name},
                         std::to_string(e.count) + " declared, " + std::to_string(k) +
                             " in the file (a truncated file?)");
      ++line_no;
      const std::uint64_t next_line_at = line_at_byte + line.size() + 1;
      // Assimp ends a data line at a carriage return too: "0 1\r 1" was a vertex of two
      // values and a line of one to it, the instances laid out apart from this check's, and
      // its triangulation aborted. Only the return of a CRLF line end is a line's last byte.
      if (const std::size_t cr = line.find('\r'); cr != std::string::npos && cr + 1 < line.size())
        throw InputError({path.string(), line_no, where},
                         "a carriage return inside the line (byte 13 at column " + std::to_string(cr + 1) +
                             "): only line ends may hold one");
      const auto w = ply_words(line);
      std::size_t at = 0;  // index in w of the next value
      bool short_line = false;
      for (const PlyProperty& p : props) {
        std::uint64_t n = 1;
        if (p.list) {
          if (at >= w.size()) {
            short_line = true;
            break;
          }
          const std::string& t = w[at++];
          const std::uint64_t left = size - std::min(size, line_at_byte);  // from this line on
          if (!parse_count(t, n)) {
            if (t[0] == '-') bad_list(path, e, k, t, left);
            throw InputError({path.string(), line_no, where}, "list length '" + t + "' is not a count");
          }
          if (n > left / 2) bad_list(path, e, k, t, left);  // " v" per value at least
          check_face_length(path, e, line_no, k, n);
        }
        if (n > w.size() - at) {
          short_line = true;
          break;
        }
        for (std::size_t v = at; v < at + n; ++v) {
          std::string why;
          if (!ply_ascii_value(w[v], p.floating, why))
            throw InputError({path.string(), line_no, where}, "value '" + w[v] + "' " + why);
          if (vertices && vertex_index_list(e.name, p)) {
            errno = 0;
            const long long index = std::strtoll(w[v].c_str(), nullptr, 10);
            check_vertex_index(path, line_no, k, errno == ERANGE ? -1 : index, *vertices);
          }
        }
        at += static_cast<std::size_t>(n);
      }
      if (short_line || at != w.size())
        throw InputError({path.string(), line_no, where},
                         std::to_string(w.size()) + " values on the line, " +
                             (short_line ? std::string("too few for its properties")
                                         : "its properties take " + std::to_string(at)) +
                             " (one instance per line)");
      line_at_byte = next_line_at;
    }
  }
}

/// The PLY header's elements against the bytes after it (an instance takes at least one
/// byte in ASCII, a line, and at least its fixed properties' bytes in binary, a list at
/// least its length field), then every list's length against the bytes left after it.
void check_ply(const std::filesystem::path& path) {
  PlyLayout layout;
  read_ply_layout(path, layout);
  std::error_code ec;
  const auto size = static_cast<std::uint64_t>(std::filesystem::file_size(path, ec));
  if (ec || size < layout.data_at) return;
  const bool ascii = layout.format == PlyLayout::Format::Ascii;
  check_ply_extents(layout.extents, ascii, size - layout.data_at, path.string());
  // Assimp takes a newline byte right after end_header's line for part of that line's end
  // and reads the binary data one byte on from there (a tetrahedron whose first vertex
  // began with 0x0a aborted in its triangulation); the file cannot be read as written.
  if (!ascii && size > layout.data_at && file_bytes(path, layout.data_at + 1).back() == '\n')
    throw InputError({path.string(), layout.header_lines, "PLY data"},
                     "the binary data starts with a newline byte (0x0a), which Assimp takes for the end of "
                     "the header: the data would be read one byte off");
  if (ascii) check_ply_ascii_body(path, layout, size);
  else check_ply_binary_lists(path, layout, size);
}

// --- OFF ---------------------------------------------------------------------------------

/// `text` with every line ending made "\n": Assimp's OFF reader ends a line at a lone "\r"
/// too, so a comment "#...\r2222222224 6" hides from a reader that ends lines at "\n" alone
/// the counts Assimp then allocates by. A "\r\n" stays one line ending (line numbers hold).
std::string unix_lines(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '\r') {
      out.push_back(text[i]);
    } else if (i + 1 >= text.size() || text[i + 1] != '\n') {
      out.push_back('\n');
    }
  }
  return out;
}

/// The OFF header's vertex and face counts, whole numbers, against the file size: each vertex
/// and face takes at least one line.
void check_off(const std::filesystem::path& path) {
  const std::string head = unix_lines(file_bytes(path, 1 << 16));
  std::istringstream is(head);
  std::vector<std::string> tokens;
  std::vector<int> lines;
  int line_no = 0;
  for (std::string line; tokens.size() < 4 && std::getline(is, line);) {
    ++line_no;
    const std::size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    for (const auto& w : words(line)) {
      tokens.push_back(w);
      lines.push_back(line_no);
    }
  }
  // Where Assimp's reader finds the counts: after the magic (ST, C, N, 4, n before "OFF"),
  // and after a dimension when the magic has the n; without a magic it still takes a
  // leading 4 for the homogeneous flag and reads the counts from the rest, so "4 4 6" (a
  // tetrahedron) would be read as 4 vertices and 6 faces.
  const auto ends_with = [&](const std::string& t, const char* tail) {
    const std::size_t n = std::strlen(tail);
    return t.size() >= n && t.compare(t.size() - n, n, tail) == 0;
  };
  std::size_t at = 0;
  if (!tokens.empty() && ends_with(tokens[0], "OFF")) at = ends_with(tokens[0], "nOFF") ? 2 : 1;
  // Without both counts there is nothing to check them against, but Assimp reads counts
  // from whatever follows (the digits of "4294945910 255OBFF" as 4294945910 vertices and
  // 255 faces) and allocates by them: a header without two counts is refused.
  if (at + 1 >= tokens.size())
    throw InputError({path.string(), tokens.empty() ? 1 : lines.back(), "OFF header"},
                     "expected [magic] vertex and face counts, found " + std::to_string(tokens.size() - at) +
                         " token(s) after the magic (an empty or truncated file?)");
  std::uint64_t nv = 0, nf = 0;
  // A count that is not all digits is refused, not left to Assimp: its reader takes the
  // leading digits ("1000000000x" as 10⁹ faces) and allocates by them before reading any.
  for (const std::size_t k : {at, at + 1})
    if (!parse_count(tokens[k], k == at ? nv : nf))
      throw InputError({path.string(), lines[k], "OFF header"},
                       std::string(k == at ? "vertex" : "face") + " count '" + printable(tokens[k]) + "' is not a count");
  if (at == 0 && tokens[0][0] == '4')
    throw InputError({path.string(), lines[0], "OFF header"},
                     "no OFF line, and a vertex count starting with 4 (Assimp reads that 4 as the homogeneous "
                     "flag of a 4OFF magic): start the file with an OFF line");
  std::error_code ec;
  const auto size = static_cast<std::uint64_t>(std::filesystem::file_size(path, ec));
  if (ec) return;
  if (nv > size || nf > size || nv + nf > size)
    throw InputError({path.string(), lines[at], "OFF header"},
                     "declares " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                         " faces, more than the file's " + std::to_string(size) +
                         " bytes can hold (a truncated or corrupt file?)");
  // Face indices: Assimp's OFF reader replaces one beyond the vertices by the last vertex
  // (logging an error nobody sees), a silently different triangle. Lines after the header's:
  // nv vertex lines, then faces "k i1 .. ik [colour]"; blank and '#' lines skipped.
  std::istringstream all(unix_lines(file_bytes(path)));
  int no = 0;
  std::uint64_t seen_v = 0, seen_f = 0;
  for (std::string line; seen_f < nf && std::getline(all, line);) {
    ++no;
    if (no <= lines[at + 1]) continue;  // the header, through the line of the counts
    const std::size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    const auto w = words(line);
    if (w.empty()) continue;
    if (seen_v < nv) {
      ++seen_v;
      continue;
    }
    std::uint64_t k = 0;
    // k ≥ w.size() rather than k + 1 > w.size(): a saturated count would wrap to 0.
    if (!parse_count(w[0], k) || k >= w.size()) return;  // Assimp reports malformed faces
    for (std::size_t i = 1; i <= k; ++i) {
      std::uint64_t index = 0;
      if (!parse_count(w[i], index) || index >= nv)
        throw InputError({path.string(), no, "face " + std::to_string(seen_f)},
                         "vertex index " + w[i] + " is not one of the " + std::to_string(nv) + " vertices (0.." +
                             std::to_string(nv == 0 ? 0 : nv - 1) + ")");
    }
    ++seen_f;
  }
}

}  // namespace

void check_ply_extents(const std::vector<PlyElementExtent>& elements, bool ascii, std::uint64_t bytes,
                       const std::string& file) {
  std::uint64_t needed = 0;
  for (const PlyElementExtent& e : elements) {
    const std::uint64_t per = ascii ? 1 : e.min_bytes;
    const std::uint64_t room = bytes - std::min(needed, bytes);
    if (e.count > bytes || (per > 0 && e.count > room / per))
      throw InputError({file, e.line, "element " + e.name},
                       "declares " + std::to_string(e.count) + " instances, more than the " + std::to_string(bytes) +
                           " bytes after the header can hold (a truncated or corrupt file?)");
    needed += e.count * per;
  }
}

std::string lower_extension(const std::filesystem::path& path) {
  std::string e = path.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e;
}

void check_mesh_file_structure(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".ply") check_ply(path);
  else if (ext == ".off") check_off(path);
  else if (ext == ".stl") check_stl_file(path);
  else if (ext == ".dae") check_dae_file(path);
  else if (ext == ".gltf") check_gltf_file(path, false);
  else if (ext == ".glb") check_gltf_file(path, true);
}

}  // namespace loom
