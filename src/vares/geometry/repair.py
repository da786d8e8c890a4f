"""Mesh repair, said aloud: what scans and CAD exports need before they are a surface.

:func:`repair` takes the points and faces of a file and makes the clear fixes, each counted in a
:class:`RepairReport`:

- polygons (more than four corners) are triangulated (ear clipping in their best-fit plane);
- nodes closer than a tolerance relative to the median edge length are welded (an unwelded
  "triangle soup", seams of separately meshed faces);
- cells that collapse (a repeated node after welding), duplicate cells, and zero-area cells on the
  boundary are dropped (a zero-area cell inside the surface would leave a slit: it is refused by
  the validation instead, naming the cell);
- cells are oriented consistently with the majority of their neighbours;
- a node where separate fans of cells touch (a "bow-tie") is split, one node per fan;
- nodes that belong to no cell are dropped.

What is not clear — non-manifold edges or nodes, several pieces, a closed surface — is left to
:class:`vares.geometry.SurfaceMesh`, whose errors name the place and say what to do.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import breadth_first_order, connected_components

from .._jit import njit
from .elements import ELEMENTS
from .mesh import EdgeTable, MeshError, corner_fans, index_listing
from .weld import coincident_nodes

__all__ = ["WELD_TOLERANCE", "RepairReport", "Repaired", "repair", "triangulate_polygon"]

#: Nodes closer than this fraction of the median edge length are the same node.
WELD_TOLERANCE = 1e-6
#: Cells whose smallest corner area is below this fraction of the squared model size are flat.
_FLAT = 1e-12


@dataclass(frozen=True)
class RepairReport:
    """What :func:`repair` changed; all zero for a clean mesh."""

    triangulated_polygons: int = 0
    welded_nodes: int = 0
    collapsed_cells: int = 0
    duplicate_cells: int = 0
    flat_boundary_cells: int = 0
    flipped_cells: int = 0
    split_nodes: int = 0
    unused_nodes: int = 0
    weld_tolerance: float = 0.0

    @property
    def changed(self) -> bool:
        return bool(self.actions())

    def actions(self) -> list[str]:
        """One phrase per change made, for summaries and warnings."""
        out = []
        if self.triangulated_polygons:
            out.append(f"triangulated {self.triangulated_polygons} polygon(s)")
        if self.welded_nodes:
            out.append(
                f"welded {self.welded_nodes} node(s) onto others within "
                f"{self.weld_tolerance:.3g} (length units)"
            )
        if self.collapsed_cells:
            out.append(f"dropped {self.collapsed_cells} cell(s) that collapsed when welded")
        if self.duplicate_cells:
            out.append(f"dropped {self.duplicate_cells} duplicate cell(s)")
        if self.flat_boundary_cells:
            out.append(f"dropped {self.flat_boundary_cells} zero-area cell(s) on the boundary")
        if self.flipped_cells:
            out.append(f"reoriented {self.flipped_cells} cell(s) to match their neighbours")
        if self.split_nodes:
            out.append(f"split {self.split_nodes} node(s) where separate fans of cells touched")
        if self.unused_nodes:
            out.append(f"dropped {self.unused_nodes} node(s) that belong to no cell")
        return out

    def to_dict(self) -> dict[str, object]:
        return {**self.__dict__, "actions": self.actions()}


@dataclass
class Repaired:
    """The repaired points ``(n, 3)`` and cells, and for every kept cell the index of the face
    of the input it comes from (to carry cell data along)."""

    points: np.ndarray
    cells: dict[str, np.ndarray]
    cell_map: np.ndarray
    report: RepairReport = field(default_factory=RepairReport)


def repair(
    points: np.ndarray,
    cells: dict[str, np.ndarray],
    polygons: list[np.ndarray] | None = None,
    *,
    weld: bool = True,
) -> Repaired:
    """Repair a surface given as points, triangle/quad blocks and polygons (module docs).

    Input faces are numbered block by block in the order of ``cells``, then the polygons;
    :attr:`Repaired.cell_map` refers to that numbering. With ``weld=False`` only polygons are
    triangulated and unused nodes dropped.
    """
    points = np.asarray(points, dtype=float)
    bad = np.flatnonzero(~np.isfinite(points).all(axis=1))
    if bad.size:
        raise MeshError(f"non-finite coordinates (NaN or inf) at nodes {index_listing(bad)}")
    blocks, owners, start = {}, {}, 0
    for cell_type, block in cells.items():
        block = np.asarray(block, dtype=np.int64).reshape(-1, 3 if cell_type == "triangle" else 4)
        blocks[cell_type] = block
        owners[cell_type] = np.arange(start, start + len(block))
        start += len(block)
    triangulated = 0
    if polygons:
        extra, extra_owner = [], []
        for k, polygon in enumerate(polygons):
            triangles = triangulate_polygon(points, np.asarray(polygon, dtype=np.int64))
            extra.append(triangles)
            extra_owner.append(np.full(len(triangles), start + k))
        triangulated = len(polygons)
        blocks["triangle"] = np.vstack([blocks.get("triangle", np.zeros((0, 3), int)), *extra])
        owners["triangle"] = np.concatenate(
            [owners.get("triangle", np.zeros(0, int)), *extra_owner]
        )
    counts = dict(triangulated_polygons=triangulated)
    if weld:
        tolerance = WELD_TOLERANCE * _median_edge(points, blocks)
        mapping = coincident_nodes(points, tolerance)
        counts.update(welded_nodes=int(points.shape[0] - np.unique(mapping).size))
        counts.update(weld_tolerance=tolerance)
        blocks = {t: mapping[b] for t, b in blocks.items()}
        marked = {t: _collapsed(b) for t, b in blocks.items()}
        blocks, owners, counts["collapsed_cells"] = _drop(blocks, owners, marked)
        marked = {t: _duplicates(b) for t, b in blocks.items()}
        blocks, owners, counts["duplicate_cells"] = _drop(blocks, owners, marked)
        marked = _flat_on_boundary(points, blocks)
        blocks, owners, counts["flat_boundary_cells"] = _drop(blocks, owners, marked)
        blocks, counts["flipped_cells"] = _orient(blocks, len(points))
        points, blocks, counts["split_nodes"] = _split_bow_ties(points, blocks)
    used = np.zeros(len(points), dtype=bool)
    for block in blocks.values():
        used[block.ravel()] = True
    renumber = np.full(len(points), -1, dtype=np.int64)
    renumber[used] = np.arange(used.sum())
    # the nodes welded onto others are unused now: counted as welded, not again as unused
    counts["unused_nodes"] = int((~used).sum()) - counts.get("welded_nodes", 0)
    kept = {t: renumber[b] for t, b in blocks.items() if len(b)}
    cell_map = np.concatenate([owners[t] for t in kept]) if kept else np.zeros(0, int)
    return Repaired(points[used], kept, cell_map, RepairReport(**counts))


def _median_edge(points: np.ndarray, blocks: dict[str, np.ndarray]) -> float:
    lengths = []
    for b in blocks.values():
        for i in range(b.shape[1] if len(b) else 0):
            d = points[b[:, i]] - points[b[:, i - 1]]
            lengths.append(np.sqrt(np.einsum("ij,ij->i", d, d)))
    lengths = np.concatenate(lengths) if lengths else np.zeros(0)
    lengths = lengths[lengths > 0]
    return float(np.median(lengths)) if lengths.size else 0.0


def _drop(blocks, owners, marked):
    """Blocks and owners without the cells ``marked`` (a mask per block), and how many."""
    dropped = 0
    out_blocks, out_owners = {}, {}
    for cell_type, block in blocks.items():
        bad = marked[cell_type]
        dropped += int(bad.sum())
        out_blocks[cell_type], out_owners[cell_type] = block[~bad], owners[cell_type][~bad]
    return out_blocks, out_owners, dropped


def _collapsed(block: np.ndarray) -> np.ndarray:
    return (np.diff(np.sort(block, axis=1), axis=1) == 0).any(axis=1)


def _duplicates(block: np.ndarray) -> np.ndarray:
    ordered = np.sort(block, axis=1)
    order = np.lexsort(ordered.T[::-1])
    same = np.zeros(len(block), dtype=bool)
    same[1:] = (ordered[order[1:]] == ordered[order[:-1]]).all(axis=1)
    duplicate = np.zeros(len(block), dtype=bool)
    duplicate[order[same]] = True  # every repeat after the first of its kind
    return duplicate


def _flat_on_boundary(points: np.ndarray, blocks: dict[str, np.ndarray]) -> dict:
    """Zero-area cells with an edge on the boundary, a mask per block; the boundary is that of
    all the blocks together. (A quad with a straight corner has an area: it is kept, and the
    validation names it.)"""
    scale = float(np.ptp(points, axis=0).max()) or 1.0
    flat = {
        t: ELEMENTS[t].areas(points, b) <= _FLAT * scale**2 if len(b) else np.zeros(0, dtype=bool)
        for t, b in blocks.items()
    }
    if not any(mask.any() for mask in flat.values()):
        return flat
    table = EdgeTable.of_cells(blocks, len(points))
    at_boundary = np.zeros(sum(len(b) for b in blocks.values()), dtype=bool)
    at_boundary[table.owner[table.counts[table.edge_id] == 1]] = True
    start = 0
    for t, block in blocks.items():
        flat[t] &= at_boundary[start : start + len(block)]
        start += len(block)
    return flat


def _orient(blocks: dict[str, np.ndarray], num_points: int) -> tuple[dict[str, np.ndarray], int]:
    """Flip cells so that neighbours traverse their shared edge in opposite directions; within
    each piece the orientation of the majority of cells is kept. Non-manifold edges are skipped
    (the validation names them)."""
    total = sum(len(b) for b in blocks.values())
    if not total:
        return blocks, 0
    table = EdgeTable.of_cells(blocks, num_points)
    directed, owner, counts = table.directed, table.owner, table.counts
    a, b = table.pairs()
    manifold = counts[table.edge_id[a]] == 2
    a, b = a[manifold], b[manifold]
    same = (directed[a, 0] == directed[b, 0]).astype(np.int8)
    if not same.any():
        return blocks, 0
    graph = sp.coo_matrix(
        (
            np.concatenate([same + 1, same + 1]),
            (np.r_[owner[a], owner[b]], np.r_[owner[b], owner[a]]),
        ),
        shape=(total, total),
    ).tocsr()
    flip = np.zeros(total, dtype=bool)
    _, label = connected_components(graph, directed=False)
    for piece in np.unique(label):
        root = int(np.flatnonzero(label == piece)[0])
        visit, parent = breadth_first_order(graph, root, directed=False)
        _propagate(visit, parent, graph.indptr, graph.indices, graph.data, flip)
        members = label == piece
        if flip[members].sum() * 2 > members.sum():
            flip[members] = ~flip[members]
    out, start = {}, 0
    for cell_type, block in blocks.items():
        turned = flip[start : start + len(block)]
        block = block.copy()
        block[turned] = block[turned, ::-1]
        out[cell_type] = block
        start += len(block)
    return out, int(flip.sum())


def _split_bow_ties(points: np.ndarray, blocks: dict[str, np.ndarray]):
    """A new node for every fan of cells at a node beyond its first (module docs)."""
    names = list(blocks)
    if not sum(len(b) for b in blocks.values()):
        return points, blocks, 0
    table = EdgeTable.of_cells(blocks, len(points))
    # the block, row and column (corner) of every directed edge's start, in the table's order
    offsets = np.cumsum([0, *(len(b) for b in blocks.values())])
    block_of = np.concatenate([np.full(b.size, k) for k, b in enumerate(blocks.values())])
    col_of = np.concatenate([np.repeat(np.arange(b.shape[1]), len(b)) for b in blocks.values()])
    row_of = table.owner - offsets[block_of]
    node, fan = corner_fans(table)
    fans = int(fan.max()) + 1 if fan.size else 1
    keys, label = np.unique(node.astype(np.int64) * fans + fan, return_inverse=True)
    pairs = np.column_stack([keys // fans, keys % fans])  # (node, fan), sorted by node
    extra = np.r_[False, pairs[1:, 0] == pairs[:-1, 0]]  # a node's second fan onward
    if not extra.any():
        return points, blocks, 0
    new_node = np.full(len(pairs), -1)
    new_node[extra] = len(points) + np.arange(extra.sum())
    moved = new_node[label.ravel()] >= 0
    block_of, row_of, col_of = block_of[moved], row_of[moved], col_of[moved]
    out = {name: block.copy() for name, block in blocks.items()}
    targets = new_node[label.ravel()[moved]]
    for index, name in enumerate(names):
        mine = block_of == index
        out[name][row_of[mine], col_of[mine]] = targets[mine]
    return np.vstack([points, points[pairs[extra, 0]]]), out, int(extra.sum())


@njit(cache=True)
def _propagate(visit, parent, indptr, indices, data, flip):  # pragma: no cover - compiled
    """Flip state along the breadth-first tree: a child is flipped relative to its parent when
    they traverse their shared edge in the same direction (edge weight 2, else 1)."""
    for k in range(1, visit.size):
        cell = visit[k]
        p = parent[cell]
        for j in range(indptr[cell], indptr[cell + 1]):
            if indices[j] == p:
                flip[cell] = flip[p] ^ (data[j] == 2)
                break


def triangulate_polygon(points: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """Triangles ``(k − 2, 3)`` of a simple polygon (node indices in order), by ear clipping in
    the polygon's best-fit plane; the triangles keep the polygon's orientation."""
    corners = points[polygon]
    centred = corners - corners.mean(axis=0)
    normal = np.cross(centred, np.roll(centred, -1, axis=0)).sum(axis=0)  # Newell's
    normal = normal / (np.linalg.norm(normal) or 1.0)
    u = np.linalg.svd(centred - np.outer(centred @ normal, normal))[2][0]
    v = np.cross(normal, u)
    flat = np.column_stack([centred @ u, centred @ v])
    remaining = list(range(len(polygon)))
    out = []
    while len(remaining) > 3:
        for k in range(len(remaining)):
            i, j, m = remaining[k - 1], remaining[k], remaining[(k + 1) % len(remaining)]
            if _is_ear(flat, i, j, m, remaining):
                out.append((polygon[i], polygon[j], polygon[m]))
                remaining.pop(k)
                break
        else:  # no ear (a degenerate polygon): fan the rest
            break
    out += [
        (polygon[remaining[0]], polygon[remaining[k]], polygon[remaining[k + 1]])
        for k in range(1, len(remaining) - 1)
    ]
    return np.array(out, dtype=np.int64)


def _is_ear(flat: np.ndarray, i: int, j: int, m: int, remaining: list[int]) -> bool:
    a, b, c = flat[i], flat[j], flat[m]
    cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    if cross <= 0:
        return False
    for k in remaining:
        if k in (i, j, m):
            continue
        p = flat[k]
        d1 = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
        d2 = (c[0] - b[0]) * (p[1] - b[1]) - (c[1] - b[1]) * (p[0] - b[0])
        d3 = (a[0] - c[0]) * (p[1] - c[1]) - (a[1] - c[1]) * (p[0] - c[0])
        if d1 >= 0 and d2 >= 0 and d3 >= 0:
            return False
    return True
