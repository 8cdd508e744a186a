// io.cpp — point files, edit scripts and `.cells` (see dynmesh/io.hpp for the formats).
#include "dynmesh/io.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <istream>
#include <limits>
#include <iterator>
#include <numeric>
#include <optional>
#include <ostream>
#include <sstream>
#include <streambuf>
#include <system_error>
#include <utility>

#include "dynmesh/errors.hpp"
#include "io/number_text.hpp"

namespace dynmesh {
namespace {

using Kind = InputError::Kind;

/// `tok` in single quotes, its control bytes escaped (escape_control_bytes), so that binary
/// junk in a file cannot put a carriage return or a terminal escape into an error message.
std::string quoted(std::string_view tok) {
  return "'" + escape_control_bytes(tok) + "'";
}

/// How fields are separated: whitespace only (`.node`, `.cells`), or also a ',' or ';' with
/// optional whitespace around it (plain point files and edit scripts, which spreadsheets and
/// CSV exports write).
enum class Separators { Whitespace, Lists };

/// Reads a file line by line, skips a UTF-8 byte order mark at its start, strips comments
/// ('#' to the end of the line) and splits the rest into fields. Keeps the current 1-based
/// line number for error messages.
class LineReader {
 public:
  LineReader(std::istream& in, const std::string& name, Separators separators = Separators::Whitespace)
      : in_(in), name_(name), separators_(separators) {}

  /// The fields of the next line that has any (blank and comment-only lines are skipped).
  /// With comments = false, '#' is an ordinary character and blank lines are returned too
  /// (used for the strict `.cells` reader). False at the end of the input.
  bool next(std::vector<std::string_view>& fields, bool comments = true) {
    errno = 0;
    while (std::getline(in_, buf_)) {
      ++line_;
      if (line_ == 1 && buf_.starts_with(kBom)) buf_.erase(0, kBom.size());  // editors on Windows
      if (!buf_.empty() && buf_.back() == '\r') buf_.pop_back();  // CRLF files
      std::string_view text = buf_;
      if (comments) {
        if (const auto hash = text.find('#'); hash != std::string_view::npos) text = text.substr(0, hash);
      }
      if (separators_ == Separators::Lists)
        split_lists(text, fields);
      else
        split(text, fields);
      if (!fields.empty() || !comments) return true;
    }
    if (in_.bad()) fail(Kind::Io, std::string("read error") + (errno ? std::string(": ") + std::strerror(errno) : ""));
    return false;
  }

  const std::string& raw_line() const noexcept { return buf_; }
  std::size_t line() const noexcept { return line_; }
  const std::string& name() const noexcept { return name_; }

  [[noreturn]] void fail(Kind kind, const std::string& text) const { throw InputError(kind, text, name_, line_); }
  [[noreturn]] void fail_at(Kind kind, const std::string& text, std::size_t line) const {
    throw InputError(kind, text, name_, line);
  }

  /// A coordinate: a finite decimal number.
  double coordinate(std::string_view tok) const {
    const double v = number(tok);
    if (!std::isfinite(v)) fail(Kind::NotFinite, "NaN or infinite coordinate " + quoted(tok));
    return v;
  }

  /// Any decimal number (NaN and infinity allowed: attributes are ignored anyway).
  double number(std::string_view tok) const {
    std::string_view t = tok;
    if (!t.empty() && t.front() == '+') {
      t.remove_prefix(1);
      if (!t.empty() && (t.front() == '+' || t.front() == '-')) fail(Kind::Malformed, "malformed number " + quoted(tok));
    }
    double v = 0;
    const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v, std::chars_format::general);
    if (ec == std::errc::invalid_argument || ptr != t.data() + t.size())
      fail(Kind::Malformed, "malformed number " + quoted(tok));
    if (ec == std::errc::result_out_of_range) {
      if (overflows(t)) fail(Kind::NotFinite, "number " + quoted(tok) + " is infinite in double precision");
      v = t.front() == '-' ? -0.0 : 0.0;  // underflow: the correctly rounded value is ±0
    }
    return v;
  }

  long long integer(std::string_view tok) const {
    std::string_view t = tok;
    if (!t.empty() && t.front() == '+') {
      t.remove_prefix(1);
      if (t.empty() || t.front() == '+' || t.front() == '-') fail(Kind::Malformed, "malformed integer " + quoted(tok));
    }
    long long v = 0;
    const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (ec != std::errc{} || ptr != t.data() + t.size()) fail(Kind::Malformed, "malformed integer " + quoted(tok));
    return v;
  }

