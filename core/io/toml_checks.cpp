#include "core/io/toml_checks.hpp"

#include "core/error.hpp"

#include <cctype>
#include <vector>

namespace loom {

namespace {

/// A scan of a TOML text that knows where keys and values stand, enough to measure nesting:
/// strings and comments are skipped, dotted keys and table headers counted key by key.
class NestingScan {
 public:
  NestingScan(const std::string& text, const std::string& file) : s_(text), file_(file) {}

  void run() {
    while (i_ < s_.size()) {
      skip_blanks_and_comments();
      if (i_ >= s_.size()) break;
      if (s_[i_] == '[') header();
      else statement();
    }
  }

 private:
  /// One open array or inline table: its kind and the depth of its own values.
  struct Open {
    bool table;
    std::size_t depth;
  };

  void note_depth(std::size_t depth) const {
    if (depth > kMaxTomlNesting)
      throw InputError({file_, line_, ""}, "nesting deeper than " + std::to_string(kMaxTomlNesting) +
                                               " levels (tables, dotted keys, arrays and inline tables)");
  }

  char at(std::size_t k) const { return k < s_.size() ? s_[k] : '\0'; }

  void newline() { ++line_; }

  void skip_blanks_and_comments() {
    while (i_ < s_.size()) {
      const char c = s_[i_];
      if (c == '\n') {
        newline();
        ++i_;
      } else if (c == ' ' || c == '\t' || c == '\r') {
        ++i_;
      } else if (c == '#') {
        while (i_ < s_.size() && s_[i_] != '\n') ++i_;
      } else {
        break;
      }
    }
  }

  void skip_inline_blanks() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t')) ++i_;
  }

  /// Skips a string of any of the four kinds starting at i_ (a quote), counting its lines.
  void skip_string() {
    const char q = s_[i_];
    const bool multi = at(i_ + 1) == q && at(i_ + 2) == q;
    i_ += multi ? 3 : 1;
    while (i_ < s_.size()) {
      const char c = s_[i_];
      if (c == '\\' && q == '"') {
        if (at(i_ + 1) == '\n') newline();
        i_ += 2;
        continue;
      }
      if (c == '\n') {
        if (!multi) return;  // an unterminated string: the parser reports it
        newline();
      }
      if (c == q && (!multi || (at(i_ + 1) == q && at(i_ + 2) == q))) {
        i_ += multi ? 3 : 1;
        while (multi && at(i_) == q) ++i_;  // up to two quotes may end the content
        return;
      }
      ++i_;
    }
  }

  /// Reads a key (bare or quoted parts joined by dots) and returns its number of parts.
  std::size_t key() {
    std::size_t parts = 0;
    for (;;) {
      skip_inline_blanks();
      const char c = at(i_);
      if (c == '"' || c == '\'') {
        skip_string();
      } else if (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-') {
        while (std::isalnum(static_cast<unsigned char>(at(i_))) || at(i_) == '_' || at(i_) == '-') ++i_;
      } else {
        return parts;  // malformed: the parser reports it
      }
      ++parts;
      skip_inline_blanks();
      if (at(i_) != '.') return parts;
      ++i_;
    }
  }

  /// `[a.b]` or `[[a.b]]`: the depth of the keys that follow it (an array of tables adds the
  /// array's level).
  void header() {
    const bool array = at(i_ + 1) == '[';
    i_ += array ? 2 : 1;
    table_depth_ = key() + (array ? 1 : 0);
    note_depth(table_depth_);
    while (i_ < s_.size() && s_[i_] != '\n') ++i_;  // "]", "]]" and any comment
  }

  /// `key = value`, the value's arrays and inline tables with it (they may span lines).
  void statement() {
    std::size_t depth = table_depth_ + key();
    note_depth(depth);
    std::vector<Open> open;
    bool want_key = false;  // inside an inline table, after '{' or ','
    while (i_ < s_.size()) {
      const char c = s_[i_];
      if (want_key) {
        skip_inline_blanks();
        if (at(i_) == '}') {
          want_key = false;
          continue;
        }
        depth = open.back().depth + key();
        note_depth(depth);
        want_key = false;
        continue;
      }
      if (c == '"' || c == '\'') {
        skip_string();
      } else if (c == '#') {
        while (i_ < s_.size() && s_[i_] != '\n') ++i_;
      } else if (c == '\n') {
        newline();
        ++i_;
        if (open.empty()) return;
      } else if (c == '=') {
        ++i_;
      } else if (c == '[' || c == '{') {
        // The new container holds values one level below the key or array element it is.
        const std::size_t here = open.empty() || open.back().table ? depth : open.back().depth + 1;
        open.push_back({c == '{', here});
        note_depth(here + 1);
        ++i_;
        want_key = c == '{';
      } else if (c == ']' || c == '}') {
        if (!open.empty()) open.pop_back();
        ++i_;
      } else if (c == ',') {
        ++i_;
        want_key = !open.empty() && open.back().table;
      } else {
        ++i_;
      }
    }
  }

  const std::string& s_;
  const std::string& file_;
  std::size_t i_ = 0;
  int line_ = 1;
  std::size_t table_depth_ = 0;
};

}  // namespace

void check_toml_nesting(const std::string& text, const std::string& file) { NestingScan(text, file).run(); }

}  // namespace loom
