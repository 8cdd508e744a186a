"""Shared fixtures of the Python module's tests (tests/python/, run by ctest as python.pytest).

The module comes from PYTHONPATH (the build tree's python/ directory, set by
tests/python/CMakeLists.txt); DYNMESH_CLI names the `dynmesh` command whose files the module
must reproduce; the small inputs are the command tests' (tests/cli/data/).
"""
import os
import pathlib
import subprocess

import numpy as np
import pytest

DATA = pathlib.Path(__file__).resolve().parent.parent / "cli" / "data"


@pytest.fixture(scope="session")
def data():
    return DATA


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("DYNMESH_CLI")
    if not path:
        pytest.skip("DYNMESH_CLI is not set (run through ctest)")
    return path


def run_cli(cli, *args, cwd):
    """Runs `dynmesh ARGS...` in cwd; fails the test with its stderr when it fails."""
    done = subprocess.run([cli, *map(str, args)], cwd=cwd, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done


def read_node_points(path):
    """The coordinates of a Triangle .node file (header skipped, comments dropped)."""
    rows = []
    for line in pathlib.Path(path).read_text().splitlines():
        fields = line.split("#", 1)[0].split()
        if fields:
            rows.append(fields)
    dim = int(rows[0][1])
    return np.array([[float(v) for v in r[1 : 1 + dim]] for r in rows[1:]])


def read_edits(path):
    """An edit script as [("+", x, y[, z]), ...]."""
    edits = []
    for line in pathlib.Path(path).read_text().splitlines():
        fields = line.split("#", 1)[0].split()
        if fields:
            edits.append((fields[0], *map(float, fields[1:])))
    return edits


def format_node(vertices, box):
    """The .node text `dynmesh mesh` writes (docs/FORMATS.md) in 2D or 3D (by the box's
    length): %.17g, marker 1 on the box boundary."""
    *origin, side = box
    dim = len(origin)
    far = [o + side for o in origin]
    lines = [f"{len(vertices)} {dim} 0 1"]
    for i, v in enumerate(vertices, start=1):
        on_box = any(v[a] == origin[a] or v[a] == far[a] for a in range(dim))
        lines.append("%d %s %d" % (i, " ".join("%.17g" % c for c in v), 1 if on_box else 0))
    return "\n".join(lines) + "\n"


def format_ele(cells):
    """The .ele text `dynmesh mesh` writes: numbered from 1, vertices from 1; triangles
    (`<#> 3 0`) or tetrahedra (`<#> 4 0`)."""
    cells = list(cells)
    per = len(cells[0]) if cells else 3
    lines = [f"{len(cells)} {per} 0"]
    for i, c in enumerate(cells, start=1):
        lines.append(f"{i} " + " ".join(str(v + 1) for v in c))
    return "\n".join(lines) + "\n"


def triangle_set(vertices, triangles):
    """The triangles (or tetrahedra) as a set of corner tuples (the feed's form)."""
    return {tuple(map(tuple, vertices[t])) for t in triangles}