  /// With Separators::Lists: the separators after fields first .. first + count − 1 (those
  /// the line has) must be all whitespace or all ',' / ';'. A mix is most likely a decimal
  /// comma ("1,5 2" is not the point (1, 5)), so it is an error naming the token.
  void require_one_separator_kind(const std::vector<std::string_view>& fields, std::size_t first,
                                  std::size_t count) const {
    std::size_t listed = 0, spaced = 0, first_listed = 0;
    for (std::size_t k = first; k < std::min(listed_.size(), first + count); ++k) {
      if (listed_[k] && listed++ == 0) first_listed = k;
      spaced += !listed_[k];
    }
    if (listed == 0 || spaced == 0) return;
    // The whitespace-delimited token around that ',' or ';' (e.g. "1,5").
    const std::string_view text = buf_;
    const auto field_end = static_cast<std::size_t>(fields[first_listed].data() - text.data()) +
                           fields[first_listed].size();
    const std::size_t sep = text.find_first_of(",;", field_end);
    const std::size_t before = text.find_last_of(kSpace, sep);
    const std::size_t from = before == std::string_view::npos ? 0 : before + 1;
    const std::size_t to = std::min(text.find_first_of(kSpace, sep), text.size());
    fail(Kind::Malformed, "malformed number " + quoted(text.substr(from, to - from)) +
                              ": separate the coordinates by whitespace alone or by ',' or ';' throughout the "
                              "line (a decimal comma?)");
  }

 private:
  static constexpr std::string_view kBom = "\xEF\xBB\xBF";
  static constexpr std::string_view kSpace = " \t\r\v\f";

  static void split(std::string_view text, std::vector<std::string_view>& fields) {
    fields.clear();
    std::size_t i = 0;
    while (true) {
      i = text.find_first_not_of(kSpace, i);
      if (i == std::string_view::npos) break;
      std::size_t j = text.find_first_of(kSpace, i);
      if (j == std::string_view::npos) j = text.size();
      fields.push_back(text.substr(i, j - i));
      i = j;
    }
  }

  /// Splits on whitespace and on ',' / ';' (whitespace around them allowed); listed_[k] says
  /// whether a ',' or ';' separates field k from field k + 1. An empty field (",," or a ','
  /// at either end) is an error.
  void split_lists(std::string_view text, std::vector<std::string_view>& fields) {
    constexpr std::string_view kSeparators = " \t\r\v\f,;";
    auto is_list = [](char c) { return c == ',' || c == ';'; };
    auto empty_field = [&] { fail(Kind::Malformed, "empty field: a ',' or ';' without a number on one side"); };
    fields.clear();
    listed_.clear();
    std::size_t i = text.find_first_not_of(kSpace);
    if (i == std::string_view::npos) return;
    if (is_list(text[i])) empty_field();
    while (true) {
      std::size_t j = text.find_first_of(kSeparators, i);
      if (j == std::string_view::npos) j = text.size();
      fields.push_back(text.substr(i, j - i));
      std::size_t k = text.find_first_not_of(kSpace, j);
      if (k == std::string_view::npos) break;
      const bool listed = is_list(text[k]);
      if (listed) {
        k = text.find_first_not_of(kSpace, k + 1);
        if (k == std::string_view::npos || is_list(text[k])) empty_field();
      }
      listed_.push_back(listed);
      i = k;
    }
  }

  /// For a syntactically valid decimal that from_chars found out of range: is its magnitude
  /// ≥ 1 (overflow) rather than < 1 (underflow)? Value = 0.DDD × 10^(P + E).
  static bool overflows(std::string_view t) {
    if (!t.empty() && (t.front() == '-' || t.front() == '+')) t.remove_prefix(1);
    long long p = 0;
    bool nonzero = false, after_point = false;
    std::size_t i = 0;
    for (; i < t.size() && t[i] != 'e' && t[i] != 'E'; ++i) {
      const char c = t[i];
      if (c == '.') {
        after_point = true;
      } else if (!nonzero) {
        if (c != '0') {
          nonzero = true;
          if (!after_point) p = 1;
        } else if (after_point) {
          --p;
        }
      } else if (!after_point) {
        ++p;
      }
    }
    long long e = 0;
    if (i < t.size()) {
      ++i;
      bool neg = false;
      if (i < t.size() && (t[i] == '+' || t[i] == '-')) neg = t[i++] == '-';
      for (; i < t.size(); ++i) e = std::min<long long>(e * 10 + (t[i] - '0'), 1'000'000'000);
      if (neg) e = -e;
    }
    return p + e > 0;
  }

  std::istream& in_;
  const std::string& name_;
  Separators separators_;
  std::string buf_;
  std::size_t line_ = 0;
  std::vector<bool> listed_;  // Lists: listed_[k] iff a ',' or ';' follows field k
};

std::ifstream open_input(const std::string& path) {
  // A directory opens as a stream on Linux and only fails at the first read; say so up front.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(Kind::Io, "cannot read: is a directory", path);
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;  // the OS reason of the failed open (libstdc++ opens with fopen)
    throw InputError(Kind::Io, std::string("cannot open file: ") + (err ? std::strerror(err) : "unknown reason"), path);
  }
  return in;
}

template <std::size_t d>
std::string box_string(const Box<d>& box) {
  std::string s = "origin (";
  for (std::size_t a = 0; a < d; ++a) {
    if (a) s += ", ";
    s += format_exact(box.origin[a]);
  }
  return s + "), side " + format_exact(box.side);
}

}  // namespace

std::string escape_control_bytes(std::string_view text) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto b = static_cast<unsigned char>(c);
    if (b < 0x20 || b == 0x7f) {
      out += "\\x";
      out += kHex[b >> 4];
      out += kHex[b & 15];
    } else {
      out += c;
    }
  }
  return out;
}

