"""Global assembly with a sparsity pattern and scatter map built once per mesh.

The unknowns are the pattern coordinates, two per node (dof ``2 a + i``). Some dofs are held
fixed (rigid modes); the matrix is assembled directly over the free dofs. Building the map sorts
all element-matrix entries once; every later assembly is a single weighted ``bincount``.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numba import njit

from ..geometry.mesh import SurfaceMesh

__all__ = ["Assembler"]


class Assembler:
    """Scatter element gradients and Hessians of ``mesh`` into global arrays.

    Parameters
    ----------
    mesh
        The mesh whose cell blocks are assembled (in ``mesh.cells`` order).
    free
        Boolean mask ``(2 n,)`` of the dofs that are unknowns; the matrix is over these only.
    """

    def __init__(self, mesh: SurfaceMesh, free: np.ndarray) -> None:
        free = np.asarray(free, dtype=bool)
        n = mesh.num_points
        if free.shape != (2 * n,):
            raise ValueError(f"free must have shape ({2 * n},); got {free.shape}")
        self.free = free
        self.num_dofs = 2 * n
        self.num_free = int(free.sum())

        # Node-level pattern first (a quarter of the entries), then each node pair (a, b)
        # becomes the 2 × 2 dof block of rows 2a+i, columns 2b+j.
        node_ptr, node_col = _node_pattern(mesh)
        degree = np.diff(node_ptr)
        node_row = np.repeat(np.arange(n), degree)
        within = np.arange(node_col.size) - node_ptr[node_row]  # rank of b in row a
        node_entry = np.concatenate(
            [_node_entries(cells, node_ptr, node_col) for cells in mesh.cells.values()]
        )

        i = np.arange(2)[:, None]
        j = np.arange(2)[None, :]

        def full_position(entry: np.ndarray) -> np.ndarray:
            """Position in the full dof CSR of the 2 × 2 block (i, j) of node entries."""
            a = node_row[entry][..., None, None]
            return 4 * node_ptr[a] + i * 2 * degree[a] + 2 * within[entry][..., None, None] + j

        # full dof structure, then keep the free rows and columns
        rows = (2 * node_row[:, None, None] + i + 0 * j).ravel()
        cols = (2 * node_col[:, None, None] + j + 0 * i).ravel()
        order = full_position(np.arange(node_col.size)).ravel()
        full_rows = np.empty_like(rows)
        full_cols = np.empty_like(cols)
        full_rows[order], full_cols[order] = rows, cols
        kept = free[full_rows] & free[full_cols]
        reduced = np.full(self.num_dofs, -1, dtype=np.int64)
        reduced[free] = np.arange(self.num_free)
        self._indices = reduced[full_cols[kept]].astype(np.int32)
        self._indptr = np.zeros(self.num_free + 1, dtype=np.int64)
        np.cumsum(
            np.bincount(reduced[full_rows[kept]], minlength=self.num_free), out=self._indptr[1:]
        )
        self.nnz = int(kept.sum())

        # entries in fixed rows or columns go to one extra slot that is dropped
        target = np.where(kept, np.cumsum(kept) - 1, self.nnz)
        total = sum(c.shape[0] * (2 * c.shape[1]) ** 2 for c in mesh.cells.values())
        self._position = np.empty(total, dtype=np.int64)
        self._dofs = []
        entry_start = position_start = 0
        for cells in mesh.cells.values():
            m, nen = cells.shape
            entries = node_entry[entry_start : entry_start + m * nen * nen]
            entry_start += m * nen * nen
            _element_positions(
                entries,
                nen,
                node_row,
                node_ptr,
                degree,
                within,
                target,
                self._position[position_start : position_start + m * 4 * nen * nen],
            )
            position_start += m * 4 * nen * nen
            self._dofs.append((2 * cells[:, :, None] + np.arange(2)).reshape(m, -1))
        self._all_dofs = np.concatenate([d.ravel() for d in self._dofs])

    def vector(self, gradients: list[np.ndarray]) -> np.ndarray:
        """Global gradient ``(n, 2)`` from per-cell gradients ``(m, nen, 2)`` of each block."""
        values = np.concatenate([g.ravel() for g in gradients])
        return np.bincount(self._all_dofs, weights=values, minlength=self.num_dofs).reshape(-1, 2)

    def matrix(self, hessians: list[np.ndarray]) -> sp.csr_matrix:
        """Global Hessian over the free dofs (CSR) from per-cell ``(m, nen, 2, nen, 2)`` blocks."""
        values = np.concatenate([h.reshape(-1) for h in hessians])
        data = np.bincount(self._position, weights=values, minlength=self.nnz + 1)[:-1]
        return sp.csr_matrix(
            (data, self._indices, self._indptr), shape=(self.num_free, self.num_free)
        )


def _node_pattern(mesh: SurfaceMesh) -> tuple[np.ndarray, np.ndarray]:
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
def _element_positions(
    entries, nen, node_row, node_ptr, degree, within, target, out
):  # pragma: no cover
    """Matrix slot of every element Hessian entry, in the layout ``(m, a, i, b, j)``.

    ``entries`` holds the node-pattern entry of each node pair ``(m, a, b)``; the dof block of
    node pair ``(a, b)`` starts in row ``2a + i`` at ``4 ptr[a] + 2 i deg[a] + 2 rank(b)``.
    """
    k = 0
    for e in range(entries.size // (nen * nen)):
        for a in range(nen):
            for i in range(2):
                for b in range(nen):
                    entry = entries[(e * nen + a) * nen + b]
                    row = node_row[entry]
                    base = 4 * node_ptr[row] + 2 * i * degree[row] + 2 * within[entry]
                    out[k] = target[base]
                    out[k + 1] = target[base + 1]
                    k += 2
