// initial_points.hpp (private to the command) — the POINTS file of `quadtree` and `mesh` made
// ready for the library: read, `--duplicates skip` applied, the box taken from --box or
// derived (docs/FORMATS.md, "The domain box"), every point located; and the library's
// construction errors re-labelled with the file's lines.
//
// Purpose: both commands take their initial points the same way, and a spread beyond the
// resolution is reported in one place, as what it is: the spread L/s (and its log2) of the
// pair the grid cannot tell apart, naming the point that causes it. That is a point far
// from all others when it alone stretches a derived box (a stray 1e17 among terrain
// coordinates makes L so large that near terrain points collide), else the later point of
// the pair.
// Points so close together that a box derived from them cannot be divided (the library's
// "too small for its offset") are named as that pair. A skipped column header is noted on
// stderr ("dynmesh: note: ...") and the run goes on.
// The dimension of POINTS (docs/FORMATS.md, "Input points": --dim, a `.node` header, or the
// count of numbers on the first line of plain text) is decided by points_shape, in an order
// that keeps the memory guard ahead of any reading that could wait (a pipe).
// Invariants: every error thrown names the POINTS file, and a line when one is known.
// Complexity: O(n log n) (locating, duplicates); a resolution error costs O(n) more;
// points_shape reads the first lines of a regular file.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <system_error>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/io.hpp"
#include "input_labels.hpp"

