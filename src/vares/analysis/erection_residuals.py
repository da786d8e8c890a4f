"""The least-squares residuals of patterns judged by their erected structure, and their
Jacobian's products (what :mod:`vares.analysis.erection_optimum` minimises).

At an erected state ``x*(X)`` (``R(x*, X) = 0``), the residual vector holds, weighted so that its
squared norm is ``J`` (module docs of :mod:`vares.analysis.erection_optimum`): per cell and yarn
the membrane force's deviation from the intended and per yarn the mean's, per cell the compression
of the plain law where its smaller principal force falls below a margin, per node the normal
deviation from the design and its excess over the bound. ``J v`` and ``Jᵀ u`` take one solve
each with the erection's tangent ``K``: ``dx* = −K⁻¹ (∂R/∂X) dX`` and the adjoint
``Jᵀu = ∂r/∂Xᵀ u − (∂R/∂X)ᵀ K⁻¹ ∂r/∂xᵀ u`` (:mod:`vares.analysis.erection_sensitivity`). Seams
are constraints beside it: every seam edge equally long in the two patterns it joins.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..materials import Hyperelastic
from ..mechanics.assembly import Assembler
from ..mechanics.problem import Problem
from ..solver.linear import LinearSolver, get_solver, solver_family
from .erection import ErectionResult
from .erection_fields import node_normals
from .erection_model import Pattern
from .erection_sensitivity import block_derivatives, block_forces, block_least_forces
from .pattern_seams import PatternLayout, seam_constraints

__all__ = [
    "ResidualModel",
    "edge_strain",
    "erected_rms",
    "pattern_edges",
    "stiffness_preconditioner",
]

#: The weight of each yarn's mean force deviation against the per-cell deviations (the mean
#: is held to the intended: a uniformly higher tension would lower the shape deviation).
MEAN_WEIGHT = 30.0
#: The weight of a node's shape deviation beyond the bound, against the RMS terms.
BOUND_WEIGHT = 100.0
#: The weight of a cell's compression (the plain law's smaller principal force, where it falls
#: below WRINKLE_MARGIN of the cell's smaller intended force: negative where the erected
#: membrane wrinkles or hangs slack) against its yarns' force deviations: an optimum should not
#: buy its forces with wrinkles (docs/erection.md). Measured on the PES/PVC and isotropic hypars
#: (docs/erection.md): 1 leaves 0.5 % of the isotropic 1.5k optimum wrinkled, 3 none; 10 none
#: either, but the 50k case's steps then gain little (10 steps, unconverged), where 3 takes 7.
WRINKLE_WEIGHT = 3.0
WRINKLE_MARGIN = 0.1
#: The shift of the patterns' stiffness in LSQR's preconditioner, relative to its mean diagonal
#: (measured on the 10k hypar: 0.1 to 1 alike; 10 preconditioned iterations reach what 30
#: plain ones do).
PRECONDITIONER_SHIFT = 0.3


class ResidualModel:
    """The residual vector of ``J`` at one erected state and products with its Jacobian.

    The residual is cheap (the cells' forces and the nodes' deviations); the linearisation (the
    derivatives' sparse matrices and the factorised erection tangent ``K``) is made on the first
    product with the Jacobian and then serves every product at this state (a trial whose
    objective is not lower is never linearised)."""

    def __init__(
        self,
        patterns: list[Pattern],
        erected: ErectionResult,
        layout: PatternLayout,
        seams: np.ndarray,
        scales: tuple[float, float],
        shape_weight: float,
        shape_bound: float | None,
        linear_solver: str | Callable[[], LinearSolver] | None,
    ) -> None:
        self.erected, self.layout, self.seams = erected, layout, seams
        #: what makes the solver the tangent is factorised by: a family's maker (an optimiser's
        #: states share one, :func:`solver_family`), or a family of its own for a solver's name
        #: (None: the fastest installed)
        self.solvers = (
            linear_solver
            if callable(linear_solver)
            else solver_family(linear_solver, many_solves=True)
        )
        problem, x, mesh = erected.problem, erected.erected_points, erected.mesh
        area = mesh.cell_areas()
        total = area.sum()
        force_scale, shape_scale = scales
        n_cells, n_nodes = mesh.num_cells, mesh.num_points
        forces = np.zeros((n_cells, 2))
        for k in range(len(problem.blocks)):
            forces[layout.cell_ids[k]] = block_forces(problem, k, x)
        # per cell and yarn the force deviation, and per yarn its mean (held near zero)
        force_weight = np.repeat(np.sqrt(area / total), 2) / force_scale
        mean_rows = sp.csr_matrix(
            (
                np.tile(area / total, 2) * np.sqrt(MEAN_WEIGHT) / force_scale,
                (
                    np.repeat([0, 1], n_cells),
                    np.concatenate([2 * np.arange(n_cells) + k for k in (0, 1)]),
                ),
            ),
            shape=(2, 2 * n_cells),
        )
        self._force_rows = sp.vstack([sp.diags(force_weight), mean_rows]).tocsr()
        # per cell the compression across wrinkles (or too little tension), penalised
        least = np.zeros(n_cells)
        for k in range(len(problem.blocks)):
            least[layout.cell_ids[k]] = block_least_forces(problem, k, x)
        margin = WRINKLE_MARGIN * np.maximum(erected.intended[:, :2].min(axis=1), 0.0)
        short = least < margin
        self._wrinkle_weight = np.where(short, np.sqrt(WRINKLE_WEIGHT * area / total), 0.0)
        self._wrinkle_weight /= force_scale
        force_residual = np.concatenate(
            [
                self._force_rows @ (forces - erected.intended).ravel(),
                self._wrinkle_weight * (least - margin),
            ]
        )
        # shape: the normal deviation at every node (its derivative the normal itself), and
        # where it exceeds the bound, the excess
        normals, node_area = node_normals(mesh)
        d = erected.normal_deviation
        rms_weight = np.sqrt(shape_weight * node_area / total) / shape_scale
        over = np.zeros(n_nodes)
        if shape_bound is not None:
            active = np.abs(d) > shape_bound
            over[active] = np.sqrt(BOUND_WEIGHT * node_area[active] / total) / shape_scale
        excess = over * (np.abs(d) - (shape_bound or 0.0))
        self._shape_rows = (np.concatenate([rms_weight, over * np.sign(d)]), normals)
        shape_residual = np.concatenate([rms_weight * d, excess])
        # seams: the two lengths of every seam edge, equal
        self.seam_residual, self.seam_by_X = self._seams(patterns)
        self.residual = np.concatenate([force_residual, shape_residual])
        self.parts = (
            float(force_residual @ force_residual),
            float(shape_residual @ shape_residual),
        )
        self.forces = forces
        self.num_force, self.num_shape = len(force_residual), len(shape_residual)
        self.solves = 0
        self._linear = None

    def _seams(self, patterns: list[Pattern]):
        """The seam constraints ``c = ℓ_P − ℓ_Q`` (one per seam edge) and their Jacobian."""
        X = np.concatenate([p.material_coordinates for p in patterns])
        return seam_constraints(X, self.seams, self.layout.num_variables)

    def linearise(self) -> None:
        """The derivatives at this state as sparse matrices (``mixed`` ``∂R/∂X`` on the free
        dofs, ``by_x`` and ``by_X`` the residuals' by the free positions and by the patterns)
        and the erection tangent ``K`` factorised (``tangent``, ``solver``)."""
        if self._linear is not None:
            return
        erected, layout = self.erected, self.layout
        problem, ctx = erected.problem, erected.context
        x, mesh = erected.erected_points, erected.mesh
        n_cells, n_nodes = mesh.num_cells, mesh.num_points
        mixed_rows, mixed_cols, mixed_vals = [], [], []
        fx_rows, fx_cols, fx_vals = [], [], []
        fX_rows, fX_cols, fX_vals = [], [], []
        lx_rows, lx_cols, lx_vals, lX_rows, lX_cols, lX_vals = [], [], [], [], [], []
        for k, block in enumerate(problem.blocks):
            d = block_derivatives(problem, k, x, with_least=True)
            ids = layout.cell_ids[k]
            nen = block.cells.shape[1]
            xdof = 3 * block.cells[:, :, None] + np.arange(3)  # (m, nen, 3)
            Xdof = 2 * layout.block_cells[k][:, :, None] + np.arange(2)  # (m, nen, 2)
            mixed_rows.append(np.broadcast_to(xdof[:, :, :, None, None], d.mixed.shape).ravel())
            mixed_cols.append(np.broadcast_to(Xdof[:, None, None], d.mixed.shape).ravel())
            mixed_vals.append(d.mixed.ravel())
            frow = 2 * ids[:, None] + np.arange(2)  # (m, 2)
            shape_x = (len(ids), 2, nen, 3)
            fx_rows.append(np.broadcast_to(frow[:, :, None, None], shape_x).ravel())
            fx_cols.append(np.broadcast_to(xdof[:, None], shape_x).ravel())
            fx_vals.append(d.force_by_x.ravel())
            shape_X = (len(ids), 2, nen, 2)
            fX_rows.append(np.broadcast_to(frow[:, :, None, None], shape_X).ravel())
            fX_cols.append(np.broadcast_to(Xdof[:, None], shape_X).ravel())
            fX_vals.append(d.force_by_X.ravel())
            lx_rows.append(np.broadcast_to(ids[:, None, None], d.least_by_x.shape).ravel())
            lx_cols.append(xdof.ravel())
            lx_vals.append(d.least_by_x.ravel())
            lX_rows.append(np.broadcast_to(ids[:, None, None], d.least_by_X.shape).ravel())
            lX_cols.append(Xdof.ravel())
            lX_vals.append(d.least_by_X.ravel())
        nv = layout.num_variables
        cat = np.concatenate
        free = ctx.assembler.free
        kept = np.flatnonzero(free)
        mixed = sp.csr_matrix(
            (cat(mixed_vals), (cat(mixed_rows), cat(mixed_cols))), shape=(3 * n_nodes, nv)
        )
        self.mixed = mixed[free]
        raw_x = sp.csr_matrix(
            (cat(fx_vals), (cat(fx_rows), cat(fx_cols))), shape=(2 * n_cells, 3 * n_nodes)
        ).tocsc()[:, kept]
        raw_X = sp.csr_matrix((cat(fX_vals), (cat(fX_rows), cat(fX_cols))), shape=(2 * n_cells, nv))
        wrinkle = sp.diags(self._wrinkle_weight)
        least_x = sp.csr_matrix(
            (cat(lx_vals), (cat(lx_rows), cat(lx_cols))), shape=(n_cells, 3 * n_nodes)
        ).tocsc()[:, kept]
        least_X = sp.csr_matrix((cat(lX_vals), (cat(lX_rows), cat(lX_cols))), shape=(n_cells, nv))
        weights, normals = self._shape_rows
        shape_by_x = shape_by_x_of(weights, normals, n_nodes)[:, kept]
        self._normals_by_x = shape_by_x_of(np.ones(n_nodes), normals, n_nodes)[:, kept]
        self.by_X = sp.vstack([self._force_rows @ raw_X, wrinkle @ least_X]).tocsr()
        self.by_x = sp.vstack([self._force_rows @ raw_x, wrinkle @ least_x, shape_by_x]).tocsr()
        self._force_by_x = self.by_x[: self.num_force]
        self._shape_by_x = self.by_x[self.num_force :]
        self._by_x_t = self.by_x.T.tocsr()
        self._by_X_t = self.by_X.T.tocsr()
        self._mixed_t = self.mixed.T.tocsr()
        # the exact tangent where every cell is taut; the film keeps it definite where cells
        # wrinkle (their positions then have no determinate derivative across the wrinkles)
        taut = not erected.fields["state"].any()
        evaluation = problem.evaluate(x, order=2, stabilised=not taut)
        self.tangent = ctx.assembler.matrix(evaluation.hessians)
        self.solver = self.solvers()
        self.solver.factorize(self.tangent)
        self._linear = True

    @property
    def linearised(self) -> bool:
        """Whether the derivatives and the factorised tangent of this state are made."""
        return self._linear is not None

    def _tangent_solve(self, rhs: np.ndarray) -> np.ndarray:
        self.solves += 1
        return self.solver.solve(rhs)

    def tangent_solve(self, rhs: np.ndarray) -> np.ndarray:
        """``K⁻¹ rhs`` (free dofs) with the factorised tangent of this state (linearised
        first): what preconditions the Newton steps of a nearby trial's erection."""
        self.linearise()
        return self.solver.solve(rhs)

    def response(self, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``J v`` and the erected positions' change ``dx* = −K⁻¹ (∂R/∂X) v`` (free dofs) for a
        change ``v`` of the patterns: one solve with ``K``."""
        self.linearise()
        dx = -self._tangent_solve(self.mixed @ v)
        forces = self.by_X @ v + self._force_by_x @ dx
        shape = self._shape_by_x @ dx
        return np.concatenate([forces, shape]), dx

    def deviation_change(self, dx: np.ndarray) -> np.ndarray:
        """The nodes' normal deviations moved by ``dx`` (free dofs), to first order."""
        self.linearise()
        return self.erected.normal_deviation + self._normals_by_x @ dx

    def deviation_gradients(self, nodes: np.ndarray) -> np.ndarray:
        """``∂d_i/∂X`` ``(k, num_variables)`` of the ``nodes``' normal deviations through the
        erected equilibrium, ``−(∂R/∂X)ᵀ K⁻¹ n_i``: one solve with ``K`` each."""
        self.linearise()
        rows = self._normals_by_x[nodes].toarray()
        return np.array([-(self._mixed_t @ self._tangent_solve(r)) for r in rows])

    def matvec(self, v: np.ndarray) -> np.ndarray:
        """``J v``: the residuals' change for a change ``v`` of the patterns."""
        return self.response(v)[0]

    def rmatvec(self, u: np.ndarray) -> np.ndarray:
        """``Jᵀ u`` by the adjoint of the erected equilibrium."""
        self.linearise()
        nf, ns = self.num_force, self.num_shape
        adjoint = self._tangent_solve(self._by_x_t @ u[: nf + ns])
        return self._by_X_t @ u[:nf] - self._mixed_t @ adjoint

    def equilibrium_sensitivity(self) -> float:
        """``|g|``, ``g = K⁻¹ (∂r/∂x)ᵀ r``: an erection stopped at a residual ``R`` (free dofs)
        instead of at equilibrium is off by ``K⁻¹ R``, and its objective by ``2 gᵀR`` to first
        order, at most ``2 |g| |R|`` (one solve with ``K``, kept)."""
        if getattr(self, "_sensitivity", None) is None:
            self.linearise()
            self._sensitivity = float(
                np.linalg.norm(self._tangent_solve(self._by_x_t @ self.residual))
            )
        return self._sensitivity

    def operator(self) -> spla.LinearOperator:
        """``J P``: the Jacobian on the steps that keep the seams matched to first order."""
        shape = (len(self.residual), self.layout.num_variables)
        if not len(self.seams):
            return spla.LinearOperator(shape, matvec=self.matvec, rmatvec=self.rmatvec, dtype=float)
        project = self.projection()
        return spla.LinearOperator(
            shape,
            matvec=lambda v: self.matvec(project(v)),
            rmatvec=lambda u: project(self.rmatvec(u)),
            dtype=float,
        )

    def projection(self):
        """``P = I − Cᵀ (C Cᵀ)⁻¹ C`` onto the null space of the seam constraints' Jacobian."""
        if getattr(self, "_projection", None) is None:
            C = self.seam_by_X.tocsr()
            gram = spla.splu((C @ C.T).tocsc())
            self._gram = gram
            self._projection = lambda v: v - C.T @ gram.solve(C @ v)
        return self._projection


def shape_by_x_of(weights: np.ndarray, normals: np.ndarray, n_nodes: int) -> sp.csc_matrix:
    """The rows ``weights_i n_i`` ``(len(weights), 3 n_nodes)``: the derivatives of weighted
    normal deviations by the positions (the weights of ``len(weights) / n_nodes`` row sets)."""
    sets = len(weights) // n_nodes
    rows = np.repeat(np.arange(len(weights)), 3)
    return sp.csr_matrix(
        (
            (weights[:, None] * np.vstack([normals] * sets)).ravel(),
            (rows, np.tile(np.arange(3 * n_nodes), sets)),
        ),
        shape=(len(weights), 3 * n_nodes),
    ).tocsc()


def stiffness_preconditioner(
    patterns: list[Pattern],
    material: Hyperelastic,
    thickness: float,
    linear_solver: str | None = None,
) -> spla.LinearOperator:
    """``(H + σ I)⁻¹`` ``(N, N)`` over all patterns' coordinates: ``H`` the patterning energy's
    Hessian (without prestress, made positive semi-definite) of each pattern on its design
    shape, one block per panel, ``σ`` :data:`PRECONDITIONER_SHIFT` of its mean diagonal.

    A right preconditioner of LSQR for ``J``: a change of the patterns weighted by the inverse
    of their stiffness is one the erected forces follow evenly, and LSQR needs about a third of
    the iterations for the same step (docs/erection.md). The patterns move by a few per cent
    while they are optimised: the factors of the starting patterns serve every step. Factorised
    by ``linear_solver`` (None: the fastest installed), with factors of its own, for the many
    solves they serve."""
    blocks = []
    for pattern in patterns:
        problem = Problem(pattern.mesh, material, thickness, fibres=pattern.fibres)
        evaluation = problem.evaluate(pattern.material_coordinates, order=2, projected=True)
        free = np.ones(2 * pattern.mesh.num_points, dtype=bool)
        assembler = Assembler(problem.connectivity, free, dofs_per_node=2)
        blocks.append(assembler.matrix(evaluation.hessians))
    H = sp.block_diag(blocks, format="csr")
    shifted = (H + PRECONDITIONER_SHIFT * H.diagonal().mean() * sp.eye(H.shape[0])).tocsr()
    # factors of its own: the erection tangent's are made and solved with between its solves
    solver = get_solver(linear_solver, own_factors=True, many_solves=True)
    solver.factorize(shifted)
    return spla.LinearOperator(H.shape, matvec=solver.solve, rmatvec=solver.solve, dtype=float)


def pattern_edges(patterns: list[Pattern], layout: PatternLayout) -> np.ndarray:
    """Every edge of every pattern cell ``(k, 2)`` (variable node ids)."""
    out = []
    for p, pattern in enumerate(patterns):
        for cells in pattern.mesh.cells.values():
            rolled = np.roll(cells, -1, axis=1)
            out.append(layout.offsets[p] + np.column_stack([cells.ravel(), rolled.ravel()]))
    return np.unique(np.sort(np.vstack(out), axis=1), axis=0)


def edge_strain(
    patterns: list[Pattern], step: np.ndarray, edges: np.ndarray, layout: PatternLayout
) -> float:
    """The largest change of a pattern edge's length by ``step``, relative to its length."""
    X = np.concatenate([p.material_coordinates for p in patterns])
    d = step.reshape(-1, 2)
    vectors = X[edges[:, 1]] - X[edges[:, 0]]
    lengths = np.linalg.norm(vectors, axis=1)
    change = np.einsum("ki,ki->k", vectors, d[edges[:, 1]] - d[edges[:, 0]]) / lengths
    return float(np.max(np.abs(change) / lengths))


def erected_rms(result: ErectionResult) -> float:
    stats = result.statistics()["stress"]
    return float(np.hypot(stats["warp"]["rms_deviation"], stats["fill"]["rms_deviation"]))
