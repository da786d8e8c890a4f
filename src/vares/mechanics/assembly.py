"""Global assembly with a sparsity pattern and scatter map built once per mesh.

The unknowns are ``d`` numbers per node (dof ``d a + i``): the pattern coordinates (``d = 2``) or
the erected positions of the forward problem (``d = 3``). Some dofs are held fixed (rigid modes,
supports); the matrix is assembled directly over the free dofs. The node pattern is built once
(a sparse sum of the cells' node pairs), with the matrix slot of every element entry; every
later assembly adds the element entries into their slots.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .._jit import compiled, njit
from ..geometry.mesh import SurfaceMesh

__all__ = ["Assembler", "Connectivity"]


class Connectivity:
    """Node count and cell blocks (any element, also line elements): what an :class:`Assembler`
    needs of a mesh. ``cells`` maps a block name to node indices ``(m, nen)``."""

    def __init__(self, num_points: int, cells: dict[str, np.ndarray]) -> None:
        self.num_points = int(num_points)
        self.cells = {name: np.asarray(c, dtype=np.int64) for name, c in cells.items() if len(c)}


class Assembler:
    """Scatter element gradients and Hessians of ``mesh`` into global arrays.

    Parameters
    ----------
    mesh
        The mesh (or :class:`Connectivity`) whose cell blocks are assembled, in ``mesh.cells``
        order.
    free
        Boolean mask ``(d n,)`` of the dofs that are unknowns; the matrix is over these only.
    dofs_per_node
        ``d``: 2 for a pattern, 3 for erected positions.
    """

    def __init__(
        self, mesh: SurfaceMesh | Connectivity, free: np.ndarray, dofs_per_node: int = 2
    ) -> None:
        free = np.asarray(free, dtype=bool)
        n, d = mesh.num_points, int(dofs_per_node)
        if free.shape != (d * n,):
            raise ValueError(f"free must have shape ({d * n},); got {free.shape}")
        self.free = free
        self.dofs_per_node = d
        self.num_dofs = d * n
        self.num_free = int(free.sum())

        # Node-level pattern first (1/d² of the entries), then each node pair (a, b) becomes
        # the d × d dof block of rows da+i, columns db+j.
        node_ptr, node_col = _node_pattern(mesh)
        degree = np.diff(node_ptr)
        node_row = np.repeat(np.arange(n), degree)
        within = np.arange(node_col.size) - node_ptr[node_row]  # rank of b in row a
        small = not compiled(sum(len(c) for c in mesh.cells.values()))
        entries_of = _sorted_entries if small else _node_entries
        node_entry = np.concatenate(
            [entries_of(cells, node_ptr, node_col) for cells in mesh.cells.values()]
        )

        reduced = np.full(self.num_dofs, -1, dtype=np.int64)
        reduced[free] = np.arange(self.num_free)
        # the free rows and columns of the full dof structure, and the slot of every full entry
        # (entries in fixed rows or columns go to one extra slot that is dropped)
        pattern = _dof_pattern_numpy if small else _dof_pattern
        self._indices, self._indptr, target = pattern(
            node_ptr, node_col, free, reduced, self.num_free, d
        )
        self.nnz = len(self._indices)
        total = sum(c.shape[0] * (d * c.shape[1]) ** 2 for c in mesh.cells.values())
        self._position = np.empty(total, dtype=np.int64)
        dofs = []
        entry_start = position_start = 0
        for cells in mesh.cells.values():
            m, nen = cells.shape
            entries = node_entry[entry_start : entry_start + m * nen * nen]
            entry_start += m * nen * nen
            positions = _positions if small else _element_positions
            positions(
                entries,
                nen,
                d,
                node_row,
                node_ptr,
                degree,
                within,
                target,
                self._position[position_start : position_start + m * d * d * nen * nen],
            )
            position_start += m * d * d * nen * nen
            dofs.append((d * cells[:, :, None] + np.arange(d)).reshape(m, -1))
        self._all_dofs = np.concatenate([block.ravel() for block in dofs])

    def vector(self, gradients: list[np.ndarray]) -> np.ndarray:
        """Global gradient ``(n, d)`` from per-cell gradients ``(m, nen, d)`` of each block."""
        values = np.concatenate([g.ravel() for g in gradients])
        d = self.dofs_per_node
        return np.bincount(self._all_dofs, weights=values, minlength=self.num_dofs).reshape(-1, d)

    def matrix(self, hessians: list[np.ndarray]) -> sp.csr_matrix:
        """Global Hessian over the free dofs (CSR) from per-cell ``(m, nen, d, nen, d)`` blocks."""
        if not compiled(sum(len(h) for h in hessians)):  # small: one weighted count
            values = np.concatenate([h.reshape(-1) for h in hessians])
            # bincount adds in order, as the loop below: the same sums
            data = np.bincount(self._position[: values.size], values, minlength=self.nnz + 1)
        else:
            data = np.zeros(self.nnz + 1)
            start = 0
            for h in hessians:  # scatter-add block by block, without a concatenated copy
                values = h.reshape(-1)
                _scatter_add(data, self._position[start : start + values.size], values)
                start += values.size
        return sp.csr_matrix(
            (data[:-1], self._indices, self._indptr),
            shape=(self.num_free, self.num_free),
        )


def _dof_pattern_numpy(
    node_ptr: np.ndarray,
    node_col: np.ndarray,
    free: np.ndarray,
    reduced: np.ndarray,
    num_free: int,
    d: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_dof_pattern` as array arithmetic (numpy, for small meshes)."""
    degree = np.diff(node_ptr)
    node_row = np.repeat(np.arange(len(node_ptr) - 1), degree)
    within = np.arange(node_col.size) - node_ptr[node_row]  # rank of b in row a
    i = np.arange(d)[:, None]
    j = np.arange(d)[None, :]
    # position in the full dof CSR of the d × d block (i, j) of each node entry
    a = node_row[:, None, None]
    order = (d * d * node_ptr[a] + i * d * degree[a] + d * within[:, None, None] + j).ravel()
    rows = (d * node_row[:, None, None] + i + 0 * j).ravel()
    cols = (d * node_col[:, None, None] + j + 0 * i).ravel()
    full_rows = np.empty_like(rows)
    full_cols = np.empty_like(cols)
    full_rows[order], full_cols[order] = rows, cols
    kept = free[full_rows] & free[full_cols]
    indices = reduced[full_cols[kept]].astype(np.int32)
    indptr = np.zeros(num_free + 1, dtype=np.int64)
    np.cumsum(np.bincount(reduced[full_rows[kept]], minlength=num_free), out=indptr[1:])
    nnz = int(kept.sum())
    return indices, indptr, np.where(kept, np.cumsum(kept) - 1, nnz)


