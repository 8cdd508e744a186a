// mesh_binding.cpp — dynmesh.Mesh (DynamicMesh in 2D, DynamicOctreeMesh in 3D) and
// dynmesh.triangulate (HpuMesh).
//
// Purpose: a changing point set and its mesh, as Python sees it (docs/FORMATS.md, "The Python
// module `dynmesh`" and "`dynmesh mesh` in 3D"): insert, erase, apply, the canonical vertices
// and simplices, last_change, last_update, to_meshio; and the static 2D mesh of a point set.
// The points' shape decides the dimension: (n, 2) is the 2D mesh (hpu by default, or the
// quadtree mesh), (n, 3) the octree's tetrahedral mesh (postprocess "quadtree", the 3D
// default; "hpu" and min_angle are 2D only, a ValueError that says so). One class serves
// both: the same calls take and give d coordinates; `cells` is the simplex array of either
// dimension (triangles (T, 3) or tetrahedra (T, 4)) and `cell_type` its meshio name
// ("triangle" or "tetra"); `triangles` is the 2D mesh's and `tetrahedra` the 3D mesh's
// (the other raises AttributeError).
// Invariants: arguments are converted (arrays.hpp) before the library is called, and the
// library's updates are failure-atomic, so a failed call changes nothing. The GIL is released
// around every call that meshes or propagates and held while arrays are read or made. One
// Mesh must not be used by two threads at once; two Mesh objects may run in parallel (the
// runtime's shared chunk cache is locked).
// Complexity: as DynamicMesh / DynamicOctreeMesh (O(lg L/s) expected trace distance per
// update) and HpuMesh, plus O(n) copies of the arrays that cross; vertices and the simplices
// compute the canonical mesh, O(t log t), on each access (mesh() gives both from one
// computation).
// Paper: Acar and Hudson (DynHPU, Figure 5; the quadtree and octree meshes, Section 5),
// through dynmesh/dynamic_mesh.hpp and dynmesh/dynamic_octree_mesh.hpp.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "dynmesh/box.hpp"
#include "dynmesh/dynamic_mesh.hpp"
#include "dynmesh/dynamic_octree_mesh.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/hpu_mesh.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/octree_mesh.hpp"
#include "dynmesh/quadtree_mesh.hpp"
#include "dynmesh/tet_mesh.hpp"

namespace dynmesh::python {
namespace {

/// The dimension of a dynamic mesh type.
template <class M>
constexpr std::size_t dim_of = std::is_same_v<M, DynamicOctreeMesh> ? 3 : 2;

std::string angle_text(double deg) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", deg);
  return buf;
}

class PyMesh {
 public:
  PyMesh(const py::object& points, const py::object& box, const py::object& min_angle, const py::object& postprocess) {
    const std::string name = postprocess.is_none() ? std::string() : string_from(postprocess, "postprocess");
    if (points_dim(points, "points") == 3) {
      // The octree's mesh, whose angle bounds are fixed: the 2D mesh's choices are refused.
      if (name == "hpu")
        throw InputError(Kind::Malformed,
                         "postprocess \"hpu\" is 2D only; the 3D mesh is the octree's (postprocess=\"quadtree\")");
      if (!name.empty() && name != "quadtree")
        throw InputError(Kind::Malformed, "postprocess must be \"quadtree\" in 3D (the octree's mesh), got '" + name + "'");
      if (!min_angle.is_none())
        throw InputError(Kind::Malformed, "min_angle is 2D only; the 3D mesh is the octree's, whose dihedral angles lie "
                                          "between " + angle_text(kOctreeMinDihedral) + " and " +
                                          angle_text(kOctreeMaxDihedral) + " degrees");
      const std::vector<Point<3>> pts = points_from<3>(points, "points");
      const Box<3> b = box_from<3>(box, pts);
      py::gil_scoped_release release;
      mesh_.emplace(std::in_place_type<DynamicOctreeMesh>, b, pts);
      return;
    }
    MeshOptions options;
    if (name.empty() || name == "hpu") {
      options.postprocess = Postprocess::Hpu;
      if (!min_angle.is_none()) options.min_angle = number_from(min_angle, "min_angle");
    } else if (name == "quadtree") {
      options.postprocess = Postprocess::Quadtree;
      // The quadtree mesh's bound is fixed: a larger request cannot be honoured.
      if (!min_angle.is_none() && !(number_from(min_angle, "min_angle") <= kQuadtreeMinAngle))
        throw InputError(Kind::Malformed, "min_angle above the quadtree mesh's bound of 18.4 degrees");
    } else {
      throw InputError(Kind::Malformed, "postprocess must be \"hpu\" or \"quadtree\", got '" + name + "'");
    }
    const std::vector<Point<2>> pts = points_from<2>(points, "points");
    const Box<2> b = box_from<2>(box, pts);
    py::gil_scoped_release release;
    mesh_.emplace(std::in_place_type<DynamicMesh>, b, pts, options);
  }