namespace {

/// Does `path` end in `ext` (lower case), in any letter case?
bool has_extension(std::string_view path, std::string_view ext) noexcept {
  if (path.size() < ext.size()) return false;
  const std::string_view tail = path.substr(path.size() - ext.size());
  for (std::size_t i = 0; i < ext.size(); ++i) {
    char c = tail[i];
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    if (c != ext[i]) return false;
  }
  return true;
}

}  // namespace

PointFormat format_for_path(std::string_view path) noexcept {
  if (has_extension(path, ".node")) return PointFormat::Node;
  if (has_extension(path, ".poly")) return PointFormat::Poly;
  if (has_extension(path, ".ele")) return PointFormat::Ele;
  return PointFormat::Plain;
}

// ---------------------------------------------------------------------------------------
// .node

namespace {

struct NodeHeader {
  long long count = 0;
  long long dim = 0;  // 0: omitted
  long long attributes = 0;
  long long markers = 0;
  std::size_t line = 0;
};

NodeHeader read_node_header(LineReader& r) {
  std::vector<std::string_view> f;
  if (!r.next(f)) r.fail(Kind::Malformed, "empty .node file: the header line is missing");
  if (f.size() > 4)
    r.fail(Kind::Malformed, ".node header has " + std::to_string(f.size()) +
                                " fields; expected <#vertices> <dimension> <#attributes> <#boundary markers>");
  NodeHeader h;
  h.line = r.line();
  h.count = r.integer(f[0]);
  if (h.count < 0) r.fail(Kind::Malformed, "negative vertex count " + quoted(f[0]));
  if (f.size() > 1) {
    h.dim = r.integer(f[1]);
    if (h.dim != 2 && h.dim != 3) r.fail(Kind::Malformed, "dimension must be 2 or 3, got " + quoted(f[1]));
  }
  if (f.size() > 2) {
    h.attributes = r.integer(f[2]);
    if (h.attributes < 0) r.fail(Kind::Malformed, "negative number of attributes " + quoted(f[2]));
  }
  if (f.size() > 3) {
    h.markers = r.integer(f[3]);
    if (h.markers != 0 && h.markers != 1)
      r.fail(Kind::Malformed, "number of boundary markers must be 0 or 1, got " + quoted(f[3]));
  }
  return h;
}

}  // namespace

int node_file_dimension(const std::string& path) {
  std::ifstream in = open_input(path);
  LineReader r(in, path);
  return static_cast<int>(read_node_header(r).dim);
}

namespace {

/// The vertex lines after a `.node` or `.poly` header: exactly h.count of them when
/// `rest_of_file` is false (a .poly file goes on with its segments), else every remaining
/// line, which must number h.count.
template <std::size_t d>
void read_vertex_lines(LineReader& r, const NodeHeader& h, PointFile<d>& out, bool rest_of_file) {
  const auto reserve = static_cast<std::size_t>(std::min<long long>(h.count, 1 << 20));
  out.points.reserve(reserve);
  out.lines.reserve(reserve);
  const auto count = static_cast<std::size_t>(h.count);
  long long base = 0;
  std::vector<std::string_view> f;
  while (out.points.size() < count || rest_of_file) {
    if (!r.next(f)) break;
    const std::size_t k = out.points.size();
    if (k == count)
      r.fail(Kind::Count, "more vertices than the " + std::to_string(count) + " announced in the header (line " +
                              std::to_string(h.line) + ")");
    if (f.size() < 1 + d)
      r.fail(Kind::Count, "vertex line has " + std::to_string(f.size()) + " field(s); expected <vertex#> and " +
                              std::to_string(d) + " coordinates");
    const long long id = r.integer(f[0]);
    if (k == 0) {
      if (id != 0 && id != 1) r.fail(Kind::Malformed, "vertex numbering must start at 0 or 1, got " + quoted(f[0]));
      base = id;
    } else if (id != base + static_cast<long long>(k)) {
      r.fail(Kind::Malformed, "vertex number " + quoted(f[0]) + " out of sequence; expected " +
                                  std::to_string(base + static_cast<long long>(k)));
    }
    Point<d> p;
    for (std::size_t a = 0; a < d; ++a) p[a] = r.coordinate(f[1 + a]);
    // Attributes and the marker are read (they must be numbers) and ignored.
    const std::size_t extra = static_cast<std::size_t>(h.attributes);
    for (std::size_t j = 0; j < extra && 1 + d + j < f.size(); ++j) (void)r.number(f[1 + d + j]);
    if (h.markers == 1 && 1 + d + extra < f.size()) (void)r.integer(f[1 + d + extra]);
    out.points.push_back(p);
    out.lines.push_back(r.line());
  }
  if (out.points.size() != count)
    r.fail_at(Kind::Count, "the header announces " + std::to_string(count) + " vertices but the file has " +
                               std::to_string(out.points.size()),
              h.line);
}

template <std::size_t d>
void require_header_dimension(const LineReader& r, const NodeHeader& h, const char* what) {
  if (h.dim != 0 && static_cast<std::size_t>(h.dim) != d)
    r.fail_at(Kind::Malformed, std::string(what) + " header announces dimension " + std::to_string(h.dim) + " but " +
                                   std::to_string(d) + "-dimensional points were requested",
              h.line);
}

}  // namespace

