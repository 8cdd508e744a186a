"""dynmesh.Quadtree against `dynmesh quadtree`'s .cells, and its updates against a rebuild."""
import numpy as np
import pytest

import dynmesh
from conftest import read_edits, read_node_points, run_cli


def read_cells(path):
    lines = path.read_text().splitlines()
    box = tuple(float(v) for v in lines[2].split()[2:])
    rows = np.array([[int(v) for v in line.split()] for line in lines[3:]], dtype=np.int64)
    return box, rows


def leaf_rows(tree):
    level, index, npoints = tree.leaves()
    return np.column_stack([level, index, npoints])


@pytest.mark.parametrize("name,dim", [("2d", 2), ("3d", 3)])
def test_leaves_equal_the_command_after_the_same_edits(cli, data, tmp_path, name, dim):
    points = read_node_points(data / f"points{name}.node")
    tree = dynmesh.Quadtree(points, dim=dim)
    assert tree.dim == dim and len(tree) == len(points)
    edits = read_edits(data / f"edits{name}.txt")
    for edit in edits[:5]:
        tree.insert(edit[1:]) if edit[0] == "+" else tree.erase(edit[1:])
    tree.apply(edits[5:])
    run_cli(cli, "quadtree", data / f"points{name}.node", "--edits", data / f"edits{name}.txt", "--cells", "out.cells",
            cwd=tmp_path)
    box, rows = read_cells(tmp_path / "out.cells")
    assert tree.box == box
    assert np.array_equal(leaf_rows(tree), rows)
    # The same leaves as a tree built on the final points in the same box.
    fresh = dynmesh.Quadtree(tree.points, dim=dim, box=tree.box)
    assert np.array_equal(leaf_rows(fresh), rows)
    assert tree.last_update["trace_distance"] > 0
    tree.check()


def test_erase_by_id():
    tree = dynmesh.Quadtree([[0.1, 0.2], [0.4, 0.4], [0.41, 0.39]])
    i = tree.insert((0.3, 0.7))
    tree.erase(i)
    tree.erase(1)
    assert len(tree) == 2
