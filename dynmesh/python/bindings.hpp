// bindings.hpp (private to the Python module) — the parts of `dynmesh._dynmesh`.
//
// Purpose: module.cpp makes the module and its exception, then asks each binding to add its
// classes and functions: bind_mesh (mesh_binding.cpp: Mesh, triangulate) and bind_quadtree
// (quadtree_binding.cpp: Quadtree). docs/FORMATS.md, "The Python module `dynmesh`", is the
// contract of all three.
// Invariants: each bind_* is called once, on the module being initialised.
// Complexity: O(1).
// Paper: none.
#pragma once

#include <pybind11/pybind11.h>

namespace dynmesh::python {

void bind_mesh(pybind11::module_& m);
void bind_quadtree(pybind11::module_& m);

}  // namespace dynmesh::python
