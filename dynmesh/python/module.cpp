// module.cpp — the Python module `dynmesh` (its compiled part, `dynmesh._dynmesh`), pybind11.
//
// Purpose: DynamicMesh, HpuMesh and DynamicQuadtree as Python sees them (docs/FORMATS.md,
// "The Python module `dynmesh`"): `Mesh` (insert, erase, apply, vertices, triangles,
// last_change, last_update, to_meshio), `triangulate` (the static mesh) and `Quadtree`
// (2D or 3D). Points and meshes cross as NumPy float64 / int64 arrays, copied in one block
// (no Python object per element); edit lists are parsed into one std::vector first.
// Invariants:
//   * Every library InputError becomes dynmesh.InputError (a ValueError) carrying the
//     library's message, `kind` (the InputError::Kind name), `indices` (the points or edits
//     involved, InputError::point_indices) and `index` (the failing one: the last of them,
//     or None). Malformed Python arguments (a bad shape, an unknown edit sign) raise the
//     same before the library is called. Either way a failed call changes nothing: the
//     library's calls are failure-atomic and the arguments are converted before them.
//   * The GIL is released around every library call that meshes or propagates (building,
//     insert, erase, apply, the canonical mesh, triangulate), and held while NumPy arrays are
//     read or made. One Mesh or Quadtree must not be used by two threads at once; different
//     objects may run in parallel (the runtime's shared chunk cache is locked).
// Complexity: as the wrapped calls, plus O(n) copies of the arrays that cross.
// Paper: none (the API of dynmesh/dynamic_mesh.hpp and dynmesh/dynamic_quadtree.hpp).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/dynamic_mesh.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/edit.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/hpu_mesh.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/quadtree_mesh.hpp"

namespace py = pybind11;
using dynmesh::InputError;
using Kind = dynmesh::InputError::Kind;

