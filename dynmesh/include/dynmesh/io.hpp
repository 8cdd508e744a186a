// dynmesh/io.hpp — reading point files and edit scripts, writing and reading `.cells`.
//
// Purpose: the file formats of docs/FORMATS.md, exactly:
//   * `.node` (Triangle 2D / TetGen 3D): header `<#vertices> <dim> <#attributes> <#markers>`
//     (trailing header fields may be omitted as Triangle allows: dim defaults to the
//     requested d, the others to 0), then `<vertex#> <x> <y> [<z>] [attributes] [marker]`.
//     Numbering starts at 0 or 1 (decided by the first vertex) and must run consecutively.
//     `#` starts a comment anywhere on a line; blank lines are skipped. Attributes and the
//     marker, when present, must be numbers and are otherwise ignored; further fields are
//     ignored.
//   * `.poly` (Triangle; TetGen's in 3D): a `.node` header and vertex list, then the number
//     of segments (facets) and of holes, and optionally of regional attributes. Only the
//     vertices are read: a file whose lists are not all empty is refused (Unsupported), as
//     is one with no vertices of its own (they would be in a separate `.node`).
//   * `.ele` (Triangle's triangles): refused (Unsupported) with a message naming the format.
//   * plain text (any other name): one point per non-blank line, fields separated by
//     whitespace or by ',' / ';' (whitespace around them allowed: "0.5,0.25", "0.5; 0.25").
//     Columns::AtLeast (the dimension given, the commands' --dim): the first d fields are
//     the coordinates and further columns are ignored (not parsed). Columns::Exactly (the
//     dimension taken from the file, point_file_shape): every line holds exactly d numbers,
//     as many as the file's first line of numbers, so that a file of `x y z` lines is never
//     read as its (x, y) projection.
//     The separators up to the last coordinate's must be of one kind, so that a decimal
//     comma ("1,5 2") is an error rather than the point (1, 5); an empty field (",,") is an
//     error. `#` comments are allowed here too. A first line without a single number is a
//     column header ("x,y"): it is skipped and reported in PointFile::header_line. A file
//     shaped like Triangle's formats (a first line starting with two whole numbers, then
//     rows of three fields or more numbered from 0 or 1, as many as announced) is refused
//     (Unsupported) naming the format it looks like.
//   * the path "-" is standard input, read as plain text (named "<stdin>" in messages). It is
//     read whole on first use, so that point_file_shape can look at its first lines before
//     read_points_file reads it as points.
//   * edit scripts: `+ x y [z]` / `- x y [z]`, exactly d coordinates (the points' dimension)
//     separated as in plain text, blank lines and `#` comments ignored. The sign must be a
//     token of its own.
//   * `.cells`: "# dynmesh cells v1", "# dim D", "# box o1 o2 [o3] L" (numbers printed as
//     %.17g in the C locale), then one line `level i j [k] npoints` per leaf, sorted by
//     (level, i, j, k); '\n' line ends.
// Every reader skips a UTF-8 byte order mark at the start of the file and accepts CRLF.
// Numbers are read with std::from_chars (locale-independent, correctly rounded): decimal or
// scientific notation with an optional leading '+' or '-'; hexadecimal floats are not
// accepted. A decimal overflow (1e999) is an infinity and an error; a decimal underflow
// (1e-999) is the correctly rounded signed zero.
// Every error is an InputError whose message names the file and the 1-based line, with the
// control bytes of quoted file text escaped as \xNN:
// Malformed (bad number or line shape), NotFinite (NaN, infinity), Count (too few or too many
// fields or vertices), Duplicate (two equal points), Resolution (two different points with
// equal located q, see locate_points), OutsideBox, Io (cannot open or read: a directory, or
// the OS reason such as "Permission denied"), Unsupported (a well-formed file of a kind not
// read: see above).
//
// Invariants: PointFile::lines[i] is the line of points[i]; points keep file order. A
// successful read never returns a NaN or infinite coordinate.
// Complexity: linear in the file size; locate_points O(n log n), however many copies of one
// point there are.
// Paper: none (formats of this project; Triangle and TetGen for `.node`).
#pragma once

#include <cstddef>
#include <iosfwd>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/edit.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/static_quadtree.hpp"

