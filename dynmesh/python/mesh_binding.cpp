// mesh_binding.cpp — dynmesh.Mesh (DynamicMesh) and dynmesh.triangulate (HpuMesh).
//
// Purpose: a changing 2D point set and its quality mesh, as Python sees it (docs/FORMATS.md,
// "The Python module `dynmesh`"): insert, erase, apply, the canonical vertices and
// triangles, last_change, last_update, to_meshio; and the static mesh of a point set.
// Invariants: arguments are converted (arrays.hpp) before the library is called, and the
// library's updates are failure-atomic, so a failed call changes nothing. The GIL is released
// around every call that meshes or propagates and held while arrays are read or made. One
// Mesh must not be used by two threads at once; two Mesh objects may run in parallel (the
// runtime's shared chunk cache is locked).
// Complexity: as DynamicMesh (O(lg L/s) expected trace distance per update) and HpuMesh,
// plus O(n) copies of the arrays that cross; vertices and triangles compute the canonical
// mesh, O(t log t), on each access (mesh() gives both from one computation).
// Paper: Acar and Hudson (DynHPU, Figure 5), through dynmesh/dynamic_mesh.hpp.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "dynmesh/box.hpp"
#include "dynmesh/dynamic_mesh.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/hpu_mesh.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/quadtree_mesh.hpp"

namespace dynmesh::python {
namespace {

class PyMesh {
 public:
  PyMesh(const py::object& points, const py::object& box, const py::object& min_angle, const std::string& postprocess) {
    MeshOptions options;
    if (postprocess == "hpu") {
      options.postprocess = Postprocess::Hpu;
      if (!min_angle.is_none()) options.min_angle = number_from(min_angle, "min_angle");
    } else if (postprocess == "quadtree") {
      options.postprocess = Postprocess::Quadtree;
      // The quadtree mesh's bound is fixed: a larger request cannot be honoured.
      if (!min_angle.is_none() && !(number_from(min_angle, "min_angle") <= kQuadtreeMinAngle))
        throw InputError(Kind::Malformed, "min_angle above the quadtree mesh's bound of 18.4 degrees");
    } else {
      throw InputError(Kind::Malformed, "postprocess must be \"hpu\" or \"quadtree\", got '" + postprocess + "'");
    }
    const std::vector<Point<2>> pts = points_from<2>(points, "points");
    const Box<2> b = box_from<2>(box, pts);
    py::gil_scoped_release release;
    mesh_.emplace(b, pts, options);
  }

  PointId insert(const py::object& p) {
    const Point<2> q = point_from<2>(p);
    py::gil_scoped_release release;
    return mesh_->insert(q);
  }

  void erase(const py::object& what) {
    if (py::isinstance<py::int_>(what)) {
      const auto id = what.cast<long long>();
      if (id < 0) throw InputError(Kind::Absent, "point id " + std::to_string(id) + " is not in the set");
      py::gil_scoped_release release;
      mesh_->erase(static_cast<PointId>(id));
      return;
    }
    const Point<2> q = point_from<2>(what);
    py::gil_scoped_release release;
    mesh_->erase(q);
  }

  std::vector<PointId> apply(const py::iterable& edits) {
    const std::vector<Edit<2>> es = edits_from<2>(edits);
    py::gil_scoped_release release;
    return mesh_->apply(es);
  }

  Mesh canonical() const {
    py::gil_scoped_release release;
    return mesh_->mesh();
  }

  py::array_t<double> points() const {
    std::vector<Point<2>> pts;
    for (const auto& entry : mesh_->points()) pts.push_back(entry.second);
    return array_of<2>(pts);
  }
  py::array_t<std::int64_t> ids() const {
    const auto entries = mesh_->points();
    py::array_t<std::int64_t> out(static_cast<py::ssize_t>(entries.size()));
    auto o = out.mutable_unchecked<1>();
    for (std::size_t i = 0; i < entries.size(); ++i) o(static_cast<py::ssize_t>(i)) = static_cast<std::int64_t>(entries[i].first);
    return out;
  }