template <std::size_t d>
PointFile<d> read_node(std::istream& in, const std::string& name) {
  LineReader r(in, name);
  const NodeHeader h = read_node_header(r);
  require_header_dimension<d>(r, h, ".node");
  PointFile<d> out;
  out.name = name;
  read_vertex_lines<d>(r, h, out, /*rest_of_file=*/true);
  return out;
}

// ---------------------------------------------------------------------------------------
// .poly

template <std::size_t d>
PointFile<d> read_poly(std::istream& in, const std::string& name) {
  LineReader r(in, name);
  const NodeHeader h = read_node_header(r);
  require_header_dimension<d>(r, h, ".poly");
  if (h.count == 0)
    r.fail_at(Kind::Unsupported,
              "this .poly file lists no vertices (Triangle then takes them from the .node file of the same name): "
              "give that .node file instead",
              h.line);
  PointFile<d> out;
  out.name = name;
  read_vertex_lines<d>(r, h, out, /*rest_of_file=*/false);
  // Then `<#segments> [<#markers>]` (TetGen: facets), `<#holes>` and, optionally,
  // `<#regions>`, each followed by its lines. Only empty lists can be honoured.
  const char* const lists[] = {d == 2 ? "segments" : "facets", "holes", "regional attributes"};
  std::vector<std::string_view> f;
  for (const char* what : lists) {
    if (!r.next(f)) {
      if (what == lists[2]) break;  // the region list is optional
      r.fail(Kind::Malformed, std::string("the .poly file ends before its number of ") + what);
    }
    const long long n = r.integer(f[0]);
    if (n < 0) r.fail(Kind::Malformed, std::string("negative number of ") + what + " " + quoted(f[0]));
    if (n > 0)
      r.fail(Kind::Unsupported, std::string("this .poly file has ") + std::to_string(n) + " " + what +
                                    ": segments and holes are not supported yet (dynmesh meshes the vertices "
                                    "in their box)");
  }
  if (r.next(f)) r.fail(Kind::Malformed, "unexpected line after the .poly file's lists");
  return out;
}

// ---------------------------------------------------------------------------------------
// plain text

namespace {

/// Does `tok` parse as a number (what from_chars accepts, with an optional leading '+')?
bool is_number(std::string_view tok) {
  if (!tok.empty() && tok.front() == '+') tok.remove_prefix(1);
  double v = 0;
  const auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v, std::chars_format::general);
  return ec != std::errc::invalid_argument && ptr == tok.data() + tok.size() && !tok.empty();
}

/// Watches the lines of a plain-text file for the shape of Triangle's and TetGen's formats:
/// a header line starting with two whole numbers (by value: <#items> <2|3|4|6> ...), then
/// rows numbered consecutively from 0 or 1, as many as the header announces (or to the end
/// of the file), each with at least three fields. Only the first fields decide, so that the
/// verdict stays the same for the points written back with just their coordinates. Such a file is a `.node`, `.ele` or `.poly` under
/// another name, and reading its numbers as coordinates would mesh nonsense.
class NumberedRows {
 public:
  void header(const std::vector<std::string_view>& f) {
    long long v[2] = {};
    if (f.size() < 2 || !whole(f[0], v[0]) || !whole(f[1], v[1])) return;
    if (v[0] < 1 || (v[1] != 2 && v[1] != 3 && v[1] != 4 && v[1] != 6)) return;
    count_ = v[0];
    per_row_ = v[1];
    candidate_ = true;
  }

  void row(const std::vector<std::string_view>& f) {
    if (settled()) return;
    long long id = 0;
    if (f.size() < 3 || !whole(f[0], id) || (rows_ == 0 ? id != 0 && id != 1 : id != base_ + rows_)) {
      candidate_ = false;
      return;
    }
    if (rows_ == 0) base_ = id;
    // Triangles: every field a whole number, 1 + <nodes per triangle> of them at least.
    bool ints = f.size() >= static_cast<std::size_t>(1 + per_row_);
    for (std::size_t k = 1; k < f.size() && ints; ++k) ints = whole(f[k], id);
    all_integer_ = all_integer_ && ints;
    ++rows_;
  }

  /// No later row can change the verdict: the file is no candidate, or every announced row
  /// has been seen.
  bool settled() const noexcept { return !candidate_ || rows_ >= count_; }

  /// After an error (or a first line that sets no dimension): feeds the rows that follow
  /// until the verdict is settled, then throws as check() does. A line too broken to split
  /// ends the look (the caller's own error is then the one reported).
  void check_after_error(LineReader& r, std::size_t header_line) {
    std::vector<std::string_view> f;
    bool at_end = false;
    try {
      while (!settled()) {
        if (!r.next(f)) {
          at_end = true;
          break;
        }
        row(f);
      }
    } catch (const InputError&) {
      return;
    }
    check(r, header_line, at_end);
  }

