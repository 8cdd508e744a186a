// module.cpp — the Python module `dynmesh` (its compiled part, `dynmesh._dynmesh`), pybind11.
//
// Purpose: makes the module: its version, its exception, and the bindings of bindings.hpp
// (Mesh and triangulate, Quadtree). The contract is docs/FORMATS.md, "The Python module
// `dynmesh`"; the package's __init__.py re-exports what is made here.
// Invariants: every library InputError becomes dynmesh.InputError (a ValueError) carrying
// the library's message, `kind` (the InputError::Kind name), `indices` (the points or edits
// involved, InputError::point_indices) and `index` (the failing one: the last of them, or
// None). Other exceptions take pybind11's defaults (InvariantError, a library bug, is a
// RuntimeError).
// Complexity: O(1).
// Paper: none.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <exception>

#include "bindings.hpp"
#include "dynmesh/errors.hpp"

namespace py = pybind11;

PYBIND11_MODULE(_dynmesh, m) {
  m.doc() = "dynmesh: dynamic quality meshes of changing point sets (docs/FORMATS.md, \"The Python module\")";
  m.attr("__version__") = DYNMESH_VERSION;

  // dynmesh.InputError(ValueError): the library's InputError with its kind and indices.
  static py::exception<dynmesh::InputError> input_error(m, "InputError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const dynmesh::InputError& e) {
      py::object err = py::reinterpret_borrow<py::object>(input_error.ptr())(e.what());
      err.attr("kind") = dynmesh::kind_name(e.kind());
      err.attr("indices") = py::tuple(py::cast(e.point_indices()));
      err.attr("index") = e.point_indices().empty() ? py::object(py::none()) : py::cast(e.point_indices().back());
      PyErr_SetObject(input_error.ptr(), err.ptr());
    }
  });

  dynmesh::python::bind_mesh(m);
  dynmesh::python::bind_quadtree(m);
}
