"""Node-smoothed yarn stretches: a fabric law on linear cells against intra-ply shear locking.

Linear triangles whose edges do not follow the yarns cannot keep two yarn families
inextensible cell by cell: each cell brings two constraints (``I4 = I6 = 1``) for one node's two
unknowns, about four constraints per node on a triangle mesh against two unknowns, and with stiff
yarns the shear field scatters from cell to cell (DESIGN.md §8). Here the yarn part of the law is
evaluated with stretches averaged over the smoothing domain of each node (a third of every
triangle around it, a quarter of every quad), so the yarns bring two constraints per node, as
many as there are unknowns; the shear part is kept per cell. This is the average-nodal treatment
of a constrained part of the energy (Bonet & Burton 1998, average nodal pressure tetrahedra; the
node-based smoothed finite element method of Liu et al. 2009) applied to the yarn stretches.

With ``w_e = ∫_e dA`` (pattern area), the nodal sums over the cells ``e ∋ k``

    a_k = Σ_e w_e / n_e,   b_k = Σ_e ∫_e I4 dA / n_e,   c_k = Σ_e ∫_e I6 dA / n_e

(``n_e`` nodes per cell) give the smoothed stretches ``Ĩ4 = b/a``, ``Ĩ6 = c/a`` and the energy

    Π = t Σ_k (1 − β) a_k Ψ(Ĩ4_k, Ĩ6_k, 0)
        + t Σ_e ∫_e [Ψ(I4, I6, I8) − (1 − β) Ψ(I4, I6, 0) − S_pre:E] dA

with ``β`` the share of the yarn part kept per cell (a stabilisation; 0: all of it smoothed).

A uniform stretch gives the same ``Ĩ`` as every cell's ``I``: the energy, and so the pattern of a
flat or developable surface, are those of the cell-wise law (patch test). Per quadrature point
``d = det J``, ``d I4 = yᵀ G y / d`` with ``y = adj(J) Φ₁`` linear in ``J``; their first and
second derivatives with respect to ``J`` are closed forms (below), so the gradient and Hessian
are exact. The Hessian has two parts: cell blocks (the shear part, and the yarn stresses times
the second derivatives of ``a, b, c``) and one block per node patch,
``t a_k ∇Ĩ_kᵀ (∂²Ψ/∂Ĩ²) ∇Ĩ_k``, which couples the nodes of the cells around node ``k``. The
assembly of the patch blocks needs :attr:`YarnSmoothing.connectivity`.

Laws written in ``(I4, I6, I8)`` (the orthotropic St. Venant–Kirchhoff law and the non-crimp
fabric law) are supported. Measured on a hemisphere (docs/locking.md): with one domain per node
the four symmetric 45° meridians agree at E/G = 1e4, where the cell-wise law locks, and lock at
E/G = 1e6; with domains of pairs of nodes (:func:`paired_domains`) they agree to 0.54° at 1e4 and
1e6 on 9,600 cells, and the stiff solve converges through softer yarns
(:func:`vares.analysis.locking.solve_yarn_strain` with ``continuation``).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..geometry.elements import ELEMENTS
from ..geometry.mesh import SurfaceMesh
from ..materials import Fibres, Hyperelastic
from .assembly import Connectivity
from .kernels import block_energy, nodal_hessian, projected_hessian
from .yarn_laws import ShearPart

__all__ = ["PATCH_BLOCK", "YARN_STRAINS", "ShearPart", "YarnSmoothing", "paired_domains"]

#: The settings of ``Problem(yarn_strain=...)``: per cell, smoothed over each node's domain, or
#: over the domains of pairs of nodes (:func:`paired_domains`).
YARN_STRAINS = ("element", "smoothed", "paired")
#: Name of the block of node patches in :attr:`YarnSmoothing.connectivity`.
PATCH_BLOCK = "yarn_patch"

# d = det J = ½ Jᵀ B J with J flattened as (J00, J01, J10, J11)
_DET_FORM = np.array([[0, 0, 0, 1], [0, 0, -1, 0], [0, -1, 0, 0], [1, 0, 0, 0]], dtype=float)


class YarnSmoothing:
    """The energy of a fibre law with node-smoothed yarn stretches, and its exact derivatives.

    Parameters
    ----------
    mesh
        The surface mesh (any cell types).
    material
        A law of ``(I4, I6, I8)``.
    fibres
        Warp and fill in the pattern plane (orthogonal).
    thickness
        Energy per pattern area = thickness × Ψ.
    stabilisation
        The share ``β ∈ [0, 1)`` of the yarn part kept per cell: ``(1 − β)`` of it is evaluated
        with the smoothed stretches, ``β`` with each cell's own (0: fully smoothed). A share of
        the order of ``G12/E`` stiffens the yarn-stretch modes the smoothing leaves to the shear
        alone without bringing back the cell-wise constraints.
    domains
        The smoothing domain of every node ``(n,)``, numbered from 0 (default: one per node);
        a domain of several nodes is the union of theirs.
    """

    def __init__(
        self,
        mesh: SurfaceMesh,
        material: Hyperelastic,
        fibres: Fibres,
        thickness: float,
        stabilisation: float = 0.0,
        domains: np.ndarray | None = None,
    ) -> None:
        if not 0.0 <= stabilisation < 1.0:
            raise ValueError(f"stabilisation must lie in [0, 1); got {stabilisation!r}")
        self.stabilisation = float(stabilisation)
        self.shear = ShearPart(material, self.stabilisation)
        self.material = material
        self.fibres = fibres
        self.thickness = float(thickness)
        self.mesh = mesh
        n = mesh.num_points
        blocks = list(mesh.cells.items())
        self._offsets = np.cumsum([0] + [len(c) for _, c in blocks])
        cells_all = [c for _, c in blocks]
        # node–cell incidence: row k, column global cell, value 1/n_e
        rows = np.concatenate([c.ravel() for c in cells_all])
        cols = np.concatenate(
            [
                np.repeat(np.arange(len(c)) + o, c.shape[1])
                for c, o in zip(cells_all, self._offsets, strict=False)
            ]
        )
        vals = np.concatenate([np.full(c.size, 1.0 / c.shape[1]) for c in cells_all])
        node_share = sp.csr_matrix((vals, (rows, cols)), shape=(n, int(self._offsets[-1])))
        domain_of = np.arange(n) if domains is None else np.asarray(domains, dtype=np.int64)
        if domain_of.shape != (n,) or set(np.unique(domain_of)) != set(range(domain_of.max() + 1)):
            raise ValueError("domains must number every node's domain from 0 without gaps")
        count = int(domain_of.max()) + 1
        merge = sp.csr_matrix((np.ones(n), (domain_of, np.arange(n))), shape=(count, n))
        #: ``(domains, cells)``: the share of each cell's integrals in each smoothing domain
        self._share = (merge @ node_share).tocsr()
        self._share.sum_duplicates()
        self._share.sort_indices()
        # the nodes of each node's patch: the nodes of its cells, padded with the first
        cell_nodes = sp.csr_matrix(
            (np.ones(rows.size), (cols, rows)), shape=(int(self._offsets[-1]), n)
        )
        adjacency = (self._share @ cell_nodes).tocsr()
        adjacency.sum_duplicates()
        adjacency.sort_indices()
        size = int(np.diff(adjacency.indptr).max())
        patches = np.empty((count, size), dtype=np.int64)
        slot_of: dict[tuple[int, int], int] = {}
        for k in range(count):
            members = adjacency.indices[adjacency.indptr[k] : adjacency.indptr[k + 1]]
            patches[k, : members.size] = members
            patches[k, members.size :] = members[0]
            slot_of.update({(k, int(b)): s for s, b in enumerate(members)})
        self.patches = patches
        # every (node k, cell e ∋ k): the patch slot of each of e's nodes, per block
        coo = self._share.tocoo()
        self._incidence = []
        for index, c in enumerate(cells_all):
            lo, hi = self._offsets[index], self._offsets[index + 1]
            chosen = (coo.col >= lo) & (coo.col < hi)
            domain, cell, weight = coo.row[chosen], coo.col[chosen] - lo, coo.data[chosen]
            slots = np.array(
                [
                    slot_of[(int(k), int(b))]
                    for k, e in zip(domain, cell, strict=True)
                    for b in c[e]
                ],
                dtype=np.int64,
            ).reshape(domain.size, c.shape[1])
            self._incidence.append((domain, cell, weight, slots))

    @property
    def connectivity(self) -> Connectivity:
        """The mesh's cell blocks and the block of node patches, in the order of the per-block
        arrays :meth:`evaluate` returns (what an :class:`~vares.mechanics.assembly.Assembler`
        is built from)."""
        return Connectivity(self.mesh.num_points, {**self.mesh.cells, PATCH_BLOCK: self.patches})

    # ------------------------------------------------------------------ pieces
    def _quadrature_terms(self, coordinates, metrics, order):
        """Per block: the cell integrals of ``(d, d I4, d I6)`` ``(m, 3)``, their gradients with
        respect to the cell's pattern nodes ``(m, 3, nen, 2)`` and their Hessians with respect
        to ``J`` at each quadrature point ``(m, q, 3, 4, 4)`` (``J`` flattened as ``2 i + α``)."""
        out = []
        phis = (self.fibres.warp, self.fibres.fill)
        for (cell_type, cells), metric in zip(self.mesh.cells.items(), metrics, strict=True):
            element = ELEMENTS[cell_type]
            grads = element.shape_gradients  # (q, nen, 2)
            J = np.einsum("mai,qac->mqic", coordinates[cells], grads)  # J_iα
            Jv = J.reshape(*J.shape[:2], 4)
            d = J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0]
            w = element.quadrature_weights
            grad_d = Jv @ _DET_FORM  # ∇d = B J
            values, jac, hes = [d], [grad_d], [np.broadcast_to(_DET_FORM, (*d.shape, 4, 4))]
            for phi in phis:
                # d I = yᵀ G y / d with y = adj(J) Φ = A J
                A = np.array([[0.0, -phi[1], 0.0, phi[0]], [phi[1], 0.0, -phi[0], 0.0]])
                M = np.einsum("ka,mqkl,lb->mqab", A, metric, A)
                MJ = np.einsum("mqab,mqb->mqa", M, Jv)
                p = np.einsum("mqa,mqa->mq", Jv, MJ) / d
                grad_p = (2.0 * MJ - p[..., None] * grad_d) / d[..., None]
                values.append(p)
                jac.append(grad_p)
                if order >= 2:
                    h = 2.0 * M - p[..., None, None] * _DET_FORM
                    h = h - grad_p[..., :, None] * grad_d[..., None, :]
                    h = h - grad_d[..., :, None] * grad_p[..., None, :]
                    hes.append(h / d[..., None, None])
            integral = np.stack([v @ w for v in values], axis=1)
            gradient = hessian = None
            if order >= 1:
                # ∂J_{iα}/∂X_{a j} = δ_ij ∂N_a/∂ξ_α
                g = np.stack(jac, axis=2).reshape(*d.shape, 3, 2, 2)  # (m, q, c, i, α)
                gradient = np.einsum("mqcia,qna,q->mcni", g, grads, w)
            if order >= 2:
                hessian = np.stack(hes, axis=2)
            out.append((integral, gradient, hessian))
        return out

    def _nodal(self, integrals):
        """Nodal sums ``(a, b, c)`` ``(n, 3)``, smoothed stretches ``(n, 2)``, nodal energies
        ``(n,)``, ``∂E_k/∂(a, b, c)`` ``(n, 3)`` and ``∂²Ψ/∂Ĩ²`` ``(n, 2, 2)``, all with the
        factor ``1 − stabilisation``."""
        per_cell = np.concatenate(integrals, axis=0)
        u = self._share @ per_cell
        a = u[:, 0]
        smoothed = u[:, 1:] / a[:, None]
        inv = np.concatenate([smoothed, np.zeros_like(a)[:, None]], axis=1)
        psi = self.material.psi_invariants(inv)
        dpsi = self.material.dpsi_invariants(inv)[:, :2]
        factor = self.thickness * (1.0 - self.stabilisation)
        energy = factor * a * psi
        multipliers = factor * np.concatenate(
            [(psi - (dpsi * smoothed).sum(axis=1))[:, None], dpsi], axis=1
        )
        d2psi = (1.0 - self.stabilisation) * self.material.d2psi_invariants(inv)[:, :2, :2]
        return u, smoothed, energy, multipliers, d2psi

    # ------------------------------------------------------------------ evaluation
    def evaluate(
        self,
        coordinates: np.ndarray,
        metrics: list[np.ndarray],
        prestress_blocks: list[np.ndarray | None],
        order: int = 2,
    ) -> tuple[list, list | None, list | None, list | None]:
        """Per-block energies, gradients and Hessians (the mesh's blocks, then the patch block).

        Returns ``(cell_energy, gradients, hessians, stored)``: per mesh block ``(m,)``,
        ``(m, nen, 2)``, ``(m, nen, 2, nen, 2)``; the patch block ``(n,)`` (zero: the nodal
        energies are shared out to the cells), ``(n, s, 2)`` (zero), ``(n, s, 2, s, 2)``;
        ``stored`` (order 2) what :meth:`projected` needs: per mesh block the Hessian of every
        quadrature point's terms with respect to ``J`` ``(m, q, 4, 4)`` (without thickness and
        weight), and the patch block made positive semi-definite (``None`` in complex
        arithmetic).
        """
        terms = self._quadrature_terms(coordinates, metrics, order)
        u, smoothed, nodal_energy, lam, d2psi = self._nodal([t[0] for t in terms])
        n = self.patches.shape[0]
        # each cell's share of node k's energy, in proportion to its share of a_k
        share_of_a = self._share.multiply(
            np.concatenate([t[0][:, 0] for t in terms])[None, :]
        ).tocsr()
        cell_yarn = share_of_a.T @ (nodal_energy / u[:, 0])
        cell_lam = self._share.T @ lam  # (cells, 3): Σ_{k∈e} λ_k / n_e
        energies, gradients, hessians, stored = [], [], [], []
        for index, ((cell_type, cells), metric, prestress, term) in enumerate(
            zip(self.mesh.cells.items(), metrics, prestress_blocks, terms, strict=True)
        ):
            element = ELEMENTS[cell_type]
            lo, hi = self._offsets[index], self._offsets[index + 1]
            block = block_energy(
                element,
                coordinates[cells],
                metric,
                self.shear,
                self.thickness,
                fibres=self.fibres,
                prestress=prestress,
                order=order,
            )
            energies.append(block.energy + cell_yarn[lo:hi])
            if order >= 1:
                gradients.append(
                    block.gradient + np.einsum("mc,mcaj->maj", cell_lam[lo:hi], term[1])
                )
            if order >= 2:
                total = block.jacobian_hessian + np.einsum(
                    "mc,mqckl->mqkl", cell_lam[lo:hi] / self.thickness, term[2]
                )
                total = np.ascontiguousarray(total)
                dtype = total.dtype
                hessians.append(
                    nodal_hessian(
                        total,
                        np.ascontiguousarray(element.shape_gradients, dtype=dtype),
                        (self.thickness * element.quadrature_weights).astype(dtype),
                    )
                )
                stored.append(total)
        size = self.patches.shape[1]
        energies.append(np.zeros(n, dtype=nodal_energy.dtype))
        if order >= 1:
            gradients.append(np.zeros((n, size, 2), dtype=gradients[0].dtype))
        if order >= 2:
            exact, patch_psd = self._patch_hessian(terms, u, smoothed, d2psi)
            hessians.append(exact)
            stored.append(patch_psd)
        return (
            energies,
            gradients if order >= 1 else None,
            hessians if order >= 2 else None,
            stored if order >= 2 else None,
        )

    def _smoothed_gradients(self, terms, u, smoothed):
        """``∇Ĩ4_k, ∇Ĩ6_k`` over each node's patch, ``(n, 2, s, 2)``."""
        n, size = self.patches.shape
        dtype = np.result_type(u, *[t[1] for t in terms])
        out = np.zeros((n, 2, size, 2), dtype=dtype)
        for (node, cell, weight, slots), term in zip(self._incidence, terms, strict=True):
            g = term[1]  # (m, 3, nen, 2)
            scale = (weight / u[node, 0])[:, None, None]
            for j in range(2):
                contribution = scale * (
                    g[cell, 1 + j] - smoothed[node, j][:, None, None] * g[cell, 0]
                )
                np.add.at(out, (node[:, None], j, slots), contribution)
        return out

    def _patch_hessian(self, terms, u, smoothed, d2psi):
        """``t a_k ∇Ĩ_kᵀ (∂²Ψ/∂Ĩ²) ∇Ĩ_k`` per patch, ``(n, s, 2, s, 2)``, and the same with
        ``∂²Ψ/∂Ĩ²`` made positive semi-definite (the same array when it is)."""
        grad = self._smoothed_gradients(terms, u, smoothed)
        n, _, size, _ = grad.shape
        flat = grad.reshape(n, 2, 2 * size)
        scale = (self.thickness * u[:, 0])[:, None, None]

        def product(curvature: np.ndarray) -> np.ndarray:
            return (flat.transpose(0, 2, 1) @ ((scale * curvature) @ flat)).reshape(
                n, size, 2, size, 2
            )

        exact = product(d2psi)
        if np.iscomplexobj(d2psi):
            return exact, None
        values, vectors = np.linalg.eigh(d2psi)
        if values.min(initial=0.0) >= 0.0:
            return exact, exact
        fixed = np.einsum("nij,nj,nkj->nik", vectors, np.maximum(values, 0.0), vectors)
        return exact, product(fixed)

    def projected(self, stored: list[np.ndarray]) -> list[np.ndarray]:
        """Positive semi-definite Hessians from :meth:`evaluate`'s ``stored``: every quadrature
        point's ``∂²W/∂J²`` with its negative eigenvalues set to zero (as for the cell-wise law),
        and the patch block with ``∂²Ψ/∂Ĩ²`` so projected (real arithmetic)."""
        out = [
            projected_hessian(ELEMENTS[t], h, self.thickness)
            for t, h in zip(self.mesh.cells, stored[:-1], strict=True)
        ]
        out.append(stored[-1])
        return out


def paired_domains(mesh: SurfaceMesh) -> np.ndarray:
    """Smoothing domains of two nodes joined by an edge ``(n,)``: a greedy matching over the
    edges, shortest first (a node left without a free neighbour keeps a domain of its own).

    Two stretch constraints per pair of nodes leave the yarns about half the unknowns, where one
    domain per node leaves them none (docs/locking.md).
    """
    edges = mesh.edges()
    lengths = np.linalg.norm(mesh.points[edges[:, 0]] - mesh.points[edges[:, 1]], axis=1)
    domain = np.full(mesh.num_points, -1, dtype=np.int64)
    count = 0
    for a, b in edges[np.argsort(lengths, kind="stable")]:
        if domain[a] < 0 and domain[b] < 0:
            domain[a] = domain[b] = count
            count += 1
    single = np.flatnonzero(domain < 0)
    domain[single] = count + np.arange(single.size)
    return domain