  /// f(mesh) on the 2D or the 3D mesh; f reads the dimension as dim_of<decltype(mesh)>.
  template <class F>
  decltype(auto) visit(F&& f) {
    return std::visit(std::forward<F>(f), *mesh_);
  }
  template <class F>
  decltype(auto) visit(F&& f) const {
    return std::visit(std::forward<F>(f), *mesh_);
  }

  std::size_t dim() const {
    return visit([](const auto& m) { return dim_of<std::decay_t<decltype(m)>>; });
  }

  PointId insert(const py::object& p) {
    return visit([&](auto& m) {
      const auto q = point_from<dim_of<std::decay_t<decltype(m)>>>(p);
      py::gil_scoped_release release;
      return m.insert(q);
    });
  }

  void erase(const py::object& what) {
    visit([&](auto& m) {
      if (py::isinstance<py::int_>(what)) {
        const auto id = what.cast<long long>();
        if (id < 0) throw InputError(Kind::Absent, "point id " + std::to_string(id) + " is not in the set");
        py::gil_scoped_release release;
        m.erase(static_cast<PointId>(id));
        return;
      }
      const auto q = point_from<dim_of<std::decay_t<decltype(m)>>>(what);
      py::gil_scoped_release release;
      m.erase(q);
    });
  }

  std::vector<PointId> apply(const py::iterable& edits) {
    return visit([&](auto& m) {
      const auto es = edits_from<dim_of<std::decay_t<decltype(m)>>>(edits);
      py::gil_scoped_release release;
      return m.apply(es);
    });
  }

  /// The canonical mesh (Mesh or TetMesh) handed to f, computed without the GIL.
  template <class F>
  py::object with_canonical(F&& f) const {
    return visit([&](const auto& m) -> py::object {
      std::optional<decltype(m.mesh())> mesh;
      {
        py::gil_scoped_release release;
        mesh.emplace(m.mesh());
      }
      return f(*mesh);
    });
  }

  py::array_t<double> points() const {
    return visit([](const auto& m) {
      constexpr std::size_t d = dim_of<std::decay_t<decltype(m)>>;
      std::vector<Point<d>> pts;
      for (const auto& entry : m.points()) pts.push_back(entry.second);
      return array_of<d>(pts);
    });
  }
  py::array_t<std::int64_t> ids() const {
    return visit([](const auto& m) {
      const auto entries = m.points();
      py::array_t<std::int64_t> out(static_cast<py::ssize_t>(entries.size()));
      auto o = out.mutable_unchecked<1>();
      for (std::size_t i = 0; i < entries.size(); ++i)
        o(static_cast<py::ssize_t>(i)) = static_cast<std::int64_t>(entries[i].first);
      return out;
    });
  }

  void check() const {
    visit([](const auto& m) {
      py::gil_scoped_release release;
      m.check_invariants();
    });
  }

 private:
  static std::string string_from(const py::object& obj, const char* what) {
    if (!py::isinstance<py::str>(obj)) throw InputError(Kind::Malformed, std::string(what) + " must be a string");
    return obj.cast<std::string>();
  }

