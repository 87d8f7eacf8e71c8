#pragma once
/// Errors that loom reports to users. A bad input (file, element, value) is an
/// InputError; the command line maps it to exit status 2 and prints what() on stderr.
/// Broken preconditions inside the library are std::logic_error (programming errors).

#include <stdexcept>
#include <string>

namespace loom {

/// Where in an input something is wrong: file path, 1-based line (0 = unknown) and the
/// element or key that holds the bad value (may be empty).
struct SourceLocation {
  std::string file;
  int line = 0;
  std::string element;
};

/// A user input is malformed or inconsistent. what() reads
/// "FILE:LINE: ELEMENT: REASON" with the parts that are known.
class InputError : public std::runtime_error {
 public:
  InputError(SourceLocation where, const std::string& reason);
  /// Where the problem was found.
  const SourceLocation& where() const { return where_; }
  /// The reason alone, without the location prefix.
  const std::string& reason() const { return reason_; }

 private:
  SourceLocation where_;
  std::string reason_;
};

/// Formats a double with enough digits to replay it exactly (17 significant digits).
std::string full_precision(double v);

}  // namespace loom