@njit(cache=True)
def _dof_pattern(node_ptr, node_col, free, reduced, num_free, d):  # pragma: no cover
    """The CSR structure (column indices, row pointer) of the matrix over the ``free`` dofs
    (``reduced``: a dof's index among them, −1 if held; ``num_free`` of them) and the slot in it
    of every entry of the full dof structure (rows ``d a + i`` in order, in each the node
    pattern's columns ``b`` in order, each as ``d b + j``), ``nnz`` for an entry in a held row
    or column."""
    n = len(node_ptr) - 1
    total = d * d * node_ptr[n]
    target = np.empty(total, dtype=np.int64)
    indices = np.empty(total, dtype=np.int32)
    indptr = np.zeros(num_free + 1, dtype=np.int64)
    k = 0  # position in the full structure
    r = 0  # slot in the reduced one
    for a in range(n):
        for i in range(d):
            row = d * a + i
            row_free = free[row]
            for p in range(node_ptr[a], node_ptr[a + 1]):
                b = node_col[p]
                for j in range(d):
                    column = d * b + j
                    if row_free and free[column]:
                        target[k] = r
                        indices[r] = reduced[column]
                        r += 1
                    else:
                        target[k] = -1
                    k += 1
            if row_free:
                indptr[reduced[row] + 1] = r
    for k in range(total):
        if target[k] < 0:
            target[k] = r
    return indices[:r].copy(), indptr, target