  /// Throws InputError(Unsupported) naming the likely format when the file had the shape:
  /// at least two numbered rows, and every row announced unless the file ended first (a
  /// `.poly` goes on with other lists, which may fail to read as points). One row is too
  /// little evidence: "1 2" then "1,5 2" is a decimal comma, not a one-vertex file.
  void check(const LineReader& r, std::size_t header_line, bool at_end) const {
    if (!candidate_ || rows_ < 2 || (rows_ < count_ && !at_end)) return;
    const bool ele = all_integer_ && (per_row_ == 3 || per_row_ == 4 || per_row_ == 6);
    if (ele)
      r.fail_at(Kind::Unsupported,
                "this looks like Triangle's .ele format (a header line, then numbered triangles of vertex numbers), "
                "not points: give the .node file of its vertices",
                header_line);
    r.fail_at(Kind::Unsupported,
              "this looks like Triangle's .node format (a header line, then numbered vertices), not plain-text "
              "points: name the file '.node' (or '.poly') to read its vertices",
              header_line);
  }

 private:
  /// A number whose value is a whole number ("3", "3.0", "3e0"): decided by value, not by
  /// spelling, so that points written back with %.17g get the same verdict.
  static bool whole(std::string_view tok, long long& v) {
    if (!tok.empty() && tok.front() == '+') tok.remove_prefix(1);
    double x = 0;
    const auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), x, std::chars_format::general);
    if (ec != std::errc{} || ptr != tok.data() + tok.size() || !(std::fabs(x) < 0x1p53) || x != std::floor(x))
      return false;
    v = static_cast<long long>(x);
    return true;
  }
  bool candidate_ = false, all_integer_ = true;
  long long count_ = 0, per_row_ = 0, rows_ = 0, base_ = 0;
};

}  // namespace

template <std::size_t d>
PointFile<d> read_plain(std::istream& in, const std::string& name, Columns columns) {
  LineReader r(in, name, Separators::Lists);
  PointFile<d> out;
  out.name = name;
  NumberedRows numbered;
  std::size_t first_line = 0;
  std::vector<std::string_view> f;
  try {
  while (r.next(f)) {
    if (first_line == 0) {
      first_line = r.line();
      // A first line without a single number is a column header ("x,y", "easting northing").
      if (std::none_of(f.begin(), f.end(), is_number)) {
        out.header_line = r.line();
        out.header = escape_control_bytes(r.raw_line());
        continue;
      }
    }
    if (out.points.empty())
      numbered.header(f);
    else
      numbered.row(f);
    Point<d> p;
    if (columns == Columns::Exactly) {
      // The dimension is the file's: every field is a coordinate, as many as on the first line.
      r.require_one_separator_kind(f, 0, f.size());
      for (std::size_t a = 0; a < f.size(); ++a) {
        const double v = r.coordinate(f[a]);
        if (a < d) p[a] = v;
      }
      if (f.size() != d)
        r.fail(Kind::Count, "expected " + std::to_string(d) + " numbers as on line " +
                                std::to_string(out.lines.empty() ? r.line() : out.lines.front()) +
                                " (the first line of numbers sets the file's dimension), found " +
                                std::to_string(f.size()) + "; --dim 2 or --dim 3 reads the first 2 or 3 numbers of "
                                                           "each line and ignores further columns");
    } else {
      r.require_one_separator_kind(f, 0, d);  // up to the separator after the last coordinate
      if (f.size() < d)
        r.fail(Kind::Count, "expected " + std::to_string(d) + " coordinates, found " + std::to_string(f.size()));
      for (std::size_t a = 0; a < d; ++a) p[a] = r.coordinate(f[a]);
    }
    out.points.push_back(p);
    out.lines.push_back(r.line());
  }
  } catch (const InputError&) {
    // A line after a numbered list (a .poly's segment count, say) is no point: say what the
    // file looks like rather than what its later line lacks.
    if (!out.lines.empty()) numbered.check_after_error(r, out.lines.front());
    throw;
  }
  if (!out.lines.empty()) numbered.check(r, out.lines.front(), /*at_end=*/true);
  return out;
}

template <std::size_t d>
PointFile<d> read_points(std::istream& in, const std::string& name, PointFormat format, Columns columns) {
  if (format == PointFormat::Auto) format = format_for_path(name);
  switch (format) {
    case PointFormat::Node: return read_node<d>(in, name);
    case PointFormat::Poly: return read_poly<d>(in, name);
    case PointFormat::Ele:
      throw InputError(Kind::Unsupported,
                       "a Triangle .ele file holds triangles (vertex numbers), not points: give the .node file of "
                       "its vertices",
                       name);
    default: return read_plain<d>(in, name, columns);
  }
}

