// arrays.hpp (private to the Python module) — library values to and from Python objects.
//
// Purpose: the conversions every binding shares, so that each crosses in one way only:
// points as (n, d) float64 arrays copied in one block (no Python object per element), one
// point as a sequence of d numbers, canonical meshes as (V, d) float64 vertices and (T, 3)
// int64 triangles or (T, 4) int64 tetrahedra, changes as (t, 3, 2) or (t, 4, 3) corners,
// boxes as (o1, o2, [o3,] L) tuples, edit lists as [("+" | "-", coordinates...)], update
// figures as dicts.
// Invariants: every function reads or makes Python objects, so it runs with the GIL held;
// a malformed argument throws InputError(Malformed) naming it (an edit also by its index),
// before any library call, so a failed call changes nothing.
// Complexity: O(size of the value) each.
// Paper: none.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/edit.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/tet_mesh.hpp"

namespace dynmesh::python {

namespace py = pybind11;
using Kind = InputError::Kind;

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// An (n, d) array (or anything NumPy turns into one) as points; n may be 0.
template <std::size_t d>
std::vector<Point<d>> points_from(const py::handle& obj, const char* what) {
  const DoubleArray a = DoubleArray::ensure(obj);
  if (!a) throw InputError(Kind::Malformed, std::string(what) + " must be an array of numbers");
  if (a.size() == 0) return {};
  if (a.ndim() != 2 || a.shape(1) != static_cast<py::ssize_t>(d))
    throw InputError(Kind::Malformed, std::string(what) + " must have shape (n, " + std::to_string(d) + ")");
  std::vector<Point<d>> pts(static_cast<std::size_t>(a.shape(0)));
  std::memcpy(pts.data(), a.data(), pts.size() * sizeof(Point<d>));
  return pts;
}

/// The dimension of a points argument: 2 or 3 by its shape (n, 2) or (n, 3); 2 for an empty
/// array of no shape (`[]`). InputError(Malformed) naming `what` otherwise.
inline std::size_t points_dim(const py::handle& obj, const char* what) {
  const DoubleArray a = DoubleArray::ensure(obj);
  if (!a) throw InputError(Kind::Malformed, std::string(what) + " must be an array of numbers");
  if (a.size() == 0 && a.ndim() != 2) return 2;
  if (a.ndim() != 2 || (a.shape(1) != 2 && a.shape(1) != 3))
    throw InputError(Kind::Malformed, std::string(what) + " must have shape (n, 2) or (n, 3)");
  return static_cast<std::size_t>(a.shape(1));
}

/// One point: a sequence of d numbers.
template <std::size_t d>
Point<d> point_from(const py::handle& obj) {
  const DoubleArray a = DoubleArray::ensure(obj);
  if (!a || a.ndim() != 1 || a.shape(0) != static_cast<py::ssize_t>(d))
    throw InputError(Kind::Malformed, "a point is a sequence of " + std::to_string(d) + " numbers");
  Point<d> p;
  for (std::size_t k = 0; k < d; ++k) p[k] = a.at(static_cast<py::ssize_t>(k));
  return p;
}

template <std::size_t d>
py::array_t<double> array_of(std::span<const Point<d>> pts) {
  py::array_t<double> out({static_cast<py::ssize_t>(pts.size()), static_cast<py::ssize_t>(d)});
  if (!pts.empty()) std::memcpy(out.mutable_data(), pts.data(), pts.size() * sizeof(Point<d>));
  return out;
}

/// Triangles by corners, (t, 3, 2): the change feed's form.
inline py::array_t<double> corners_of(const std::vector<Triangle>& ts) {
  py::array_t<double> out({static_cast<py::ssize_t>(ts.size()), py::ssize_t{3}, py::ssize_t{2}});
  static_assert(sizeof(Triangle) == 6 * sizeof(double));
  if (!ts.empty()) std::memcpy(out.mutable_data(), ts.data(), ts.size() * sizeof(Triangle));
  return out;
}

/// Tetrahedra by corners, (t, 4, 3): the 3D change feed's form.
inline py::array_t<double> corners_of(const std::vector<Tetrahedron>& ts) {
  py::array_t<double> out({static_cast<py::ssize_t>(ts.size()), py::ssize_t{4}, py::ssize_t{3}});
  static_assert(sizeof(Tetrahedron) == 12 * sizeof(double));
  if (!ts.empty()) std::memcpy(out.mutable_data(), ts.data(), ts.size() * sizeof(Tetrahedron));
  return out;
}

/// The tetrahedra of a canonical mesh, (t, 4) int64 indices into its vertices.
inline py::array_t<std::int64_t> tetrahedron_array(const TetMesh& mesh) {
  py::array_t<std::int64_t> tets({static_cast<py::ssize_t>(mesh.tetrahedra.size()), py::ssize_t{4}});
  auto t = tets.mutable_unchecked<2>();
  for (std::size_t i = 0; i < mesh.tetrahedra.size(); ++i)
    for (py::ssize_t k = 0; k < 4; ++k) t(static_cast<py::ssize_t>(i), k) = mesh.tetrahedra[i][static_cast<std::size_t>(k)];
  return tets;
}

inline py::dict mesh_dict(const TetMesh& mesh) {
  py::dict out;
  out["vertices"] = array_of<3>(mesh.vertices);
  out["tetrahedra"] = tetrahedron_array(mesh);
  return out;
}

/// The triangles of a canonical mesh, (t, 3) int64 indices into its vertices.
inline py::array_t<std::int64_t> triangle_array(const Mesh& mesh) {
  py::array_t<std::int64_t> tris({static_cast<py::ssize_t>(mesh.triangles.size()), py::ssize_t{3}});
  auto t = tris.mutable_unchecked<2>();
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
    for (py::ssize_t k = 0; k < 3; ++k) t(static_cast<py::ssize_t>(i), k) = mesh.triangles[i][static_cast<std::size_t>(k)];
  return tris;
}

inline py::dict mesh_dict(const Mesh& mesh) {
  py::dict out;
  out["vertices"] = array_of<2>(mesh.vertices);
  out["triangles"] = triangle_array(mesh);
  return out;
}

/// The box argument: None (derived from the points) or (o1, o2, [o3,] L).
template <std::size_t d>
Box<d> box_from(const py::object& box, std::span<const Point<d>> pts) {
  if (box.is_none()) return derive_box<d>(pts);
  const DoubleArray a = DoubleArray::ensure(box);
  if (!a || a.ndim() != 1 || a.shape(0) != static_cast<py::ssize_t>(d + 1))
    throw InputError(Kind::Malformed, "box must be (o1, o2" + std::string(d == 3 ? ", o3" : "") + ", L)");
  Box<d> b;
  for (std::size_t k = 0; k < d; ++k) b.origin[k] = a.at(static_cast<py::ssize_t>(k));
  b.side = a.at(static_cast<py::ssize_t>(d));
  validate_box(b);
  return b;
}

template <std::size_t d>
py::tuple box_tuple(const Box<d>& b) {
  py::tuple t(d + 1);
  for (std::size_t k = 0; k < d; ++k) t[k] = b.origin[k];
  t[d] = b.side;
  return t;
}

/// [("+", x, y[, z]), ("-", x, y[, z]), ...] as edits, all parsed before any is applied.
template <std::size_t d>
std::vector<Edit<d>> edits_from(const py::iterable& edits) {
  std::vector<Edit<d>> out;
  for (const py::handle item : edits) {
    const std::size_t i = out.size();
    auto bad = [&](const std::string& why) {
      return InputError(Kind::Malformed, "edit " + std::to_string(i) + ": " + why).with_points({i});
    };
    if (!py::isinstance<py::sequence>(item) || py::isinstance<py::str>(item)) throw bad("an edit is a tuple (\"+\" or \"-\", coordinates...)");
    const auto seq = py::reinterpret_borrow<py::sequence>(item);
    if (seq.size() != 1 + d) throw bad("an edit has a sign and " + std::to_string(d) + " coordinates");
    if (!py::isinstance<py::str>(seq[0])) throw bad("the sign must be \"+\" or \"-\"");
    const std::string sign = seq[0].cast<std::string>();
    if (sign != "+" && sign != "-") throw bad("the sign must be \"+\" or \"-\", got '" + sign + "'");
    Edit<d> e{sign == "+" ? EditOp::Insert : EditOp::Delete, {}};
    for (std::size_t k = 0; k < d; ++k) {
      try {
        e.point[k] = seq[1 + k].cast<double>();
      } catch (const py::cast_error&) {
        throw bad("coordinate " + std::to_string(k) + " is not a number");
      }
    }
    out.push_back(e);
  }
  return out;
}

inline py::dict update_dict(const UpdateStats& u) {
  py::dict out;
  out["trace_distance"] = u.trace_distance;
  out["reexecuted"] = u.reexecuted;
  out["seconds"] = u.seconds;
  return out;
}

/// A number argument (min_angle): InputError(Malformed) naming it when it is not one.
inline double number_from(const py::handle& obj, const char* what) {
  try {
    return obj.cast<double>();
  } catch (const py::cast_error&) {
    throw InputError(Kind::Malformed, std::string(what) + " must be a number");
  }
}

}  // namespace dynmesh::python
