"""Surface meshes: the fixed 3D shape whose cutting pattern is sought.

`SurfaceMesh` follows meshio's data model: ``points`` of shape ``(n, 3)`` and ``cells``, a
mapping from meshio cell type names (``"triangle"``, ``"quad"``) to integer index arrays.
A mesh is validated once, on construction, so that everything downstream may assume a
single connected, open, manifold, consistently oriented surface without degenerate cells.
Reading and writing mesh files is :mod:`vares.io`'s.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from .elements import ELEMENTS

__all__ = [
    "EdgeTable",
    "MeshError",
    "SurfaceMesh",
    "connected_pieces",
    "corner_fans",
    "index_listing",
]


class MeshError(ValueError):
    """The input is not a surface that can be patterned; the message names cells or nodes."""


def index_listing(indices: np.ndarray, limit: int = 8) -> str:
    """The first ``limit`` of ``indices`` (nodes or cells) for an error message, with the count
    when there are more: ``"3, 7, 9, … (12 in all)"``."""
    indices = np.asarray(indices).ravel()
    shown = ", ".join(str(int(i)) for i in indices[:limit])
    more = f", … ({indices.size} in all)" if indices.size > limit else ""
    return shown + more


class SurfaceMesh:
    """A validated, immutable surface mesh.

    Parameters
    ----------
    points
        Node coordinates, shape ``(n, 3)`` (``(n, 2)`` is taken as a flat surface, z = 0).
    cells
        Mapping of meshio cell type (``"triangle"`` ``(m, 3)``, ``"quad"`` ``(m, 4)``, meshio's
        node order) to node index arrays. Mixed meshes are allowed.
    drop_unused_nodes
        Nodes referenced by no cell are an error by default; with ``True`` they are removed
        (with a warning) and :attr:`node_map` maps the kept nodes to the given indices.

    Error messages name cells by type and index within their block, and nodes by their index
    in the given ``points``.
    """

    def __init__(
        self,
        points: np.ndarray,
        cells: Mapping[str, np.ndarray],
        *,
        drop_unused_nodes: bool = False,
    ) -> None:
        points = np.array(points, dtype=float)
        if points.ndim != 2 or points.shape[1] not in (2, 3):
            raise MeshError(f"points must have shape (n, 3); got {points.shape}")
        if points.shape[1] == 2:
            points = np.column_stack([points, np.zeros(len(points))])
        if len(points) == 0:
            raise MeshError("the mesh has no points")
        bad = np.flatnonzero(~np.isfinite(points).all(axis=1))
        if bad.size:
            raise MeshError(f"non-finite coordinates (NaN or inf) at nodes {index_listing(bad)}")

        clean: dict[str, np.ndarray] = {}
        for cell_type, block in cells.items():
            if cell_type not in ELEMENTS:
                raise MeshError(
                    f"cell type {cell_type!r} is not supported; a surface mesh needs "
                    f"{' or '.join(repr(t) for t in ELEMENTS)} cells"
                )
            arr = np.asarray(block)
            nen = ELEMENTS[cell_type].num_nodes
            if arr.size == 0:
                continue
            if arr.ndim != 2 or arr.shape[1] != nen:
                raise MeshError(f"{cell_type!r} cells must have shape (m, {nen}); got {arr.shape}")
            if not np.issubdtype(arr.dtype, np.integer):
                if not np.all(np.equal(np.mod(arr, 1), 0)):
                    raise MeshError(f"{cell_type!r} cell indices must be integers")
            arr = arr.astype(np.int64)
            if cell_type in clean:
                arr = np.vstack([clean[cell_type], arr])
            clean[cell_type] = arr
        if not clean:
            raise MeshError("the mesh has no triangle or quad cells")

        num_points = len(points)
        for cell_type, arr in clean.items():
            out = np.flatnonzero(((arr < 0) | (arr >= num_points)).any(axis=1))
            if out.size:
                raise MeshError(
                    f"{cell_type} cells {index_listing(out)} refer to nodes outside "
                    f"0..{num_points - 1}"
                )

        used = np.zeros(num_points, dtype=bool)
        for arr in clean.values():
            used[arr.ravel()] = True
        node_map = np.arange(num_points)
        if not used.all():
            unused = np.flatnonzero(~used)
            if not drop_unused_nodes:
                raise MeshError(
                    f"nodes {index_listing(unused)} belong to no cell "
                    "(pass drop_unused_nodes=True to remove them)"
                )
            warnings.warn(
                f"dropped {unused.size} node(s) that belong to no cell: {index_listing(unused)}",
                stacklevel=2,
            )
            node_map = np.flatnonzero(used)
            renumber = np.full(num_points, -1, dtype=np.int64)
            renumber[node_map] = np.arange(node_map.size)
            points = points[node_map]
            clean = {t: renumber[a] for t, a in clean.items()}

        self._points = points
        self._cells = clean
        self._node_map = node_map
        self._edges: EdgeTable | None = None
        self._areas: np.ndarray | None = None
        for arr in (self._points, self._node_map, *self._cells.values()):
            arr.setflags(write=False)
        self._validate()

    # ------------------------------------------------------------------ properties
    @property
    def points(self) -> np.ndarray:
        """Node coordinates ``(n, 3)`` (read-only)."""
        return self._points

    @property
    def cells(self) -> dict[str, np.ndarray]:
        """Cell blocks by meshio type name (read-only arrays)."""
        return dict(self._cells)

    @property
    def node_map(self) -> np.ndarray:
        """For each node, its index in the points given to the constructor."""
        return self._node_map

    @property
    def num_points(self) -> int:
        return len(self._points)

    @property
    def num_cells(self) -> int:
        return sum(len(a) for a in self._cells.values())

    def cell_areas(self) -> np.ndarray:
        """3D area of every cell in global cell order, shape ``(num_cells,)`` (read-only)."""
        if self._areas is None:
            areas = [ELEMENTS[t].areas(self._points, a) for t, a in self._cells.items()]
            self._areas = np.concatenate(areas)
            self._areas.setflags(write=False)
        return self._areas

    def area_vectors(self) -> np.ndarray:
        """Every cell's ``∫ ∂x/∂ξ₁ × ∂x/∂ξ₂``, ``(num_cells, 3)`` in global cell order: its area
        along its unit normal for a flat cell (a warped quad's is a little shorter); the normals
        follow the cells' orientation."""
        vectors = []
        for cell_type, cells in self._cells.items():
            element = ELEMENTS[cell_type]
            j = element.jacobians(self._points, cells)
            normal = np.cross(j[..., 0], j[..., 1])
            vectors.append(np.einsum("mqi,q->mi", normal, element.quadrature_weights))
        return np.vstack(vectors)

    @property
    def area(self) -> float:
        """Total 3D surface area."""
        return float(self.cell_areas().sum())

    def boundary_edges(self) -> np.ndarray:
        """Boundary edges ``(k, 2)``, each oriented as in its cell."""
        table = self._edge_table()
        return table.directed[table.counts[table.edge_id] == 1]

    def edges(self) -> np.ndarray:
        """Every edge once ``(k, 2)``, oriented as in the first cell that has it."""
        table = self._edge_table()
        ids = table.edge_id[table.order]
        first = np.ones(ids.size, dtype=bool)
        first[1:] = ids[1:] != ids[:-1]
        return table.directed[table.order[first]]

    def boundary_loops(self) -> list[np.ndarray]:
        """Closed node loops of the boundary, longest (most nodes) first, each in cell
        orientation (counter-clockwise for the outer loop of a positively oriented pattern)."""
        following = {int(a): int(b) for a, b in self.boundary_edges()}
        loops, seen = [], set()
        for start in sorted(following):
            if start in seen:
                continue
            loop = [start]
            seen.add(start)
            node = following[start]
            while node != start:
                if node in seen or node not in following:
                    raise MeshError(f"the boundary passes twice through node {node}")
                loop.append(node)
                seen.add(node)
                node = following[node]
            loops.append(np.array(loop))
        return sorted(loops, key=len, reverse=True)

    def transformed(self, points: np.ndarray) -> SurfaceMesh:
        """The same topology with new node coordinates ``(n, 3)``."""
        return SurfaceMesh(points, self._cells)

    def __repr__(self) -> str:
        blocks = ", ".join(f"{len(a)} {t}" for t, a in self._cells.items())
        return f"SurfaceMesh({self.num_points} points; {blocks})"

    # ------------------------------------------------------------------ validation
    def _global_cells(self) -> list[tuple[str, np.ndarray, int]]:
        out, offset = [], 0
        for t, a in self._cells.items():
            out.append((t, a, offset))
            offset += len(a)
        return out

    def _describe_cells(self, global_ids: np.ndarray) -> str:
        """Name cells by type and index within the type."""
        parts = []
        for t, a, offset in self._global_cells():
            mine = global_ids[(global_ids >= offset) & (global_ids < offset + len(a))] - offset
            if mine.size:
                parts.append(f"{t} cells {index_listing(np.unique(mine))}")
        return "; ".join(parts)

    def _edge_table(self) -> EdgeTable:
        """The edge table (computed once: the mesh does not change)."""
        if self._edges is None:
            self._edges = EdgeTable.of_cells(self._cells, self.num_points)
        return self._edges

    def _validate(self) -> None:
        points = self._points
        scale = float(np.ptp(points, axis=0).max()) or 1.0

        for t, a, _ in self._global_cells():
            repeated = np.flatnonzero((np.diff(np.sort(a, axis=1), axis=1) == 0).any(axis=1))
            if repeated.size:
                raise MeshError(f"degenerate {t} cells {index_listing(repeated)} repeat a node")
            # Smallest corner parallelogram area of each cell, relative to the model size.
            corner = ELEMENTS[t].corner_areas(points, a).min(axis=1)
            flat = np.flatnonzero(corner <= 1e-12 * scale**2)
            if flat.size:
                raise MeshError(
                    f"degenerate {t} cells {index_listing(flat)} have (nearly) zero area "
                    "or collinear corners"
                )

        table = self._edge_table()
        directed, owner, edge_id, counts = table.directed, table.owner, table.edge_id, table.counts

        over = np.flatnonzero(counts > 2)
        if over.size:
            at = np.isin(edge_id, over)
            edge = np.sort(directed[np.flatnonzero(at)[0]])
            raise MeshError(
                f"non-manifold edges: edge {tuple(int(v) for v in self._node_map[edge])} is "
                "shared by more "
                f"than two cells ({self._describe_cells(np.unique(owner[at]))})"
            )

        # Two cells sharing an edge must traverse it in opposite directions.
        first, second = table.pairs()
        same_direction = directed[first, 0] == directed[second, 0]
        if same_direction.any():
            bad = np.unique(
                np.concatenate([owner[first[same_direction]], owner[second[same_direction]]])
            )
            raise MeshError(
                "inconsistent orientation: neighbouring cells traverse a shared edge in the same "
                f"direction ({self._describe_cells(bad)}); orient all cells consistently"
            )

        if not (counts == 1).any():
            raise MeshError(
                "the surface is closed (it has no boundary edge): a closed surface has no "
                "cutting pattern in one piece; give it panels (a cell data array with a panel "
                "id per cell, or one object per panel in a .3dm) and pattern them with "
                "'vares panels'"
            )

        num_cells = self.num_cells
        # Cells are connected through shared edges; nodes join cells only through edges.
        adjacency = sp.coo_matrix(
            (np.ones(first.size), (owner[first], owner[second])), shape=(num_cells, num_cells)
        )
        num_pieces, label = connected_components(adjacency, directed=False)
        if num_pieces > 1:
            sizes = np.bincount(label)
            raise MeshError(
                f"the mesh has {num_pieces} separate pieces (cells per piece: "
                f"{index_listing(sizes)}); pattern them as the panels of a structure: "
                "'vares panels FILE' takes each piece as a panel"
            )

        self._check_manifold_vertices(table)

    def _check_manifold_vertices(self, table: EdgeTable) -> None:
        """Around each node the cells must form a single fan (no 'bow-tie' nodes)."""
        corner_node, fan = corner_fans(table)
        fan_node = np.empty(fan.max() + 1, dtype=np.int64)
        fan_node[fan] = corner_node  # the corners of a fan are at one node
        fans_per_node = np.bincount(fan_node, minlength=self.num_points)
        bow_tie = np.flatnonzero(fans_per_node > 1)
        if bow_tie.size:
            raise MeshError(
                f"non-manifold nodes {index_listing(self._node_map[bow_tie])}: the cells around "
                "each of them form separate fans that touch only at the node (reading the file "
                "with repair on splits such nodes)"
            )


def corner_fans(table: EdgeTable) -> tuple[np.ndarray, np.ndarray]:
    """The fan of every cell corner: corners (one per directed edge, at its start node) of the
    same node are in one fan when their cells are joined around the node by shared edges.
    Returns the node and the fan label of every corner (in the table's order of edges)."""
    directed, following = table.directed, table.following
    corner_node = directed[:, 0]

    def corner_of(edge: np.ndarray, node: np.ndarray) -> np.ndarray:
        """The corner of an edge's cell at one of the edge's ends: the edge's own if it
        starts there, else the next edge's of the cell."""
        return np.where(directed[edge, 0] == node, edge, following[edge])

    a, b = table.pairs()
    rows, cols = [], []
    for k in (0, 1):
        node = directed[a, k]
        rows.append(corner_of(a, node))
        cols.append(corner_of(b, node))
    graph = sp.coo_matrix(
        (np.ones(2 * a.size), (np.concatenate(rows), np.concatenate(cols))),
        shape=(corner_node.size, corner_node.size),
    )
    _, fan = connected_components(graph, directed=False)
    return corner_node, fan


@dataclass(frozen=True)
class EdgeTable:
    """Every directed cell edge, the cell it belongs to, the id of its undirected edge, the
    number of cells at each undirected edge, the stable order that sorts by edge id, and the
    next edge of the same cell (round the cell, as its nodes are listed)."""

    directed: np.ndarray
    owner: np.ndarray
    edge_id: np.ndarray
    counts: np.ndarray
    order: np.ndarray
    following: np.ndarray

    @classmethod
    def of_cells(cls, cells: Mapping[str, np.ndarray], num_points: int) -> EdgeTable:
        """The table of cell blocks by type (global cell order: block after block)."""
        return cls.of(directed_edges(cells), num_points, following_edges(cells))

    @classmethod
    def of(
        cls, edges: tuple[np.ndarray, np.ndarray], num_points: int, following: np.ndarray
    ) -> EdgeTable:
        directed, owner = edges
        key = np.minimum(directed[:, 0], directed[:, 1]) * num_points + np.maximum(
            directed[:, 0], directed[:, 1]
        )
        order = np.argsort(key, kind="stable")
        ordered = key[order]
        start = np.ones(ordered.size, dtype=bool)
        start[1:] = ordered[1:] != ordered[:-1]
        edge_id = np.empty(key.size, dtype=np.int64)
        edge_id[order] = np.cumsum(start) - 1
        return cls(directed, owner, edge_id, np.bincount(edge_id), order, following)

    def pairs(self) -> tuple[np.ndarray, np.ndarray]:
        """The two directed edges of every edge shared by (at least) two cells."""
        ids = self.edge_id[self.order]
        pair_start = np.flatnonzero(ids[1:] == ids[:-1])
        return self.order[pair_start], self.order[pair_start + 1]


def directed_edges(cells: Mapping[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Every directed edge ``(k, 2)`` of the cell blocks (edge ``i`` of every cell of a block,
    then edge ``i + 1``, block after block) and the global cell each belongs to."""
    edges, owner, offset = [], [], 0
    for block in cells.values():
        nen = block.shape[1]
        for i in range(nen):
            edges.append(np.column_stack([block[:, i], block[:, (i + 1) % nen]]))
            owner.append(offset + np.arange(len(block)))
        offset += len(block)
    if not edges:
        return np.zeros((0, 2), dtype=np.int64), np.zeros(0, dtype=np.int64)
    return np.vstack(edges), np.concatenate(owner)


def following_edges(cells: Mapping[str, np.ndarray]) -> np.ndarray:
    """For every directed edge of :func:`directed_edges` the index of the next edge of its cell
    (edge ``i + 1`` of the same cell, edge 0 after the last)."""
    out, offset = [], 0
    for block in cells.values():
        m, nen = block.shape
        local = np.arange(m * nen)
        out.append(offset + (local + m) % (m * nen))
        offset += m * nen
    return np.concatenate(out) if out else np.zeros(0, dtype=np.int64)


def connected_pieces(points: np.ndarray, cells: Mapping[str, np.ndarray]) -> np.ndarray:
    """The piece (0, 1, …) of every cell (global cell order): cells are in one piece when a
    chain of shared edges joins them; the largest piece is 0."""
    offset = sum(len(block) for block in cells.values())
    table = EdgeTable.of_cells(cells, len(points))
    first, second = table.pairs()
    adjacency = sp.coo_matrix(
        (np.ones(first.size), (table.owner[first], table.owner[second])), shape=(offset, offset)
    )
    _, label = connected_components(adjacency, directed=False)
    sizes = np.bincount(label)
    rank = np.empty_like(sizes)
    rank[np.argsort(-sizes, kind="stable")] = np.arange(sizes.size)
    return rank[label]
