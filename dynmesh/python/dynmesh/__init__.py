"""dynmesh: dynamic quality meshes of changing point sets.

The contract is docs/FORMATS.md, "The Python module `dynmesh`":

    import dynmesh
    m = dynmesh.Mesh(points)            # (n, 2) float64; box=None, min_angle=20.7, postprocess="hpu"
    i = m.insert((x, y)); m.erase(i)    # one propagation each
    m.apply([("+", x, y), ("-", x, y)]) # one propagation
    m.vertices, m.triangles             # canonical, as `dynmesh mesh` writes .node/.ele
    removed, added = m.last_change      # the triangles of the last update, by corners
    m3 = dynmesh.Mesh(points3)          # (n, 3): the octree's tetrahedral mesh (postprocess "quadtree")
    m3.vertices, m3.tetrahedra          # (V, 3) float64 and (T, 4) int64, canonical
    m.cells, m.cell_type                # the simplices of either dimension, "triangle" or "tetra"
    dynmesh.triangulate(points)         # static: {"vertices", "triangles"}
    dynmesh.Quadtree(points, dim=2)     # the quadtree (octree) alone

Bad input raises dynmesh.InputError, a ValueError, and leaves the object as it was.
"""
from ._dynmesh import InputError, Mesh, Quadtree, __version__, triangulate

__all__ = ["InputError", "Mesh", "Quadtree", "triangulate", "__version__"]
