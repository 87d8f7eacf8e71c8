#include "core/io/step_file_checks.hpp"

#include "core/error.hpp"
#include "core/io/input_file.hpp"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <string>
#include <vector>

namespace loom {

namespace {

/// An entity instance definition: its number, type and line.
struct StepInstance {
  std::uint64_t id = 0;
  std::string type;
  int line = 0;
};

/// A reference `#to` met inside the definition of instances[from].
struct StepReference {
  std::uint64_t to = 0;
  std::size_t from = 0;
};

/// The decimal number at s[i..] (i moved past it), saturating beyond 64 bits.
std::uint64_t read_number(const std::string& s, std::size_t& i) {
  std::uint64_t v = 0;
  for (; i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])); ++i)
    v = v > (UINT64_MAX - 9) / 10 ? UINT64_MAX : v * 10 + static_cast<std::uint64_t>(s[i] - '0');
  return v;
}

}  // namespace

void check_step_references(const std::filesystem::path& path) {
  const std::string s = file_bytes(path);
  std::vector<StepInstance> instances;
  std::vector<StepReference> refs;
  int line = 1;
  bool statement_start = true;  // after ';' (or at the start): a "#N =" here defines N
  bool in_instance = false;     // inside the definition of instances.back()
  for (std::size_t i = 0; i < s.size();) {
    const char c = s[i];
    if (c == '\n') {
      ++line;
      ++i;
    } else if (c == '\'') {  // a string; '' inside it is a quote
      for (++i; i < s.size(); ++i) {
        if (s[i] == '\n') ++line;
        if (s[i] == '\'') {
          if (i + 1 < s.size() && s[i + 1] == '\'') ++i;
          else break;
        }
      }
      ++i;
    } else if (c == '/' && i + 1 < s.size() && s[i + 1] == '*') {
      const std::size_t end = s.find("*/", i + 2);
      const std::size_t stop = end == std::string::npos ? s.size() : end + 2;
      line += static_cast<int>(std::count(s.begin() + static_cast<std::ptrdiff_t>(i),
                                          s.begin() + static_cast<std::ptrdiff_t>(stop), '\n'));
      i = stop;
    } else if (c == ';') {
      statement_start = true;
      in_instance = false;
      ++i;
    } else if (c == '#' && i + 1 < s.size() && std::isdigit(static_cast<unsigned char>(s[i + 1]))) {
      ++i;
      const std::uint64_t id = read_number(s, i);
      std::size_t j = i;
      while (j < s.size() && std::isspace(static_cast<unsigned char>(s[j])) && s[j] != '\n') ++j;
      if (statement_start && j < s.size() && s[j] == '=') {
        StepInstance inst{id, "", line};
        for (++j; j < s.size() && (std::isspace(static_cast<unsigned char>(s[j])) || s[j] == '('); ++j)
          if (s[j] == '\n') ++line;
        const std::size_t from = j;
        while (j < s.size() && (std::isalnum(static_cast<unsigned char>(s[j])) || s[j] == '_')) ++j;
        inst.type = s.substr(from, j - from);
        instances.push_back(std::move(inst));
        in_instance = true;
        i = j;
      } else if (in_instance) {
        refs.push_back({id, instances.size() - 1});
      }
      statement_start = false;
    } else {
      if (!std::isspace(static_cast<unsigned char>(c))) statement_start = false;
      ++i;
    }
  }
  std::vector<std::uint64_t> defined(instances.size());
  for (std::size_t k = 0; k < instances.size(); ++k) defined[k] = instances[k].id;
  std::sort(defined.begin(), defined.end());
  for (const StepReference& r : refs) {
    if (std::binary_search(defined.begin(), defined.end(), r.to)) continue;
    const StepInstance& from = instances[r.from];
    throw InputError({path.string(), from.line, "entity #" + std::to_string(from.id) + " (" + from.type + ")"},
                     "refers to #" + std::to_string(r.to) + ", which the file does not define");
  }
}

}  // namespace loom
