"""The README's promise after `pip install --no-build-isolation .` in a new virtual
environment (run by pip_install_test.sh with that environment's python):

    install_check.py DYNMESH_CLI WORK_DIR

meshes 2,000 points, inserts and erases points, and checks that vertices/triangles equal
`dynmesh mesh`'s .node/.ele on the same final points, that to_meshio() writes a VTK file
meshio reads back, and that a NaN point raises ValueError and leaves the mesh as it was.
"""
import pathlib
import subprocess
import sys

import meshio
import numpy as np

import dynmesh

cli, work = sys.argv[1], pathlib.Path(sys.argv[2])
assert "site-packages" in dynmesh.__file__, f"dynmesh imported from {dynmesh.__file__}, not the installed package"

rng = np.random.default_rng(11)
points = rng.random((2000, 2))
m = dynmesh.Mesh(points)
ids = [m.insert(tuple(p)) for p in 0.1 + 0.8 * rng.random((10, 2))]
for i in ids[:5]:
    m.erase(i)
m.erase(0)

final = m.points
(work / "final.txt").write_text("".join("%.17g %.17g\n" % (x, y) for x, y in final))
o1, o2, side = m.box
subprocess.run([cli, "mesh", "final.txt", "--box", "%.17g" % o1, "%.17g" % o2, "%.17g" % side, "-o", "final"],
               cwd=work, check=True)
node = np.loadtxt(work / "final.node", skiprows=1)
ele = np.loadtxt(work / "final.ele", skiprows=1, dtype=np.int64)
assert np.array_equal(node[:, 1:3], m.vertices)
assert np.array_equal(ele[:, 1:] - 1, m.triangles)

m.to_meshio().write(work / "mesh.vtk")
back = meshio.read(work / "mesh.vtk")
assert np.array_equal(back.points[:, :2], m.vertices)
assert np.array_equal(back.cells_dict["triangle"], m.triangles)

vertices, triangles = m.vertices, m.triangles
try:
    m.insert((float("nan"), 0.5))
    raise SystemExit("a NaN point was accepted")
except ValueError as err:
    print("NaN refused:", err)
assert np.array_equal(m.vertices, vertices) and np.array_equal(m.triangles, triangles)
print(f"install check: {len(m)} points, {len(m.triangles)} triangles: ok")