namespace dynmesh::tool {

template <std::size_t d>
struct InitialPoints {
  PointFile<d> file;
  Box<d> box;
  bool box_derived = false;          // no --box: derived from the points
  std::vector<Position<d>> located;  // located[i]: the position of file.points[i]
  std::size_t duplicates_skipped = 0;
};

namespace detail {

template <std::size_t d>
std::size_t line_of(const InitialPoints<d>& in, std::size_t i) {
  return i < in.file.lines.size() ? in.file.lines[i] : 0;
}

/// A point that alone makes a derived box at least this many times wider is named as the
/// cause of a spread beyond the resolution, rather than the pair that collides because of it.
inline constexpr double kStretchFactor = 1024;

/// The other point the grid cannot tell apart from point i, for an error that names i alone:
/// one whose cell of `level` is i's or a neighbour of it (level 52 for the quadtree, the
/// mesh's coarser resolution level for the mesh; negative: no partner).
template <std::size_t d>
std::optional<std::size_t> resolution_partner(const InitialPoints<d>& in, std::size_t i, int level) {
  if (level < 0 || level > kMaxLevel || i >= in.located.size()) return std::nullopt;
  const int shift = kMaxLevel - level;
  for (std::size_t j = 0; j < in.located.size(); ++j) {
    bool near = j != i;
    for (std::size_t a = 0; a < d && near; ++a) {
      const std::uint64_t x = in.located[j][a] >> shift, y = in.located[i][a] >> shift;
      near = (x > y ? x - y : y - x) <= 1;
    }
    if (near) return j;
  }
  return std::nullopt;
}

/// The two points at the ends of the widest axis of the points' extent: the pair that spans
/// a derived box (first in file order first).
template <std::size_t d>
std::pair<std::size_t, std::size_t> extent_pair(std::span<const Point<d>> pts) {
  std::size_t best_axis = 0;
  double best = -1;
  std::size_t lo[d] = {}, hi[d] = {};
  for (std::size_t a = 0; a < d; ++a) {
    for (std::size_t i = 1; i < pts.size(); ++i) {
      if (pts[i][a] < pts[lo[a]][a]) lo[a] = i;
      if (pts[i][a] > pts[hi[a]][a]) hi[a] = i;
    }
    if (pts.size() > 0 && pts[hi[a]][a] - pts[lo[a]][a] > best) {
      best = pts[hi[a]][a] - pts[lo[a]][a];
      best_axis = a;
    }
  }
  return {std::min(lo[best_axis], hi[best_axis]), std::max(lo[best_axis], hi[best_axis])};
}

}  // namespace detail

/// The error for a box derived from points so close together, for their distance from the
/// origin, that double coordinates cannot resolve it (the library says "the domain box is
/// too small for its offset", or a point falls outside the rounded box): it names the two
/// points that span the box.
template <std::size_t d>
[[noreturn]] void throw_too_close_error(const InitialPoints<d>& in) {
  const auto [a, b] = detail::extent_pair<d>(in.file.points);
  const auto& pts = in.file.points;
  throw InputError(InputError::Kind::Resolution,
                   "points " + to_string<d>(pts[a]) + " and " + to_string<d>(pts[b]) + " (lines " +
                       std::to_string(detail::line_of(in, a)) + ", " + std::to_string(detail::line_of(in, b)) +
                       ") are too close together for the resolution of double coordinates at their distance from "
                       "the origin: the box derived from them cannot be divided into cells; spread the points "
                       "further apart, or give a larger box with --box",
                   in.file.name, detail::line_of(in, b))
      .with_points({a, b});
}

/// The error for points i and j that the grid cannot tell apart at `level` (52 for the
/// quadtree, the mesh's resolution level for the mesh): the spread L/s of the pair exceeds
/// the resolution L/2^level. Names the point that stretches a derived box when there is one
/// (its line is the error's), else the later point of the pair; both lines of the pair.
template <std::size_t d>
[[noreturn]] void throw_resolution_error(const InitialPoints<d>& in, std::size_t i, std::size_t j,
                                         int level = kMaxLevel) {
  const std::size_t a = std::min(i, j), b = std::max(i, j);
  const auto& pts = in.file.points;
  const std::string exceeds = " makes the spread exceed the resolution L/2^" + std::to_string(level) + ": ";
  const std::string spread = spread_text<d>(in.box, pts[b], pts[a]);
  const std::string lines = " (lines " + std::to_string(detail::line_of(in, a)) + ", " +
                            std::to_string(detail::line_of(in, b)) + ")";
  if (in.box_derived) {
    const auto stretch = stretching_point<d>(pts);
    if (stretch && stretch->index != a && stretch->index != b &&
        stretch->side_without * detail::kStretchFactor <= in.box.side)
      throw InputError(InputError::Kind::Resolution,
                       "point " + to_string<d>(pts[stretch->index]) + exceeds +
                           "it stretches the derived box (L = " + format_brief(stretch->side_without) +
                           " without it), so the points on lines " + std::to_string(detail::line_of(in, a)) + " and " +
                           std::to_string(detail::line_of(in, b)) + " have " + spread,
                       in.file.name, detail::line_of(in, stretch->index))
          .with_points({stretch->index, a, b});
  }
  throw InputError(InputError::Kind::Resolution,
                   "point " + to_string<d>(pts[b]) + exceeds + "with the point on line " +
                       std::to_string(detail::line_of(in, a)) + " " + to_string<d>(pts[a]) + " it has " + spread +
                       lines,
                   in.file.name, detail::line_of(in, b))
      .with_points({a, b});
}

/// The dimension of POINTS and how its lines are read (point_file_shape; `dim_option` is
/// --dim, 0 when not given), with `guard(dim)` (the command's memory guard for that
/// dimension) run before any reading that could wait: a regular file's first lines are looked
/// at first, since the guard's estimate depends on the dimension; standard input and pipes
/// only after the guard, because looking at them waits for their writer, and the guard counts
/// none of their points (it then assumes --dim, else 2, for the points the edits insert).
template <class Guard>
PointFileShape points_shape(const std::string& path, int dim_option, Guard&& guard) {
  std::error_code ec;
  const bool pipe = path == kStandardInput || (std::filesystem::exists(path, ec) &&
                                               !std::filesystem::is_regular_file(path, ec) &&
                                               !std::filesystem::is_directory(path, ec));
  if (pipe && dim_option == 0) {
    guard(2);
    return point_file_shape(path, 0);
  }
  const PointFileShape shape = point_file_shape(path, dim_option);
  guard(shape.dim);
  return shape;
}

/// Reads `path` (its format by extension; plain-text lines as `columns` says), drops later
/// copies of a point when `skip_duplicates`, takes the box from `box_option` (--box) or
/// derives it, and locates every point. Throws InputError naming the file and line.
template <std::size_t d>
InitialPoints<d> read_initial_points(const std::string& path, const std::vector<double>& box_option,
                                     bool skip_duplicates, Columns columns = Columns::AtLeast) {
  InitialPoints<d> in;
  in.file = read_points_file<d>(path, PointFormat::Auto, columns);
  if (in.file.header_line != 0) {
    // A note, not an error: the run goes on. On stderr, so that stdout stays the outputs'.
    std::fflush(stdout);
    std::fprintf(stderr, "dynmesh: note: %s:%zu: skipped the header line '%s' (it holds no number)\n",
                 escape_control_bytes(in.file.name).c_str(), in.file.header_line, in.file.header.c_str());
  }
  if (skip_duplicates) in.duplicates_skipped = drop_duplicate_points<d>(in.file);
  in.box_derived = box_option.empty();
  if (in.box_derived) {
    try {
      in.box = derive_box<d>(in.file.points);
    } catch (const InputError& e) {
      rethrow_in(e, in.file.name);
    }
  } else {
    in.box = box_from_option<d>(box_option);
  }
  // Outside the box, NaN, duplicates: named by line here, before the library sees the points.
  try {
    in.located = locate_points<d>(in.file, in.box);
  } catch (const InputError& e) {
    // A derived box holds every point unless rounding shrank it: the points are too close.
    if (e.kind() == InputError::Kind::OutsideBox && in.box_derived && in.file.points.size() >= 2)
      throw_too_close_error(in);
    if (e.kind() != InputError::Kind::Resolution || e.point_indices().size() != 2) throw;
    throw_resolution_error(in, e.point_indices()[0], e.point_indices()[1]);
  }
  return in;
}

/// A constructor's error naming point indices, re-labelled with the point file's lines; a
/// resolution error names the pair and its spread (throw_resolution_error), the partner of a
/// point named alone found at `resolution_level` (see detail::resolution_partner).
template <std::size_t d>
[[noreturn]] void rethrow_construction_error(const InputError& e, const InitialPoints<d>& in,
                                             int resolution_level = kMaxLevel) {
  std::vector<std::size_t> idx = e.point_indices();
  // A Resolution error naming no point is about the box (too small for its offset): with a
  // derived box, the points that span it are too close together.
  // A negative resolution level says the same of the mesh's box.
  if ((idx.empty() || resolution_level < 0) && e.kind() == InputError::Kind::Resolution && in.box_derived &&
      in.file.points.size() >= 2)
    throw_too_close_error(in);
  if (idx.empty()) rethrow_in(e, in.file.name);
  if (e.kind() == InputError::Kind::Resolution && idx.size() <= 2 && idx.back() < in.file.points.size()) {
    if (idx.size() == 2) throw_resolution_error(in, idx[0], idx[1]);
    if (const auto partner = detail::resolution_partner(in, idx[0], resolution_level))
      throw_resolution_error(in, idx[0], *partner, resolution_level);
  }
  std::sort(idx.begin(), idx.end());
  std::string text = e.text();
  // "point I: ..." names an index; the line number replaces it.
  for (const std::size_t i : idx) {
    const std::string prefix = "point " + std::to_string(i) + ": ";
    if (text.compare(0, prefix.size(), prefix) == 0) text.erase(0, prefix.size());
  }
  if (idx.size() > 1) {
    text += " (lines";
    for (std::size_t k = 0; k < idx.size(); ++k) text += (k ? ", " : " ") + std::to_string(detail::line_of(in, idx[k]));
    text += ")";
  }
  throw InputError(e.kind(), text, in.file.name, detail::line_of(in, idx.back()));
}

}  // namespace dynmesh::tool
