// dynmesh/errors.hpp — the exceptions dynmesh throws.
//
// Purpose: bad input gets a clear error that names what is wrong and, when the input came
// from a file, the file and the line (docs/DESIGN.md, "Bad input": malformed files, NaN or infinite
// coordinates, duplicate points, points outside the box, deleting an absent point, spread
// beyond the resolution). Library bugs found by the invariant checkers are a different
// thing and get InvariantError.
//
//   Error          – base of everything dynmesh throws on purpose.
//   InputError     – the input is unusable; kind() says why; file()/line() say where when
//                    known (line numbers count from 1; 0 means "no line"). what() is the
//                    complete one-line message "FILE:LINE: text" (or "FILE: text", or just
//                    "text"), ready for stderr. point_indices() lists the input indices of
//                    the points involved when the thrower knows them (a duplicate pair, the
//                    pair that is too close for the resolution), so that a caller holding
//                    line numbers can name lines.
//   InvariantError – a check_invariants() found a broken contract (a bug, not bad input).
//
// Invariants: what() always contains file and line when they are known. Complexity: n/a.
// Paper: none (docs/DESIGN.md, "Bad input": bad input gets a clear error, the state stays as it was).
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace dynmesh {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class InputError : public Error {
 public:
  enum class Kind {
    Io,           // the file cannot be opened or read
    Malformed,    // a token is not a number, a line has the wrong shape, bad header
    NotFinite,    // NaN or an infinite coordinate (including decimal overflow such as 1e999)
    Count,        // the number of values or of points differs from what was announced
    Duplicate,    // two points have the same located integer position q
    OutsideBox,   // a point's q falls outside [0, 2^52) or the box itself is unusable
    Resolution,   // a level-52 cell would have to split: spread beyond 2^52
    Absent,       // deleting a point that is not in the set
    Present,      // inserting a point that is already in the set
    Empty,        // no points where some are needed (deriving a box from nothing)
    Unsupported,  // a well-formed file of a kind not read (yet): Triangle's .ele, a .poly
                  // with segments or holes, rows numbered as in Triangle's formats
  };

  InputError(Kind kind, std::string text, std::string file = {}, std::size_t line = 0)
      : Error(compose(file, line, text)),
        kind_(kind),
        text_(std::move(text)),
        file_(std::move(file)),
        line_(line) {}

  Kind kind() const noexcept { return kind_; }
  /// The message without the "FILE:LINE: " prefix.
  const std::string& text() const noexcept { return text_; }
  const std::string& file() const noexcept { return file_; }
  std::size_t line() const noexcept { return line_; }
  const std::vector<std::size_t>& point_indices() const noexcept { return points_; }
  InputError& with_points(std::vector<std::size_t> indices) {
    points_ = std::move(indices);
    return *this;
  }

  static std::string compose(std::string_view file, std::size_t line, std::string_view text) {
    std::string s;
    if (!file.empty()) {
      s += file;
      if (line != 0) {
        s += ':';
        s += std::to_string(line);
      }
      s += ": ";
    } else if (line != 0) {
      s += "line " + std::to_string(line) + ": ";
    }
    s += text;
    return s;
  }

 private:
  Kind kind_;
  std::string text_;
  std::string file_;
  std::size_t line_;
  std::vector<std::size_t> points_;
};

/// The enumerator's name ("Io", "Malformed", ...), for messages and test reports.
constexpr const char* kind_name(InputError::Kind kind) noexcept {
  using Kind = InputError::Kind;
  switch (kind) {
    case Kind::Io: return "Io";
    case Kind::Malformed: return "Malformed";
    case Kind::NotFinite: return "NotFinite";
    case Kind::Count: return "Count";
    case Kind::Duplicate: return "Duplicate";
    case Kind::OutsideBox: return "OutsideBox";
    case Kind::Resolution: return "Resolution";
    case Kind::Absent: return "Absent";
    case Kind::Present: return "Present";
    case Kind::Empty: return "Empty";
    case Kind::Unsupported: return "Unsupported";
  }
  return "?";
}

class InvariantError : public Error {
 public:
  using Error::Error;
};

}  // namespace dynmesh