namespace {

/// Standard input or a pipe (any path that is not a regular file) whose first lines
/// point_file_shape looked at: read whole then, because such an input cannot be read twice,
/// and kept here until read_points_file reads it as points (and releases it).
struct ReadAhead {
  std::string path;
  std::string text;
  bool held = false;
};
ReadAhead& read_ahead() {
  static ReadAhead input;
  return input;
}

/// Can `path` be opened again to read it a second time? Standard input cannot, nor can a
/// FIFO or a process substitution; a path that does not exist counts as one (its reader
/// reports it).
bool rereadable(const std::string& path) {
  if (path == kStandardInput) return false;
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  return ec || !std::filesystem::exists(status) || std::filesystem::is_regular_file(status) ||
         std::filesystem::is_directory(status);
}

/// The whole text of a path that cannot be read twice, read now and held for
/// read_points_file.
const std::string& read_ahead_text(const std::string& path) {
  ReadAhead& input = read_ahead();
  if (input.held && input.path == path) return input.text;
  std::string text;
  if (path == kStandardInput) {
    text.assign(std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>());
    if (std::cin.bad()) throw InputError(Kind::Io, "read error", kStandardInputName);
  } else {
    std::ifstream in = open_input(path);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (in.bad()) throw InputError(Kind::Io, "read error", path);
  }
  input = ReadAhead{path, std::move(text), true};
  return input.text;
}

/// A read-only stream buffer over text that stays alive and unchanged while it is read.
class TextBuffer : public std::streambuf {
 public:
  explicit TextBuffer(std::string_view text) {
    char* p = const_cast<char*>(text.data());  // the get area only: never written through
    setg(p, p, p + text.size());
  }
};

}  // namespace

template <std::size_t d>
PointFile<d> read_points_file(const std::string& path, PointFormat format, Columns columns) {
  const bool standard_input = path == kStandardInput;
  const std::string& name = standard_input ? kStandardInputName : path;
  if (standard_input && format == PointFormat::Auto) format = PointFormat::Plain;
  ReadAhead& input = read_ahead();
  if (input.held && input.path == path) {
    // Read as points once, then released, as the pipe itself was consumed.
    const std::string text = std::move(input.text);
    input = ReadAhead{};
    TextBuffer buffer(text);
    std::istream in(&buffer);
    return read_points<d>(in, name, format, columns);
  }
  if (standard_input) return read_points<d>(std::cin, name, format, columns);
  std::ifstream in = open_input(path);
  return read_points<d>(in, path, format, columns);
}

PointFileShape point_file_shape(const std::string& path, int dim) {
  if (dim != 0) return {dim, Columns::AtLeast};
  const bool standard_input = path == kStandardInput;
  const PointFormat format = standard_input ? PointFormat::Plain : format_for_path(path);
  if (format == PointFormat::Ele) return {2, Columns::AtLeast};  // refused when read
  // A pipe is read whole now and held for read_points_file; a regular file is opened again.
  const bool once = !rereadable(path);
  std::ifstream file;
  std::optional<TextBuffer> buffer;
  std::optional<std::istream> held;
  if (once) {
    buffer.emplace(read_ahead_text(path));
    held.emplace(&*buffer);
  } else {
    file = open_input(path);
  }
  std::istream& in = once ? *held : static_cast<std::istream&>(file);
  const std::string& name = standard_input ? kStandardInputName : path;
  if (format == PointFormat::Node || format == PointFormat::Poly) {
    LineReader r(in, name);
    return {read_node_header(r).dim == 3 ? 3 : 2, Columns::AtLeast};
  }
  LineReader r(in, name, Separators::Lists);
  std::vector<std::string_view> f;
  bool first = true;
  while (r.next(f)) {
    // A first line without a single number is a column header, as read_plain skips it.
    if (std::exchange(first, false) && std::none_of(f.begin(), f.end(), is_number)) continue;
    r.require_one_separator_kind(f, 0, f.size());  // a decimal comma is no extra column
    if (f.size() == 2 || f.size() == 3) return {static_cast<int>(f.size()), Columns::Exactly};
    const std::size_t line = r.line();
    NumberedRows numbered;
    numbered.header(f);
    numbered.check_after_error(r, line);
    r.fail_at(Kind::Count,
              "the first line of numbers holds " + std::to_string(f.size()) +
                  " numbers, and without --dim their count is the dimension of plain-text points, 2 or 3: pass "
                  "--dim 2 or --dim 3 to read the first 2 or 3 numbers of each line and ignore further columns",
              line);
  }
  return {2, Columns::Exactly};
}