  std::optional<std::variant<DynamicMesh, DynamicOctreeMesh>> mesh_;
};

/// The simplices of a canonical mesh: (T, 3) triangles or (T, 4) tetrahedra.
py::array_t<std::int64_t> cell_array(const Mesh& mesh) { return triangle_array(mesh); }
py::array_t<std::int64_t> cell_array(const TetMesh& mesh) { return tetrahedron_array(mesh); }

/// The mesh as a meshio.Mesh: points (V, 3) (z = 0 in 2D: VTK and Gmsh store 3D points, and
/// meshio warns on 2D ones), one "triangle" or "tetra" cell block.
py::object to_meshio(const PyMesh& s) {
  return s.with_canonical([](const auto& mesh) -> py::object {
    constexpr bool tets = std::is_same_v<std::decay_t<decltype(mesh)>, TetMesh>;
    const py::module_ meshio = py::module_::import("meshio");
    py::array_t<double> xyz({static_cast<py::ssize_t>(mesh.vertices.size()), py::ssize_t{3}});
    auto p = xyz.mutable_unchecked<2>();
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
      const auto row = static_cast<py::ssize_t>(i);
      p(row, 0) = mesh.vertices[i][0];
      p(row, 1) = mesh.vertices[i][1];
      if constexpr (tets)
        p(row, 2) = mesh.vertices[i][2];
      else
        p(row, 2) = 0.0;
    }
    py::list cells;
    cells.append(py::make_tuple(tets ? "tetra" : "triangle", cell_array(mesh)));
    return meshio.attr("Mesh")(xyz, cells);
  });
}

/// The simplex array of one dimension: `triangles` in 2D, `tetrahedra` in 3D; the other
/// dimension's name raises AttributeError naming the right one.
py::object simplices(const PyMesh& s, std::size_t dim, const char* name) {
  if (s.dim() != dim)
    throw py::attribute_error(std::string("a ") + std::to_string(s.dim()) + "D mesh has no " + name + "; use m." +
                              (s.dim() == 2 ? "triangles" : "tetrahedra") + " or m.cells");
  return s.with_canonical([](const auto& mesh) -> py::object { return cell_array(mesh); });
}

}  // namespace

