"""Global assembly with a sparsity pattern and scatter map built once per mesh.

The unknowns are the pattern coordinates, two per node (dof ``2 a + i``). Some dofs are held
fixed (rigid modes); the matrix is assembled directly over the free dofs. Building the map sorts
all element-matrix entries once; every later assembly is a single weighted ``bincount``.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .mesh import SurfaceMesh

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
        if free.shape != (2 * mesh.num_points,):
            raise ValueError(f"free must have shape ({2 * mesh.num_points},); got {free.shape}")
        self.free = free
        self.num_dofs = 2 * mesh.num_points
        self.num_free = int(free.sum())
        reduced = np.full(self.num_dofs, -1, dtype=np.int64)
        reduced[free] = np.arange(self.num_free)

        self._dofs, self._keep, keys = [], [], []
        for cells in mesh.cells.values():
            dofs = (2 * cells[:, :, None] + np.arange(2)).reshape(len(cells), -1)  # (m, 2 nen)
            rows = reduced[dofs][:, :, None]
            cols = reduced[dofs][:, None, :]
            keep = ((rows >= 0) & (cols >= 0)).ravel()
            key = (rows * self.num_free + cols).ravel()[keep]
            self._dofs.append(dofs)
            self._keep.append(keep)
            keys.append(key)
        self._all_dofs = np.concatenate([d.ravel() for d in self._dofs])
        unique, self._position = np.unique(np.concatenate(keys), return_inverse=True)
        self._position = self._position.ravel()
        self._indices = (unique % self.num_free).astype(np.int32)
        row_of = unique // self.num_free
        self._indptr = np.zeros(self.num_free + 1, dtype=np.int64)
        np.cumsum(np.bincount(row_of, minlength=self.num_free), out=self._indptr[1:])
        self.nnz = unique.size

    def vector(self, gradients: list[np.ndarray]) -> np.ndarray:
        """Global gradient ``(n, 2)`` from per-cell gradients ``(m, nen, 2)`` of each block."""
        values = np.concatenate([g.ravel() for g in gradients])
        return np.bincount(self._all_dofs, weights=values, minlength=self.num_dofs).reshape(-1, 2)

    def matrix(self, hessians: list[np.ndarray]) -> sp.csr_matrix:
        """Global Hessian over the free dofs (CSR) from per-cell ``(m, nen, 2, nen, 2)`` blocks."""
        values = np.concatenate(
            [h.reshape(-1)[k] for h, k in zip(hessians, self._keep, strict=True)]
        )
        data = np.bincount(self._position, weights=values, minlength=self.nnz)
        return sp.csr_matrix(
            (data, self._indices, self._indptr), shape=(self.num_free, self.num_free)
        )