template <std::size_t d>
std::vector<Position<d>> locate_points(const PointFile<d>& file, const Box<d>& box) {
  validate_box(box);
  const std::size_t n = file.points.size();
  auto line_of = [&](std::size_t i) { return i < file.lines.size() ? file.lines[i] : 0; };
  std::vector<Position<d>> q(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Point<d>& p = file.points[i];
    for (std::size_t a = 0; a < d; ++a)
      if (!std::isfinite(p[a]))
        throw InputError(Kind::NotFinite, "NaN or infinite coordinate in point " + to_string<d>(p), file.name,
                         line_of(i))
            .with_points({i});
    const auto located = try_locate(box, p);
    if (!located)
      throw InputError(Kind::OutsideBox,
                       "point " + to_string<d>(p) + " is outside the domain box (" + box_string(box) + ")",
                       file.name, line_of(i))
          .with_points({i});
    q[i] = *located;
  }
  // Duplicates: equal located positions. Report the first point, in file order, that repeats
  // an earlier one. Sorted by (q, index), each group of equal positions starts with its
  // smallest index, and its second member is the group's first repeat: one pass, remembering
  // where the current group starts, finds them all (O(n log n) with any number of copies).
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return q[a] != q[b] ? q[a] < q[b] : a < b;
  });
  std::size_t dup = n, orig = n;
  for (std::size_t k = 1, group = 0; k < n; ++k) {
    if (q[order[k]] != q[order[k - 1]]) {
      group = k;
      continue;
    }
    if (k == group + 1 && order[k] < dup) {
      dup = order[k];
      orig = order[group];
    }
  }
  if (dup == n) return q;
  if (file.points[dup] == file.points[orig])
    throw InputError(Kind::Duplicate,
                     "duplicate point " + to_string<d>(file.points[dup]) +
                         ": it has the same located position as the point on line " + std::to_string(line_of(orig)) +
                         " " + to_string<d>(file.points[orig]),
                     file.name, line_of(dup))
        .with_points({orig, dup});
  // Different points that the grid cannot tell apart: the spread is beyond the resolution.
  throw InputError(Kind::Resolution,
                   "point " + to_string<d>(file.points[dup]) + " has the same located position as the point on line " +
                       std::to_string(line_of(orig)) + " " + to_string<d>(file.points[orig]) + ": " +
                       spread_text<d>(box, file.points[dup], file.points[orig]) + " exceeds the resolution of 2^52",
                   file.name, line_of(dup))
      .with_points({orig, dup});
}

template <std::size_t d>
std::size_t drop_duplicate_points(PointFile<d>& file) {
  const std::size_t n = file.points.size();
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  // Stable by index within equal coordinates, so the first copy in file order is kept.
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return file.points[a] != file.points[b] ? file.points[a] < file.points[b] : a < b;
  });
  std::vector<bool> drop(n, false);
  for (std::size_t k = 1; k < n; ++k) drop[order[k]] = file.points[order[k]] == file.points[order[k - 1]];
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (drop[i]) continue;
    file.points[kept] = file.points[i];
    if (i < file.lines.size()) file.lines[kept] = file.lines[i];
    ++kept;
  }
  file.points.resize(kept);
  if (file.lines.size() > kept) file.lines.resize(kept);
  return n - kept;
}

// ---------------------------------------------------------------------------------------
// edit scripts

template <std::size_t d>
EditScript<d> read_edits(std::istream& in, const std::string& name) {
  LineReader r(in, name, Separators::Lists);
  EditScript<d> out;
  out.name = name;
  std::vector<std::string_view> f;
  while (r.next(f)) {
    r.require_one_separator_kind(f, 1, d);  // the sign stands apart; the coordinates agree
    EditOp op;
    if (f[0] == "+")
      op = EditOp::Insert;
    else if (f[0] == "-")
      op = EditOp::Delete;
    else
      r.fail(Kind::Malformed, "an edit starts with '+' or '-' as a field of its own, got " + quoted(f[0]));
    if (f.size() != 1 + d)
      r.fail(Kind::Count, "an edit needs exactly " + std::to_string(d) + " coordinates (the points are " +
                              std::to_string(d) + "D), found " + std::to_string(f.size() - 1));
    Edit<d> e{op, {}};
    for (std::size_t a = 0; a < d; ++a) e.point[a] = r.coordinate(f[1 + a]);
    out.edits.push_back(e);
    out.lines.push_back(r.line());
  }
  return out;
}

template <std::size_t d>
EditScript<d> read_edits_file(const std::string& path) {
  std::ifstream in = open_input(path);
  return read_edits<d>(in, path);
}

// ---------------------------------------------------------------------------------------
// .cells

template <std::size_t d>
std::string format_cells_header(const Box<d>& box) {
  std::string s = "# dynmesh cells v1\n# dim ";
  detail::append_number(s, d);
  s += "\n# box";
  for (std::size_t a = 0; a < d; ++a) {
    s += ' ';
    s += format_exact(box.origin[a]);
  }
  s += ' ';
  s += format_exact(box.side);
  s += '\n';
  return s;
}

template <std::size_t d>
void append_cells_lines(std::string& s, std::span<const Leaf<d>> sorted) {
  s.reserve(s.size() + sorted.size() * (8 + 14 * d));
  for (const Leaf<d>& leaf : sorted) {
    detail::append_number(s, static_cast<std::size_t>(leaf.cell.level));
    for (std::size_t a = 0; a < d; ++a) {
      s += ' ';
      detail::append_number(s, leaf.cell.index[a]);
    }
    s += ' ';
    detail::append_number(s, leaf.npoints);
    s += '\n';
  }
}

template <std::size_t d>
std::string format_cells(const Box<d>& box, std::span<const Leaf<d>> leaves) {
  std::vector<Leaf<d>> sorted(leaves.begin(), leaves.end());
  std::sort(sorted.begin(), sorted.end(), [](const Leaf<d>& a, const Leaf<d>& b) { return a.cell < b.cell; });
  std::string s = format_cells_header<d>(box);
  append_cells_lines<d>(s, sorted);
  return s;
}

template <std::size_t d>
void write_cells(std::ostream& out, const Box<d>& box, std::span<const Leaf<d>> leaves) {
  const std::string s = format_cells<d>(box, leaves);
  out.write(s.data(), static_cast<std::streamsize>(s.size()));
}