namespace {

// --- arrays in and out ---------------------------------------------------------------------

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// An (n, d) array (or anything NumPy turns into one) as points; n may be 0.
template <std::size_t d>
std::vector<dynmesh::Point<d>> points_from(const py::handle& obj, const char* what) {
  const DoubleArray a = DoubleArray::ensure(obj);
  if (!a) throw InputError(Kind::Malformed, std::string(what) + " must be an array of numbers");
  if (a.size() == 0) return {};
  if (a.ndim() != 2 || a.shape(1) != static_cast<py::ssize_t>(d))
    throw InputError(Kind::Malformed, std::string(what) + " must have shape (n, " + std::to_string(d) + ")");
  std::vector<dynmesh::Point<d>> pts(static_cast<std::size_t>(a.shape(0)));
  std::memcpy(pts.data(), a.data(), pts.size() * sizeof(dynmesh::Point<d>));
  return pts;
}

/// One point: a sequence of d numbers.
template <std::size_t d>
dynmesh::Point<d> point_from(const py::handle& obj) {
  const DoubleArray a = DoubleArray::ensure(obj);
  if (!a || a.ndim() != 1 || a.shape(0) != static_cast<py::ssize_t>(d))
    throw InputError(Kind::Malformed, "a point is a sequence of " + std::to_string(d) + " numbers");
  dynmesh::Point<d> p;
  for (std::size_t k = 0; k < d; ++k) p[k] = a.at(static_cast<py::ssize_t>(k));
  return p;
}

template <std::size_t d>
py::array_t<double> array_of(std::span<const dynmesh::Point<d>> pts) {
  py::array_t<double> out({static_cast<py::ssize_t>(pts.size()), static_cast<py::ssize_t>(d)});
  if (!pts.empty()) std::memcpy(out.mutable_data(), pts.data(), pts.size() * sizeof(dynmesh::Point<d>));
  return out;
}

/// Triangles by corners, (t, 3, 2): the change feed's form.
py::array_t<double> corners_of(const std::vector<dynmesh::Triangle>& ts) {
  py::array_t<double> out({static_cast<py::ssize_t>(ts.size()), py::ssize_t{3}, py::ssize_t{2}});
  static_assert(sizeof(dynmesh::Triangle) == 6 * sizeof(double));
  if (!ts.empty()) std::memcpy(out.mutable_data(), ts.data(), ts.size() * sizeof(dynmesh::Triangle));
  return out;
}

/// The triangles of a canonical mesh, (t, 3) int64 indices into its vertices.
py::array_t<std::int64_t> triangle_array(const dynmesh::Mesh& mesh) {
  py::array_t<std::int64_t> tris({static_cast<py::ssize_t>(mesh.triangles.size()), py::ssize_t{3}});
  auto t = tris.mutable_unchecked<2>();
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
    for (py::ssize_t k = 0; k < 3; ++k) t(static_cast<py::ssize_t>(i), k) = mesh.triangles[i][static_cast<std::size_t>(k)];
  return tris;
}

py::dict mesh_dict(const dynmesh::Mesh& mesh) {
  py::dict out;
  out["vertices"] = array_of<2>(mesh.vertices);
  out["triangles"] = triangle_array(mesh);
  return out;
}

/// The box argument: None (derived from the points) or (o1, o2, [o3,] L).
template <std::size_t d>
dynmesh::Box<d> box_from(const py::object& box, std::span<const dynmesh::Point<d>> pts) {
  if (box.is_none()) return dynmesh::derive_box<d>(pts);
  const DoubleArray a = DoubleArray::ensure(box);
  if (!a || a.ndim() != 1 || a.shape(0) != static_cast<py::ssize_t>(d + 1))
    throw InputError(Kind::Malformed, "box must be (o1, o2" + std::string(d == 3 ? ", o3" : "") + ", L)");
  dynmesh::Box<d> b;
  for (std::size_t k = 0; k < d; ++k) b.origin[k] = a.at(static_cast<py::ssize_t>(k));
  b.side = a.at(static_cast<py::ssize_t>(d));
  dynmesh::validate_box(b);
  return b;
}

template <std::size_t d>
py::tuple box_tuple(const dynmesh::Box<d>& b) {
  py::tuple t(d + 1);
  for (std::size_t k = 0; k < d; ++k) t[k] = b.origin[k];
  t[d] = b.side;
  return t;
}

/// [("+", x, y[, z]), ("-", x, y[, z]), ...] as edits, all parsed before any is applied.
template <std::size_t d>
std::vector<dynmesh::Edit<d>> edits_from(const py::iterable& edits) {
  std::vector<dynmesh::Edit<d>> out;
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
    dynmesh::Edit<d> e{sign == "+" ? dynmesh::EditOp::Insert : dynmesh::EditOp::Delete, {}};
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

py::dict update_dict(const dynmesh::UpdateStats& u) {
  py::dict out;
  out["trace_distance"] = u.trace_distance;
  out["reexecuted"] = u.reexecuted;
  out["seconds"] = u.seconds;
  return out;
}

// --- Mesh ----------------------------------------------------------------------------------

class PyMesh {
 public:
  PyMesh(const py::object& points, const py::object& box, const py::object& min_angle, const std::string& postprocess) {
    dynmesh::MeshOptions options;
    if (postprocess == "hpu") {
      options.postprocess = dynmesh::Postprocess::Hpu;
      if (!min_angle.is_none()) options.min_angle = min_angle.cast<double>();
    } else if (postprocess == "quadtree") {
      options.postprocess = dynmesh::Postprocess::Quadtree;
      // The quadtree mesh's bound is fixed: a larger request cannot be honoured.
      if (!min_angle.is_none() && !(min_angle.cast<double>() <= dynmesh::kQuadtreeMinAngle))
        throw InputError(Kind::Malformed, "min_angle above the quadtree mesh's bound of 18.4 degrees");
    } else {
      throw InputError(Kind::Malformed, "postprocess must be \"hpu\" or \"quadtree\", got '" + postprocess + "'");
    }
    const std::vector<dynmesh::Point<2>> pts = points_from<2>(points, "points");
    const dynmesh::Box<2> b = box_from<2>(box, pts);
    py::gil_scoped_release release;
    mesh_.emplace(b, pts, options);
  }

  dynmesh::PointId insert(const py::object& p) {
    const dynmesh::Point<2> q = point_from<2>(p);
    py::gil_scoped_release release;
    return mesh_->insert(q);
  }

  void erase(const py::object& what) {
    if (py::isinstance<py::int_>(what)) {
      const auto id = what.cast<long long>();
      if (id < 0) throw InputError(Kind::Absent, "point id " + std::to_string(id) + " is not in the set");
      py::gil_scoped_release release;
      mesh_->erase(static_cast<dynmesh::PointId>(id));
      return;
    }
    const dynmesh::Point<2> q = point_from<2>(what);
    py::gil_scoped_release release;
    mesh_->erase(q);
  }

  std::vector<dynmesh::PointId> apply(const py::iterable& edits) {
    const std::vector<dynmesh::Edit<2>> es = edits_from<2>(edits);
    py::gil_scoped_release release;
    return mesh_->apply(es);
  }

  dynmesh::Mesh canonical() const {
    py::gil_scoped_release release;
    return mesh_->mesh();
  }

  py::array_t<double> points() const {
    std::vector<dynmesh::Point<2>> pts;
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

  const dynmesh::DynamicMesh& get() const { return *mesh_; }
  void check() const {
    py::gil_scoped_release release;
    mesh_->check_invariants();
  }

 private:
  std::optional<dynmesh::DynamicMesh> mesh_;
};

// --- Quadtree (2D or 3D) ------------------------------------------------------------------

class PyQuadtree {
 public:
  PyQuadtree(const py::object& points, int dim, const py::object& box) {
    if (dim == 2)
      build<2>(points, box);
    else if (dim == 3)
      build<3>(points, box);
    else
      throw InputError(Kind::Malformed, "dim must be 2 or 3, got " + std::to_string(dim));
  }

  int dim() const { return tree_.index() == 0 ? 2 : 3; }

  dynmesh::PointId insert(const py::object& p) {
    return std::visit([&](auto& t) { return insert_in(t, p); }, tree_);
  }
  void erase(const py::object& what) {
    std::visit([&](auto& t) { erase_in(t, what); }, tree_);
  }
  std::vector<dynmesh::PointId> apply(const py::iterable& edits) {
    return std::visit([&](auto& t) { return apply_in(t, edits); }, tree_);
  }
  py::tuple leaves() const {
    return std::visit([&](const auto& t) { return leaves_of(t); }, tree_);
  }
  py::array_t<double> points() const {
    return std::visit(
        [](const auto& t) {
          constexpr std::size_t d = std::remove_cvref_t<decltype(t)>::dim;
          std::vector<dynmesh::Point<d>> pts;
          for (const auto& entry : t->points()) pts.push_back(entry.second);
          return array_of<d>(pts);
        },
        tree_);
  }
  std::size_t size() const {
    return std::visit([](const auto& t) { return t->size(); }, tree_);
  }
  py::tuple box() const {
    return std::visit([](const auto& t) { return box_tuple(t->box()); }, tree_);
  }
  py::dict last_update() const {
    return std::visit([](const auto& t) { return update_dict(t->last_update()); }, tree_);
  }
  void check() const {
    std::visit(
        [](const auto& t) {
          py::gil_scoped_release release;
          t->check_invariants();
        },
        tree_);
  }

 private:
  template <std::size_t d>
  struct Tree {
    static constexpr std::size_t dim = d;
    std::optional<dynmesh::DynamicQuadtree<d>> tree;
    dynmesh::DynamicQuadtree<d>* operator->() { return &*tree; }
    const dynmesh::DynamicQuadtree<d>* operator->() const { return &*tree; }
  };
  template <class T>
  static constexpr std::size_t dim_of = std::remove_cvref_t<T>::dim;

  template <std::size_t d>
  void build(const py::object& points, const py::object& box) {
    const std::vector<dynmesh::Point<d>> pts = points_from<d>(points, "points");
    const dynmesh::Box<d> b = box_from<d>(box, pts);
    Tree<d> t;
    {
      py::gil_scoped_release release;
      t.tree.emplace(b, pts);
    }
    tree_ = std::move(t);
  }
  template <class T>
  static dynmesh::PointId insert_in(T& t, const py::object& p) {
    const auto q = point_from<dim_of<T>>(p);
    py::gil_scoped_release release;
    return t->insert(q);
  }
  template <class T>
  static void erase_in(T& t, const py::object& what) {
    if (py::isinstance<py::int_>(what)) {
      const auto id = what.cast<long long>();
      if (id < 0) throw InputError(Kind::Absent, "point id " + std::to_string(id) + " is not in the set");
      py::gil_scoped_release release;
      t->erase(static_cast<dynmesh::PointId>(id));
      return;
    }
    const auto q = point_from<dim_of<T>>(what);
    py::gil_scoped_release release;
    t->erase(q);
  }
  template <class T>
  static std::vector<dynmesh::PointId> apply_in(T& t, const py::iterable& edits) {
    const auto es = edits_from<dim_of<T>>(edits);
    py::gil_scoped_release release;
    return t->apply(es);
  }
  /// (level (L,), index (L, d), npoints (L,)), sorted by (level, index) as in `.cells`.
  template <class T>
  static py::tuple leaves_of(const T& t) {
    constexpr std::size_t d = dim_of<T>;
    std::vector<dynmesh::Leaf<d>> ls;
    {
      py::gil_scoped_release release;
      ls = t->leaves();
      std::sort(ls.begin(), ls.end(), [](const auto& a, const auto& b) { return a.cell < b.cell; });
    }
    const auto n = static_cast<py::ssize_t>(ls.size());
    py::array_t<std::int64_t> level(n), npoints(n);
    py::array_t<std::int64_t> index({n, static_cast<py::ssize_t>(d)});
    auto lv = level.mutable_unchecked<1>();
    auto np = npoints.mutable_unchecked<1>();
    auto ix = index.mutable_unchecked<2>();
    for (py::ssize_t i = 0; i < n; ++i) {
      const auto& leaf = ls[static_cast<std::size_t>(i)];
      lv(i) = leaf.cell.level;
      np(i) = leaf.npoints;
      for (std::size_t k = 0; k < d; ++k) ix(i, static_cast<py::ssize_t>(k)) = static_cast<std::int64_t>(leaf.cell.index[k]);
    }
    return py::make_tuple(level, index, npoints);
  }

  std::variant<Tree<2>, Tree<3>> tree_;
};

}  // namespace

PYBIND11_MODULE(_dynmesh, m) {
  m.doc() = "dynmesh: dynamic quality meshes of changing point sets (docs/FORMATS.md, \"The Python module\")";
  m.attr("__version__") = DYNMESH_VERSION;

  // dynmesh.InputError(ValueError): the library's InputError with its kind and indices.
  static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      py::object err = py::reinterpret_borrow<py::object>(input_error.ptr())(e.what());
      err.attr("kind") = dynmesh::kind_name(e.kind());
      err.attr("indices") = py::tuple(py::cast(e.point_indices()));
      err.attr("index") = e.point_indices().empty() ? py::object(py::none()) : py::cast(e.point_indices().back());
      PyErr_SetObject(input_error.ptr(), err.ptr());
    }
  });

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
            const dynmesh::MeshChange& c = s.get().last_change();
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
                               return s.get().options().postprocess == dynmesh::Postprocess::Hpu
                                          ? s.get().options().min_angle
                                          : dynmesh::kQuadtreeMinAngle;
                             })
      .def("__len__", [](const PyMesh& s) { return s.get().size(); })
      .def("check", &PyMesh::check, "run every invariant checker (raises on a broken contract)")
      .def(
          "to_meshio",
          [](const PyMesh& s) {
            const dynmesh::Mesh mesh = s.canonical();
            const py::module_ meshio = py::module_::import("meshio");
            // Points with z = 0: VTK and Gmsh store 3D points (meshio warns on 2D ones).
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
          },
          "the mesh as a meshio.Mesh: points (V, 3) with z = 0, one \"triangle\" cell block (needs meshio)");

  m.def(
      "triangulate",
      [](const py::object& points, const py::object& min_angle, const py::object& box) {
        const std::vector<dynmesh::Point<2>> pts = points_from<2>(points, "points");
        const dynmesh::Box<2> b = box_from<2>(box, pts);
        const double bound = min_angle.is_none() ? dynmesh::kHpuDefaultMinAngle : min_angle.cast<double>();
        dynmesh::Mesh mesh;
        {
          py::gil_scoped_release release;
          mesh = dynmesh::HpuMesh(b, pts, bound).mesh();
        }
        return mesh_dict(mesh);
      },
      py::arg("points"), py::arg("min_angle") = py::none(), py::arg("box") = py::none(),
      "the static quality mesh (HpuMesh) of (n, 2) points: {\"vertices\", \"triangles\"}");

  py::class_<PyQuadtree>(m, "Quadtree", "The well-graded quadtree (2D) or octree (3D) T* of a changing point set.")
      .def(py::init<const py::object&, int, const py::object&>(), py::arg("points"), py::arg("dim") = 2,
           py::arg("box") = py::none())
      .def("insert", &PyQuadtree::insert, py::arg("point"))
      .def("erase", &PyQuadtree::erase, py::arg("point"))
      .def("apply", &PyQuadtree::apply, py::arg("edits"))
      .def("leaves", &PyQuadtree::leaves, "(level (L,), index (L, dim), npoints (L,)), sorted as in .cells")
      .def_property_readonly("points", &PyQuadtree::points)
      .def_property_readonly("dim", &PyQuadtree::dim)
      .def_property_readonly("box", &PyQuadtree::box)
      .def_property_readonly("last_update", &PyQuadtree::last_update)
      .def("__len__", &PyQuadtree::size)
      .def("check", &PyQuadtree::check);
}