namespace dynmesh {

template <std::size_t d>
  requires SupportedDim<d>
struct PointFile {
  std::string name;                // as used in error messages
  std::vector<Point<d>> points;    // in file order
  std::vector<std::size_t> lines;  // lines[i]: the 1-based line of points[i]
  std::size_t header_line = 0;     // plain text: the line of a skipped column header (0: none)
  std::string header{};            // that line, control bytes escaped
};

enum class PointFormat { Auto, Node, Plain, Poly, Ele };

/// How many fields of a plain-text line are read (docs/FORMATS.md, "Input points"): with the
/// dimension given, the first d and further columns ignored (AtLeast); with the dimension
/// taken from the file, exactly d, on every line (Exactly). `.node` and `.poly` files ignore it.
enum class Columns { AtLeast, Exactly };

/// By the name's ending, in any letter case: Node for ".node", Poly for ".poly", Ele for
/// ".ele" (refused by the readers), Plain otherwise.
PointFormat format_for_path(std::string_view path) noexcept;

/// The path that names standard input, and the name its messages use.
inline constexpr std::string_view kStandardInput = "-";
inline const std::string kStandardInputName = "<stdin>";

/// `text` with every control byte (below 0x20, and 0x7f) written as \xNN: file text quoted
/// in a message can then neither break the line nor drive the terminal.
std::string escape_control_bytes(std::string_view text);

template <std::size_t d>
PointFile<d> read_node(std::istream& in, const std::string& name);
template <std::size_t d>
PointFile<d> read_poly(std::istream& in, const std::string& name);
template <std::size_t d>
PointFile<d> read_plain(std::istream& in, const std::string& name, Columns columns = Columns::AtLeast);
/// Reads `in` as `format` (Auto: by the extension of `name`); Ele is refused.
template <std::size_t d>
PointFile<d> read_points(std::istream& in, const std::string& name, PointFormat format = PointFormat::Auto,
                         Columns columns = Columns::AtLeast);
/// Opens `path` (standard input for "-", as plain text unless `format` says otherwise) and
/// reads it as `format` (Auto: by extension).
template <std::size_t d>
PointFile<d> read_points_file(const std::string& path, PointFormat format = PointFormat::Auto,
                              Columns columns = Columns::AtLeast);

/// The dimension announced by a `.node` file's header (2 when the field is omitted, as in
/// Triangle). Throws InputError naming the file and line for a malformed header.
int node_file_dimension(const std::string& path);

/// The dimension of a point file and how its plain-text lines are read.
struct PointFileShape {
  int dim = 2;
  Columns columns = Columns::AtLeast;
};

/// The dimension rule of docs/FORMATS.md, "Input points", for a path read by extension as
/// read_points_file reads it. `dim` is the dimension asked for (the commands' --dim), 0 when
/// none was. Given, it is the dimension, with Columns::AtLeast (a `.node` or `.poly` header
/// that announces another is reported when the file is read). Otherwise a `.node` or `.poly`
/// header decides (2 when it omits the field), and plain text is looked at up to its first
/// line that holds numbers: their count is the dimension, with Columns::Exactly; a count other
/// than 2 or 3 is InputError(Count) naming that line and asking for --dim (unless the file
/// has the shape of Triangle's formats, refused as read_plain refuses it). A file without
/// any number is 2D. Reads only the first lines, except to tell Triangle's shape.
PointFileShape point_file_shape(const std::string& path, int dim = 0);

/// Locates every point in `box`, in file order. Throws InputError(OutsideBox) naming the
/// line of the first point outside the box; for the first point (in file order) whose
/// located q equals that of an earlier point, naming its line and that earlier line,
/// InputError(Duplicate) when the two are equal and InputError(Resolution) (with the spread
/// L/s of the pair) when they differ: the grid cannot tell them apart. The exception's
/// point_indices() are the indices into file.points.
template <std::size_t d>
std::vector<Position<d>> locate_points(const PointFile<d>& file, const Box<d>& box);

/// Drops every point equal to an earlier one (file order), with its line, keeping the first
/// copy; returns how many were dropped (`--duplicates skip`). Coordinates must be finite, as
/// the readers return them. O(n log n).
template <std::size_t d>
std::size_t drop_duplicate_points(PointFile<d>& file);

/// An edit script: the edits in order and, for each, its 1-based line in the file.
template <std::size_t d>
  requires SupportedDim<d>
struct EditScript {
  std::string name;                // as used in error messages
  std::vector<Edit<d>> edits;
  std::vector<std::size_t> lines;  // lines[i]: the line of edits[i]
};

template <std::size_t d>
EditScript<d> read_edits(std::istream& in, const std::string& name);
template <std::size_t d>
EditScript<d> read_edits_file(const std::string& path);

/// Writes the `.cells` format; the leaves are sorted by (level, i, j, k) on the way out.
template <std::size_t d>
void write_cells(std::ostream& out, const Box<d>& box, std::span<const Leaf<d>> leaves);
/// The `.cells` text as a string (what write_cells writes).
template <std::size_t d>
std::string format_cells(const Box<d>& box, std::span<const Leaf<d>> leaves);
/// The same text in pieces, for a writer that streams the leaves (dynmesh-mpi): the three
/// header lines, then a line per leaf of `sorted` (already in (level, i, j, k) order).
template <std::size_t d>
std::string format_cells_header(const Box<d>& box);
template <std::size_t d>
void append_cells_lines(std::string& out, std::span<const Leaf<d>> sorted);
/// Writes to `path`; InputError(Io) when the file cannot be written.
template <std::size_t d>
void write_cells_file(const std::string& path, const Box<d>& box, std::span<const Leaf<d>> leaves);

template <std::size_t d>
  requires SupportedDim<d>
struct CellsFile {
  Box<d> box;
  std::vector<Leaf<d>> leaves;  // in file order (which a valid file has sorted)
};

/// Reads a `.cells` file strictly: the three header lines, then leaves with valid levels
/// and indices, sorted strictly ascending. Tiling is not checked here (see check_tree).
template <std::size_t d>
CellsFile<d> read_cells(std::istream& in, const std::string& name);
template <std::size_t d>
CellsFile<d> read_cells_file(const std::string& path);

}  // namespace dynmesh