void bind_mesh(py::module_& m) {
  py::class_<PyMesh>(m, "Mesh",
                     "A changing point set and its mesh of the box, every point a vertex, updated by change "
                     "propagation: (n, 2) points give the 2D quality mesh (DynamicMesh), (n, 3) points the octree's "
                     "tetrahedral mesh (DynamicOctreeMesh).")
      .def(py::init<const py::object&, const py::object&, const py::object&, const py::object&>(), py::arg("points"),
           py::arg("box") = py::none(), py::arg("min_angle") = py::none(), py::arg("postprocess") = py::none(),
           "points: (n, 2) or (n, 3) array; box: None (derived) or (o1, o2, [o3,] L); min_angle (2D only): hpu's "
           "bound, 1 to 30 (default 20.7); postprocess: \"hpu\" (the 2D default) or \"quadtree\" (the 3D default "
           "and only choice)")
      .def("insert", &PyMesh::insert, py::arg("point"), "insert a point (x, y[, z]); returns its id")
      .def("erase", &PyMesh::erase, py::arg("point"), "erase a point by id or by coordinates")
      .def("apply", &PyMesh::apply, py::arg("edits"),
           "apply [(\"+\", x, y[, z]), (\"-\", x, y[, z]), ...] in one propagation; returns the ids of the insertions")
      .def_property_readonly("dim", &PyMesh::dim, "2 or 3")
      .def_property_readonly(
          "vertices",
          [](const PyMesh& s) {
            return s.with_canonical([](const auto& mesh) -> py::object {
              return array_of<std::is_same_v<std::decay_t<decltype(mesh)>, TetMesh> ? 3 : 2>(mesh.vertices);
            });
          },
          "(V, d) float64, sorted by (x, y[, z])")
      .def_property_readonly(
          "triangles", [](const PyMesh& s) { return simplices(s, 2, "triangles"); },
          "2D: (T, 3) int64 indices into vertices, counter-clockwise from the smallest, sorted")
      .def_property_readonly(
          "tetrahedra", [](const PyMesh& s) { return simplices(s, 3, "tetrahedra"); },
          "3D: (T, 4) int64 indices into vertices, positively oriented, canonical (as OUTBASE.ele), sorted")
      .def_property_readonly(
          "cells", [](const PyMesh& s) { return s.with_canonical([](const auto& mesh) -> py::object { return cell_array(mesh); }); },
          "the simplices of either dimension: triangles (T, 3) in 2D, tetrahedra (T, 4) in 3D")
      .def_property_readonly(
          "cell_type", [](const PyMesh& s) { return s.dim() == 3 ? "tetra" : "triangle"; },
          "the meshio name of the cells: \"triangle\" or \"tetra\"")
      .def("mesh", [](const PyMesh& s) { return s.with_canonical([](const auto& mesh) -> py::object { return mesh_dict(mesh); }); },
           "{\"vertices\", \"triangles\"} (2D) or {\"vertices\", \"tetrahedra\"} (3D) of one canonical mesh (one "
           "computation for both)")
      .def_property_readonly(
          "last_change",
          [](const PyMesh& s) {
            return s.visit([](const auto& mesh) {
              const auto& c = mesh.last_change();
              return py::make_tuple(corners_of(c.removed), corners_of(c.added));
            });
          },
          "(removed, added): (R, 3, 2) and (A, 3, 2) triangle corners in 2D, (R, 4, 3) and (A, 4, 3) tetrahedron "
          "corners in 3D, of the last update")
      .def_property_readonly(
          "last_update", [](const PyMesh& s) { return s.visit([](const auto& mesh) { return update_dict(mesh.last_update()); }); },
          "{trace_distance, reexecuted, seconds} of the last update")
      .def_property_readonly("points", &PyMesh::points, "(n, d) the input points, by id")
      .def_property_readonly("ids", &PyMesh::ids, "(n,) their ids")
      .def_property_readonly(
          "box",
          [](const PyMesh& s) {
            return s.visit([](const auto& mesh) { return box_tuple(mesh.box()); });
          },
          "(o1, o2, [o3,] L)")
      .def_property_readonly(
          "min_angle",
          [](const PyMesh& s) -> py::object {
            return s.visit([](const auto& mesh) -> py::object {
              if constexpr (std::is_same_v<std::decay_t<decltype(mesh)>, DynamicMesh>)
                return py::float_(mesh.options().postprocess == Postprocess::Hpu ? mesh.options().min_angle
                                                                                 : kQuadtreeMinAngle);
              else
                return py::none();
            });
          },
          "2D: the smallest angle the mesh keeps, in degrees; 3D: None")
      .def("__len__", [](const PyMesh& s) { return s.visit([](const auto& mesh) { return mesh.size(); }); })
      .def("check", &PyMesh::check, "run every invariant checker (raises on a broken contract)")
      .def("to_meshio", &to_meshio,
           "the mesh as a meshio.Mesh: points (V, 3) (z = 0 in 2D), one \"triangle\" or \"tetra\" cell block (needs "
           "meshio)");

  m.def(
      "triangulate",
      [](const py::object& points, const py::object& min_angle, const py::object& box) {
        const std::vector<Point<2>> pts = points_from<2>(points, "points");
        const Box<2> b = box_from<2>(box, pts);
        const double bound = min_angle.is_none() ? kHpuDefaultMinAngle : number_from(min_angle, "min_angle");
        Mesh mesh;
        {
          py::gil_scoped_release release;
          mesh = HpuMesh(b, pts, bound).mesh();
        }
        return mesh_dict(mesh);
      },
      py::arg("points"), py::arg("min_angle") = py::none(), py::arg("box") = py::none(),
      "the static quality mesh (HpuMesh) of (n, 2) points: {\"vertices\", \"triangles\"}");
}

}  // namespace dynmesh::python
