// quadtree_binding.cpp — dynmesh.Quadtree (DynamicQuadtree<2> or <3>).
//
// Purpose: the well-graded quadtree (octree) T* of a changing point set, as Python sees it
// (docs/FORMATS.md, "The Python module `dynmesh`"): insert, erase, apply, and the leaves as
// the rows of `dynmesh quadtree --cells`.
// Invariants: one class for both dimensions (a variant of the two trees, chosen by `dim`);
// the arguments are converted before the library is called, and its updates are
// failure-atomic, so a failed call changes nothing. The GIL is released around building,
// updating and listing the leaves.
// Complexity: as DynamicQuadtree (O(lg L/s) expected trace distance per update), plus O(n)
// copies of the arrays that cross; leaves() O(L log L).
// Paper: Acar and Hudson (QuadTreeRefine, Figure 2), through dynmesh/dynamic_quadtree.hpp.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "dynmesh/box.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/errors.hpp"

namespace dynmesh::python {
namespace {

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

  PointId insert(const py::object& p) {
    return std::visit([&](auto& t) { return insert_in(t, p); }, tree_);
  }
  void erase(const py::object& what) {
    std::visit([&](auto& t) { erase_in(t, what); }, tree_);
  }
  std::vector<PointId> apply(const py::iterable& edits) {
    return std::visit([&](auto& t) { return apply_in(t, edits); }, tree_);
  }
  py::tuple leaves() const {
    return std::visit([&](const auto& t) { return leaves_of(t); }, tree_);
  }
  py::array_t<double> points() const {
    return std::visit(
        [](const auto& t) {
          constexpr std::size_t d = std::remove_cvref_t<decltype(t)>::dim;
          std::vector<Point<d>> pts;
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
    std::optional<DynamicQuadtree<d>> tree;
    DynamicQuadtree<d>* operator->() { return &*tree; }
    const DynamicQuadtree<d>* operator->() const { return &*tree; }
  };
  template <class T>
  static constexpr std::size_t dim_of = std::remove_cvref_t<T>::dim;

  template <std::size_t d>
  void build(const py::object& points, const py::object& box) {
    const std::vector<Point<d>> pts = points_from<d>(points, "points");
    const Box<d> b = box_from<d>(box, pts);
    Tree<d> t;
    {
      py::gil_scoped_release release;
      t.tree.emplace(b, pts);
    }
    tree_ = std::move(t);
  }
  template <class T>
  static PointId insert_in(T& t, const py::object& p) {
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
      t->erase(static_cast<PointId>(id));
      return;
    }
    const auto q = point_from<dim_of<T>>(what);
    py::gil_scoped_release release;
    t->erase(q);
  }
  template <class T>
  static std::vector<PointId> apply_in(T& t, const py::iterable& edits) {
    const auto es = edits_from<dim_of<T>>(edits);
    py::gil_scoped_release release;
    return t->apply(es);
  }
  /// (level (L,), index (L, d), npoints (L,)), sorted by (level, index) as in `.cells`.
  template <class T>
  static py::tuple leaves_of(const T& t) {
    constexpr std::size_t d = dim_of<T>;
    std::vector<Leaf<d>> ls;
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

void bind_quadtree(py::module_& m) {
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

}  // namespace dynmesh::python
