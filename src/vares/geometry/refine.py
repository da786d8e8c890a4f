"""Refining a triangle mesh on its own faces, so that the surface stays exactly the same.

Every new node is the midpoint of an edge of the mesh, and every new triangle lies in the plane of
the triangle it comes from: the refined mesh is the same polyhedral surface (same shape, same
area to round-off), only with smaller cells. A round of refinement splits every triangle whose
longest edge is longer than the target into four (its edge midpoints: "red", the four are similar
to it), every triangle with two or three split edges likewise, and a triangle with one split
edge into two (from the opposite corner to the midpoint: "green"), so that no node hangs on
an edge. Rounds repeat until no edge is longer than the target. A mesh whose cells are all too
large is subdivided uniformly (1-to-4 midpoint subdivision): every angle is kept.
"""

from __future__ import annotations

import numpy as np

from .mesh import SurfaceMesh
from .surface_lines import check_triangles, mesh_edges

__all__ = ["MAX_ROUNDS", "refine", "refine_once"]

#: Rounds of refinement at most (each one halves the cells it splits: 4 096 times as many cells).
MAX_ROUNDS = 6


def refine_once(mesh: SurfaceMesh, longest: float) -> SurfaceMesh:
    """One round of refinement (module docs) of the triangles whose longest edge exceeds
    ``longest`` (mesh units); the mesh is returned unchanged if none does."""
    triangles = check_triangles(mesh)
    points = mesh.points
    edges, side = mesh_edges(triangles)  # side (m, 3): the edge of corner k → k + 1
    length = np.linalg.norm(points[edges[:, 1]] - points[edges[:, 0]], axis=1)
    split = np.zeros(len(edges), dtype=bool)
    split[np.unique(side[length[side].max(axis=1) > longest])] = True
    if not split.any():
        return mesh
    while True:  # closure: a cell with two split edges is split into four
        count = split[side].sum(axis=1)
        more = np.unique(side[count == 2])
        if not (~split[more]).any():
            break
        split[more] = True
    midpoint = np.full(len(edges), -1, dtype=np.int64)
    midpoint[split] = len(points) + np.arange(int(split.sum()))
    new_points = np.vstack([points, 0.5 * (points[edges[split, 0]] + points[edges[split, 1]])])
    count = split[side].sum(axis=1)
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    m = midpoint[side]  # (m, 3): midpoint of side k, or −1
    blocks = [triangles[count == 0]]
    red = count == 3
    ab, bc, ca = m[red, 0], m[red, 1], m[red, 2]
    blocks += [
        np.stack(corners, axis=1)
        for corners in (
            (a[red], ab, ca),
            (ab, b[red], bc),
            (ca, bc, c[red]),
            (ab, bc, ca),
        )
    ]
    for k in range(3):  # green: side k (corner k → k + 1) split, the opposite corner k + 2
        green = (count == 1) & (m[:, k] >= 0)
        first, second, opposite = (triangles[green, (k + j) % 3] for j in range(3))
        middle = m[green, k]
        blocks += [
            np.stack([first, middle, opposite], axis=1),
            np.stack([middle, second, opposite], axis=1),
        ]
    return SurfaceMesh(new_points, {"triangle": np.vstack(blocks)})


def refine(
    mesh: SurfaceMesh, longest: float, max_rounds: int = MAX_ROUNDS
) -> tuple[SurfaceMesh, int]:
    """The triangle mesh refined on its own faces (module docs) until no edge is longer than
    ``longest`` (mesh units), or after ``max_rounds`` rounds (``longest = 0``: uniform 1-to-4
    subdivision, ``max_rounds`` times); and the number of rounds done."""
    if not longest >= 0:
        raise ValueError(f"the longest edge must be ≥ 0; got {longest!r}")
    rounds = 0
    while rounds < max_rounds:
        finer = refine_once(mesh, longest)
        if finer is mesh:
            break
        mesh, rounds = finer, rounds + 1
    return mesh, rounds