template <std::size_t d>
void write_cells_file(const std::string& path, const Box<d>& box, std::span<const Leaf<d>> leaves) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw InputError(Kind::Io, std::string("cannot open file for writing: ") + std::strerror(errno), path);
  write_cells<d>(out, box, leaves);
  out.flush();
  if (!out) throw InputError(Kind::Io, "write error", path);
}

template <std::size_t d>
CellsFile<d> read_cells(std::istream& in, const std::string& name) {
  LineReader r(in, name);
  std::vector<std::string_view> f;
  auto header = [&](std::string_view what) {
    if (!r.next(f, false)) r.fail(Kind::Malformed, "missing header line " + quoted(what));
  };
  header("# dynmesh cells v1");
  if (r.raw_line() != "# dynmesh cells v1") r.fail(Kind::Malformed, "expected '# dynmesh cells v1'");
  header("# dim D");
  if (f.size() != 3 || f[0] != "#" || f[1] != "dim") r.fail(Kind::Malformed, "expected '# dim D'");
  if (r.integer(f[2]) != static_cast<long long>(d))
    r.fail(Kind::Malformed, "file has dimension " + std::string(f[2]) + ", expected " + std::to_string(d));
  header("# box ...");
  if (f.size() != d + 3 || f[0] != "#" || f[1] != "box")
    r.fail(Kind::Malformed, "expected '# box' followed by " + std::to_string(d + 1) + " numbers");
  CellsFile<d> out;
  for (std::size_t a = 0; a < d; ++a) out.box.origin[a] = r.coordinate(f[2 + a]);
  out.box.side = r.coordinate(f[2 + d]);
  try {
    validate_box(out.box);
  } catch (const InputError& e) {
    r.fail(e.kind(), e.text());
  }
  while (r.next(f, false)) {
    if (f.size() != d + 2)
      r.fail(Kind::Count, "a leaf line has " + std::to_string(d + 2) + " integers, found " + std::to_string(f.size()) +
                              " fields");
    Leaf<d> leaf;
    const long long level = r.integer(f[0]);
    if (level < 0 || level > kMaxLevel) r.fail(Kind::Malformed, "level " + quoted(f[0]) + " outside [0, 52]");
    leaf.cell.level = static_cast<int>(level);
    for (std::size_t a = 0; a < d; ++a) {
      const long long i = r.integer(f[1 + a]);
      if (i < 0 || static_cast<std::uint64_t>(i) >= cells_per_axis(leaf.cell.level))
        r.fail(Kind::Malformed, "index " + quoted(f[1 + a]) + " outside [0, 2^level)");
      leaf.cell.index[a] = static_cast<std::uint64_t>(i);
    }
    const long long np = r.integer(f[1 + d]);
    if (np < 0 || np > std::numeric_limits<std::uint32_t>::max())
      r.fail(Kind::Malformed, "bad point count " + quoted(f[1 + d]));
    leaf.npoints = static_cast<std::uint32_t>(np);
    if (!out.leaves.empty() && !(out.leaves.back().cell < leaf.cell))
      r.fail(Kind::Malformed, "leaves are not sorted strictly by (level, i, j, k)");
    out.leaves.push_back(leaf);
  }
  return out;
}

template <std::size_t d>
CellsFile<d> read_cells_file(const std::string& path) {
  std::ifstream in = open_input(path);
  return read_cells<d>(in, path);
}

#define DYNMESH_INSTANTIATE_IO(D)                                                                    \
  template PointFile<D> read_node<D>(std::istream&, const std::string&);                             \
  template PointFile<D> read_plain<D>(std::istream&, const std::string&, Columns);                   \
  template PointFile<D> read_poly<D>(std::istream&, const std::string&);                             \
  template PointFile<D> read_points<D>(std::istream&, const std::string&, PointFormat, Columns);     \
  template PointFile<D> read_points_file<D>(const std::string&, PointFormat, Columns);               \
  template std::vector<Position<D>> locate_points<D>(const PointFile<D>&, const Box<D>&);            \
  template std::size_t drop_duplicate_points<D>(PointFile<D>&);                                      \
  template EditScript<D> read_edits<D>(std::istream&, const std::string&);                           \
  template EditScript<D> read_edits_file<D>(const std::string&);                                     \
  template std::string format_cells<D>(const Box<D>&, std::span<const Leaf<D>>);                     \
  template std::string format_cells_header<D>(const Box<D>&);                                          \
  template void append_cells_lines<D>(std::string&, std::span<const Leaf<D>>);                        \
  template void write_cells<D>(std::ostream&, const Box<D>&, std::span<const Leaf<D>>);              \
  template void write_cells_file<D>(const std::string&, const Box<D>&, std::span<const Leaf<D>>);    \
  template CellsFile<D> read_cells<D>(std::istream&, const std::string&);                            \
  template CellsFile<D> read_cells_file<D>(const std::string&);

DYNMESH_INSTANTIATE_IO(2)
DYNMESH_INSTANTIATE_IO(3)

#undef DYNMESH_INSTANTIATE_IO

}  // namespace dynmesh