  const DynamicMesh& get() const { return *mesh_; }
  void check() const {
    py::gil_scoped_release release;
    mesh_->check_invariants();
  }

 private:
  std::optional<DynamicMesh> mesh_;
};

/// The mesh as a meshio.Mesh: points (V, 3) with z = 0 (VTK and Gmsh store 3D points, and
/// meshio warns on 2D ones), one "triangle" cell block.
py::object to_meshio(const PyMesh& s) {
  const Mesh mesh = s.canonical();
  const py::module_ meshio = py::module_::import("meshio");
  py::array_t<double> xyz({static_cast<py::ssize_t>(mesh.vertices.size()), py::ssize_t{3}});
  auto p = xyz.mutable_unchecked<2>();
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const auto row = static_cast<py::ssize_t>(i);
    p(row, 0) = mesh.vertices[i][0];
    p(row, 1) = mesh.vertices[i][1];
    p(row, 2) = 0.0;
  }
  py::list cells;
  cells.append(py::make_tuple("triangle", triangle_array(mesh)));
  return meshio.attr("Mesh")(xyz, cells);
}

}  // namespace

void bind_mesh(py::module_& m) {
  py::class_<PyMesh>(m, "Mesh",
                     "A changing 2D point set and its quality mesh of the box (DynamicMesh): every point a "
                     "vertex, updated by change propagation.")
      .def(py::init<const py::object&, const py::object&, const py::object&, const std::string&>(), py::arg("points"),
           py::arg("box") = py::none(), py::arg("min_angle") = py::none(), py::arg("postprocess") = "hpu",
           "points: (n, 2) array; box: None (derived) or (o1, o2, L); min_angle: hpu's bound, 1 to 30 "
           "(default 20.7); postprocess: \"hpu\" or \"quadtree\"")
      .def("insert", &PyMesh::insert, py::arg("point"), "insert a point (x, y); returns its id")
      .def("erase", &PyMesh::erase, py::arg("point"), "erase a point by id or by coordinates")
      .def("apply", &PyMesh::apply, py::arg("edits"),
           "apply [(\"+\", x, y), (\"-\", x, y), ...] in one propagation; returns the ids of the insertions")
      .def_property_readonly(
          "vertices", [](const PyMesh& s) { return array_of<2>(s.canonical().vertices); },
          "(V, 2) float64, sorted by (x, y)")
      .def_property_readonly(
          "triangles", [](const PyMesh& s) { return triangle_array(s.canonical()); },
          "(T, 3) int64 indices into vertices, counter-clockwise from the smallest, sorted")
      .def("mesh", [](const PyMesh& s) { return mesh_dict(s.canonical()); },
           "{\"vertices\", \"triangles\"} of one canonical mesh (one computation for both)")
      .def_property_readonly(
          "last_change",
          [](const PyMesh& s) {
            const MeshChange& c = s.get().last_change();
            return py::make_tuple(corners_of(c.removed), corners_of(c.added));
          },
          "(removed, added): (R, 3, 2) and (A, 3, 2) triangle corners of the last update")
      .def_property_readonly(
          "last_update", [](const PyMesh& s) { return update_dict(s.get().last_update()); },
          "{trace_distance, reexecuted, seconds} of the last update")
      .def_property_readonly("points", &PyMesh::points, "(n, 2) the input points, by id")
      .def_property_readonly("ids", &PyMesh::ids, "(n,) their ids")
      .def_property_readonly("box", [](const PyMesh& s) { return box_tuple(s.get().box()); }, "(o1, o2, L)")
      .def_property_readonly("min_angle",
                             [](const PyMesh& s) {
                               return s.get().options().postprocess == Postprocess::Hpu
                                          ? s.get().options().min_angle
                                          : kQuadtreeMinAngle;
                             })
      .def("__len__", [](const PyMesh& s) { return s.get().size(); })
      .def("check", &PyMesh::check, "run every invariant checker (raises on a broken contract)")
      .def("to_meshio", &to_meshio,
           "the mesh as a meshio.Mesh: points (V, 3) with z = 0, one \"triangle\" cell block (needs meshio)");

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
