"""Move a few points of a mesh and draw the mesh before and after (matplotlib).

    python3 examples/move_points.py [--out move_points.png]

Meshes 300 clustered points with dynmesh.Mesh, then moves five of them: each move is an
erase and an insert, applied together as one update (Mesh.apply), so that only the
triangles near the moved points change. The picture shows the mesh before, the mesh after,
and the triangles the update removed (red) and added (blue), taken from Mesh.last_change.
"""
import argparse

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import PolyCollection

import dynmesh


def draw(ax, mesh, title, inputs):
    ax.triplot(mesh.vertices[:, 0], mesh.vertices[:, 1], mesh.triangles, color="0.55", linewidth=0.4)
    ax.plot(inputs[:, 0], inputs[:, 1], "k.", markersize=2.5)
    ax.set_title(title, fontsize=10)
    ax.set_aspect("equal")
    ax.set_axis_off()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="move_points.png", help="the picture (PNG or SVG)")
    args = parser.parse_args()

    rng = np.random.default_rng(2)
    centres = np.array([[0.3, 0.3], [0.7, 0.6], [0.4, 0.75]])
    points = np.concatenate([c + 0.08 * rng.standard_normal((100, 2)) for c in centres])
    mesh = dynmesh.Mesh(points)

    fig, axes = plt.subplots(1, 3, figsize=(13, 4.6))
    draw(axes[0], mesh, f"before: {len(mesh.triangles)} triangles", mesh.points)

    # Five points move by a small step: erase each, insert it at its new place, one update.
    moved = points[:5]
    edits = [("-", x, y) for x, y in moved] + [("+", x + 0.06, y - 0.04) for x, y in moved]
    mesh.apply(edits)
    removed, added = mesh.last_change
    draw(axes[1], mesh, f"after moving 5 points: {len(mesh.triangles)} triangles", mesh.points)

    draw(axes[2], mesh, f"the update: {len(removed)} removed, {len(added)} added", mesh.points)
    axes[2].add_collection(PolyCollection(removed, facecolor="none", edgecolor="tab:red", linewidth=0.8))
    axes[2].add_collection(PolyCollection(added, facecolor="tab:blue", alpha=0.25, edgecolor="tab:blue",
                                          linewidth=0.6))
    axes[2].plot(moved[:, 0], moved[:, 1], "rx", markersize=5)
    fig.tight_layout()
    fig.savefig(args.out, dpi=80)
    print(f"{args.out}: {len(mesh.points)} points, trace distance {mesh.last_update['trace_distance']}")


if __name__ == "__main__":
    main()