def _node_pattern(mesh: SurfaceMesh | Connectivity) -> tuple[np.ndarray, np.ndarray]:
    """CSR pattern (row pointer, sorted column indices) of the node pairs that share a cell."""
    n = mesh.num_points
    rows = np.concatenate([np.repeat(c, c.shape[1], axis=1).ravel() for c in mesh.cells.values()])
    cols = np.concatenate([np.tile(c, (1, c.shape[1])).ravel() for c in mesh.cells.values()])
    pattern = sp.csr_matrix(
        (np.ones(rows.size, dtype=np.int8), (rows.astype(np.int32), cols.astype(np.int32))),
        shape=(n, n),
    )
    pattern.sum_duplicates()  # sorted, unique columns in every row
    return pattern.indptr.astype(np.int64), pattern.indices.astype(np.int64)


def _sorted_entries(cells: np.ndarray, node_ptr: np.ndarray, node_col: np.ndarray) -> np.ndarray:
    """:func:`_node_entries` by a sorted search (numpy, for small meshes): the pattern's
    entries in order are its pairs ``(row, column)`` in lexicographic order."""
    n = len(node_ptr) - 1
    keys = np.repeat(np.arange(n), np.diff(node_ptr)) * n + node_col
    pairs = cells[:, :, None] * n + cells[:, None, :]  # (m, a, b)
    return np.searchsorted(keys, pairs.reshape(-1)).astype(np.int64)


def _positions(
    entries: np.ndarray,
    nen: int,
    d: int,
    node_row: np.ndarray,
    node_ptr: np.ndarray,
    degree: np.ndarray,
    within: np.ndarray,
    target: np.ndarray,
    out: np.ndarray,
) -> None:
    """:func:`_element_positions` as array arithmetic (numpy, for small meshes)."""
    entry = entries.reshape(-1, nen, 1, nen, 1)  # (m, a, i, b, j)
    row = node_row[entry]
    i = np.arange(d).reshape(1, 1, d, 1, 1)
    j = np.arange(d).reshape(1, 1, 1, 1, d)
    base = d * d * node_ptr[row] + d * i * degree[row] + d * within[entry]
    out[:] = target[base + j].reshape(-1)


@njit(cache=True)
def _node_entries(cells, node_ptr, node_col):  # pragma: no cover - compiled
    """Index in the node pattern of every node pair ``(m, a, b)`` of the cells, flattened."""
    m, nen = cells.shape
    out = np.empty(m * nen * nen, dtype=np.int64)
    k = 0
    for e in range(m):
        for a in range(nen):
            row = cells[e, a]
            for b in range(nen):
                column = cells[e, b]
                position = node_ptr[row]
                while node_col[position] != column:
                    position += 1
                out[k] = position
                k += 1
    return out


@njit(cache=True)
def _scatter_add(data, position, values):  # pragma: no cover - compiled
    """``data[position[k]] += values[k]`` in order (the same sums as a weighted bincount)."""
    for k in range(values.size):
        data[position[k]] += values[k]


@njit(cache=True)
def _element_positions(
    entries, nen, d, node_row, node_ptr, degree, within, target, out
):  # pragma: no cover
    """Matrix slot of every element Hessian entry, in the layout ``(m, a, i, b, j)``.

    ``entries`` holds the node-pattern entry of each node pair ``(m, a, b)``; the dof block of
    node pair ``(a, b)`` starts in row ``da + i`` at ``d² ptr[a] + d i deg[a] + d rank(b)``.
    """
    k = 0
    for e in range(entries.size // (nen * nen)):
        for a in range(nen):
            for i in range(d):
                for b in range(nen):
                    entry = entries[(e * nen + a) * nen + b]
                    row = node_row[entry]
                    base = d * d * node_ptr[row] + d * i * degree[row] + d * within[entry]
                    for j in range(d):
                        out[k + j] = target[base + j]
                    k += d
