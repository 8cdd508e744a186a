"""Mesh.to_meshio() round-trips through meshio's VTK and Gmsh writers."""
import numpy as np
import pytest

import dynmesh

meshio = pytest.importorskip("meshio")


@pytest.mark.parametrize("name,file_format", [("mesh.vtk", "vtk"), ("mesh.msh", "gmsh22")])
def test_to_meshio_round_trip(tmp_path, name, file_format):
    rng = np.random.default_rng(3)
    m = dynmesh.Mesh(rng.random((200, 2)))
    m.insert((0.5, 0.5))
    out = m.to_meshio()
    assert isinstance(out, meshio.Mesh)
    assert out.points.shape == (len(m.vertices), 3) and np.all(out.points[:, 2] == 0)
    path = tmp_path / name
    if file_format == "gmsh22":
        meshio.write(path, out, file_format=file_format, binary=False)
    else:
        meshio.write(path, out, file_format=file_format)
    back = meshio.read(path)
    assert np.array_equal(back.points[:, :2], m.vertices)
    assert np.all(back.points[:, 2:] == 0)
    triangles = [c.data for c in back.cells if c.type == "triangle"]
    assert len(triangles) == 1
    assert np.array_equal(triangles[0], m.triangles)
