// The facet grammar of ASCII STL, checked token by token before Assimp reads the file.
#include "core/io/stl_file_checks.hpp"

#include "core/error.hpp"
#include "core/io/input_file.hpp"

#include <charconv>
#include <cstdint>
#include <cstring>
#include <string>
#include <system_error>

namespace loom {
namespace {

/// Whitespace between STL tokens (Assimp ends a word at any of these, and at NUL).
bool stl_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }

/// True when Assimp 5.2 reads these bytes as binary STL: at least 84 bytes and exactly
/// 84 + 50 bytes per facet of the count at byte 80 (its 32-bit arithmetic, wrap included).
bool assimp_reads_binary(const std::string& bytes) {
  if (bytes.size() < 84) return false;
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, sizeof count);
  return static_cast<std::uint64_t>(static_cast<std::uint32_t>(count * 50u + 84u)) == bytes.size();
}

/// A word and the 1-based line it starts on.
struct Token {
  std::string text;
  int line = 0;
};

/// Splits STL text into words, counting lines; a NUL byte is refused (Assimp would end the
/// file there, silently dropping what follows).
class StlTokens {
 public:
  StlTokens(const std::string& bytes, const std::filesystem::path& path) : b_(bytes), path_(path) {}

  /// The next word; false at the end.
  bool next(Token& t) {
    skip_space();
    if (at_ >= b_.size()) return false;
    t.line = line_;
    const std::size_t start = at_;
    while (at_ < b_.size() && !stl_space(b_[at_])) {
      if (b_[at_] == '\0')
        throw InputError({path_.string(), line_, "ASCII STL"}, "a NUL byte in the text (a binary STL whose size "
                                                              "does not match its facet count, or a corrupt file?)");
      ++at_;
    }
    t.text.assign(b_, start, at_ - start);
    return true;
  }
  /// True when the next word is on the current line (the solid's name is on its line).
  bool more_on_this_line() const {
    std::size_t k = at_;
    while (k < b_.size() && stl_space(b_[k]) && b_[k] != '\n') ++k;
    return k < b_.size() && b_[k] != '\n';
  }
  /// True when the next word starts with `prefix` (nothing is consumed but whitespace).
  bool next_starts_with(const char* prefix) {
    skip_space();
    return b_.compare(at_, std::strlen(prefix), prefix) == 0;
  }
  /// Skips to the start of the next line.
  void skip_line() {
    while (at_ < b_.size() && b_[at_] != '\n') ++at_;
  }

 private:
  void skip_space() {
    for (; at_ < b_.size() && stl_space(b_[at_]); ++at_)
      if (b_[at_] == '\n') ++line_;
  }
  const std::string& b_;
  const std::filesystem::path& path_;
  std::size_t at_ = 0;
  int line_ = 1;
};

/// A decimal number as STL writes one ("-1.5e+02"; a leading '+' allowed).
bool stl_number(const std::string& t) {
  const char* first = t.data();
  const char* last = t.data() + t.size();
  if (first != last && *first == '+') ++first;
  double v = 0.0;
  const auto r = std::from_chars(first, last, v);
  return first != last && r.ptr == last && r.ec != std::errc::invalid_argument;
}

/// Walks the solids of an ASCII STL file, refusing what Assimp would misread or reject.
class StlChecker {
 public:
  StlChecker(const std::string& bytes, const std::filesystem::path& path) : tokens_(bytes, path), path_(path) {}

  void run() {
    // After the last solid Assimp stops reading, whatever follows (NUL padding too).
    Token t;
    while (tokens_.next_starts_with("solid") && tokens_.next(t)) solid(t);
  }

 private:
  [[noreturn]] void fail(int line, const std::string& what, const std::string& reason) const {
    throw InputError({path_.string(), line, what}, reason);
  }

  std::string facet_name() const { return "facet " + std::to_string(facets_); }

  /// Three numbers after `keyword` (the line of which is `line`).
  void numbers(const char* keyword, int line) {
    Token t;
    for (int k = 0; k < 3; ++k) {
      if (!tokens_.next(t)) fail(line, facet_name(), std::string("the file ends inside '") + keyword + "'");
      if (!stl_number(t.text))
        fail(t.line, facet_name(),
             std::string("'") + keyword + "' coordinate " + std::to_string(k + 1) + " is '" + t.text + "', not a number");
    }
  }

  /// The facet whose `facet` word was read (line `line`): its normal and three vertices.
  void facet_body(int line) {
    Token t;
    if (!tokens_.next(t) || t.text != "normal")
      fail(line, facet_name(), "'facet' without 'normal x y z' (Assimp reads a facet without its normal and then "
                               "rejects the solid)");
    numbers("normal", t.line);
    int vertices = 0;
    while (true) {
      if (!tokens_.next(t)) fail(line, facet_name(), "the file ends inside the facet (no 'endfacet')");
      if (t.text == "vertex") {
        if (++vertices > 3) fail(t.line, facet_name(), "a fourth vertex (STL facets are triangles)");
        numbers("vertex", t.line);
      } else if (t.text == "endfacet" || t.text == "facet" || t.text.compare(0, 8, "endsolid") == 0) {
        break;
      }
      // Other words (`outer`, `loop`, `endloop`) carry nothing; Assimp skips them too.
    }
    if (vertices != 3)
      fail(line, facet_name(), "the facet has " + std::to_string(vertices) + " vertices (STL facets are triangles: 3)");
    pending_ = t;
  }

  /// The solid whose first word `head` ("solid" or "solidNAME") was read.
  void solid(const Token& head) {
    std::string name = head.text.substr(5);
    Token t;
    if (name.empty() && tokens_.more_on_this_line() && tokens_.next(t)) name = t.text;
    if (name.size() > kMaxStlSolidName)
      fail(head.line, "solid", "a solid name of " + std::to_string(name.size()) + " characters (Assimp takes at most " +
                                   std::to_string(kMaxStlSolidName) + ")");
    pending_.text.clear();
    while (!pending_.text.empty() || tokens_.next(t)) {
      if (!pending_.text.empty()) {
        t = pending_;
        pending_.text.clear();
      }
      if (t.text.compare(0, 8, "endsolid") == 0) {
        tokens_.skip_line();
        return;
      }
      if (t.text == "facet") {
        ++facets_;
        facet_body(t.line);
      } else if (t.text == "vertex") {
        fail(t.line, "solid", "'vertex' outside a facet (Assimp drops it)");
      }
    }
    // A file ending without `endsolid` after complete facets: Assimp reads it (and warns).
  }

  StlTokens tokens_;
  const std::filesystem::path& path_;
  Token pending_;  ///< a word read past the end of a facet, not yet handled
  std::size_t facets_ = 0;
};

}  // namespace

void check_stl_file(const std::filesystem::path& path) {
  const std::string bytes = file_bytes(path);
  if (assimp_reads_binary(bytes)) return;
  std::size_t first = 0;
  while (first < bytes.size() && (bytes[first] == ' ' || bytes[first] == '\t')) ++first;
  // Assimp reads text only from a file that starts with `solid` (spaces and tabs before it).
  if (bytes.size() <= first + 5 || bytes.compare(first, 5, "solid") != 0) return;
  StlChecker(bytes, path).run();
}

}  // namespace loom
