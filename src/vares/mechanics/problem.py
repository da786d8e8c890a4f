"""The discrete VaReS problem: mesh, material, thickness, fibres and prestress.

``Problem`` evaluates the energy of DESIGN.md eq. (1) and its exact derivatives for any pattern;
it knows nothing about how the pattern is found (see :mod:`vares.solver`). It is the *objective*
that :func:`vares.solver.newton.newton` minimises.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, replace

import numpy as np

from ..geometry.elements import ELEMENTS
from ..geometry.flatten import inverted_cells
from ..geometry.mesh import SurfaceMesh
from ..materials import Fibres, Hyperelastic, MaterialError
from .assembly import Connectivity
from .kernels import block_energy, determinant, projected_hessian
from .prestress import prestress_components, prestress_tensor
from .yarn_smoothing import YARN_STRAINS, YarnSmoothing, paired_domains

__all__ = ["Evaluation", "Problem", "first_positive_root"]


@dataclass(frozen=True)
class Evaluation:
    """Energy and per-block derivatives of a pattern (blocks in ``mesh.cells`` order)."""

    energy: float
    cell_energy: list[np.ndarray]
    gradients: list[np.ndarray] | None
    hessians: list[np.ndarray] | None
    jacobian_hessians: list[np.ndarray] | None = None


class Problem:
    """Energy of erecting a pattern onto a fixed surface.

    Parameters
    ----------
    mesh
        The 3D surface.
    material
        Hyperelastic law (energy density per unit reference volume).
    thickness
        Membrane thickness; the energy per pattern area is ``thickness × Ψ``. For laws given as
        force per length (``E·t``), use 1.
    fibres
        Warp/fill directions in the pattern plane; required for anisotropic laws.
    prestress
        Intended prestress along the yarns, force per length: a number (isotropic), (warp, fill
        [, shear]) or one such row per cell (see :func:`vares.prestress.prestress_components`).
    points
        Surface node positions to use instead of ``mesh.points`` (pseudo-time stepping).
    yarn_strain
        ``"element"``: the law per quadrature point; ``"smoothed"``: the yarn stretches of a
        fibre law averaged over node patches, the shear per cell (no intra-ply shear locking; see
        :mod:`vares.mechanics.yarn_smoothing`); ``"paired"``: averaged over the domains of pairs
        of nodes (:func:`~vares.mechanics.yarn_smoothing.paired_domains`). The per-block arrays
        then end with the patch block, assembled over :attr:`connectivity`.
    yarn_stabilisation
        With smoothed yarn strains: the share of the yarn part kept per cell (see
        :class:`~vares.mechanics.yarn_smoothing.YarnSmoothing`).
    """

    def __init__(
        self,
        mesh: SurfaceMesh,
        material: Hyperelastic,
        thickness: float = 1.0,
        *,
        fibres: Fibres | None = None,
        prestress: np.ndarray | None = None,
        points: np.ndarray | None = None,
        yarn_strain: str = "element",
        yarn_stabilisation: float = 0.0,
    ) -> None:
        if yarn_strain not in YARN_STRAINS:
            raise ValueError(f"yarn_strain must be one of {YARN_STRAINS}; got {yarn_strain!r}")
        if not (np.isfinite(thickness) and thickness > 0):
            raise ValueError(f"thickness must be a finite positive number; got {thickness!r}")
        if material.needs_fibres and fibres is None:
            raise MaterialError(f"{type(material).__name__} needs fibre directions")
        if material.requires_orthogonal_fibres and abs(fibres.warp @ fibres.fill) > 1e-9:
            raise MaterialError(
                f"{type(material).__name__} is written for yarns at 90° in the pattern; "
                f"got warp and fill {np.degrees(np.arccos(fibres.warp @ fibres.fill)):.6g}° apart"
            )
        self.mesh = mesh
        self.material = material
        self.thickness = float(thickness)
        self.fibres = fibres
        self.points = mesh.points if points is None else np.asarray(points, dtype=float)
        # the metric is translation invariant: recentred, far-off site coordinates lose nothing
        centred = self.points - self.points.mean(axis=0)
        self.prestress = prestress_components(prestress, mesh.num_cells)
        if self.prestress is not None and fibres is None:
            raise ValueError("a prestress along the yarns needs fibre directions")
        self._prestress_blocks = self._split_prestress(self.prestress)
        self._metrics = [ELEMENTS[t].metrics(centred, cells) for t, cells in mesh.cells.items()]
        self.yarn_strain = yarn_strain
        self.yarn_stabilisation = float(yarn_stabilisation)
        self._smoothing = (
            YarnSmoothing(
                mesh,
                material,
                fibres,
                self.thickness,
                yarn_stabilisation,
                domains=paired_domains(mesh) if yarn_strain == "paired" else None,
            )
            if yarn_strain != "element"
            else None
        )

    def _split_prestress(self, components: np.ndarray | None) -> list[np.ndarray | None]:
        """``S_pre`` per block, broadcastable to ``(m, q, 2, 2)``."""
        blocks = list(self.mesh.cells.values())
        if components is None:
            return [None] * len(blocks)
        tensor = prestress_tensor(components, self.fibres, self.thickness)
        if len(tensor) == 1:
            return [tensor[0]] * len(blocks)
        bounds = np.cumsum([0] + [len(cells) for cells in blocks])
        return [tensor[a:b, None] for a, b in itertools.pairwise(bounds)]

    @property
    def orientation_matters(self) -> bool:
        """True when the energy depends on the yarn directions (anisotropic law or prestress)."""
        return self.material.needs_fibres or self.prestress is not None

    def with_surface(self, points: np.ndarray, prestress_factor: float = 1.0) -> Problem:
        """The same problem on other surface positions, with the prestress scaled."""
        prestress = None if self.prestress is None else prestress_factor * self.prestress
        return Problem(
            self.mesh,
            self.material,
            self.thickness,
            fibres=self.fibres,
            prestress=prestress,
            points=points,
            yarn_strain=self.yarn_strain,
            yarn_stabilisation=self.yarn_stabilisation,
        )

    @property
    def connectivity(self) -> SurfaceMesh | Connectivity:
        """What the per-block arrays of :meth:`evaluate` are assembled over: the mesh, or with
        smoothed yarn strains the mesh's blocks and the node patches."""
        return self.mesh if self._smoothing is None else self._smoothing.connectivity

    # ------------------------------------------------------------------ evaluation
    def evaluate(
        self, coordinates: np.ndarray, order: int = 2, *, projected: bool = False
    ) -> Evaluation:
        """Energy (and per-block gradients for ``order ≥ 1``, Hessians for ``order = 2``).

        ``coordinates`` is the pattern ``(n, 2)``; it must not invert any cell. With
        ``projected`` the Hessians are made positive semi-definite quadrature point by
        quadrature point (see :meth:`projected_hessians`).
        """
        if self._smoothing is not None:
            energies, gradients, hessians, stored = self._smoothing.evaluate(
                coordinates, self._metrics, self._prestress_blocks, order
            )
            total = float(sum(np.sum(e).real for e in energies))
            evaluation = Evaluation(total, energies, gradients, hessians, stored)
            if projected and order >= 2:
                evaluation = replace(evaluation, hessians=self.projected_hessians(evaluation))
            return evaluation
        energies, gradients, hessians, jacobian_hessians = [], [], [], []
        for (cell_type, cells), metric, prestress in zip(
            self.mesh.cells.items(), self._metrics, self._prestress_blocks, strict=True
        ):
            block = block_energy(
                ELEMENTS[cell_type],
                coordinates[cells],
                metric,
                self.material,
                self.thickness,
                fibres=self.fibres,
                prestress=prestress,
                order=order,
            )
            energies.append(block.energy)
            gradients.append(block.gradient)
            hessians.append(block.hessian)
            jacobian_hessians.append(block.jacobian_hessian)
        total = float(sum(np.sum(e).real for e in energies))
        evaluation = Evaluation(
            total,
            energies,
            gradients if order >= 1 else None,
            hessians if order >= 2 else None,
            jacobian_hessians if order >= 2 else None,
        )
        if projected and order >= 2:
            evaluation = replace(evaluation, hessians=self.projected_hessians(evaluation))
        return evaluation

    def projected_hessians(self, evaluation: Evaluation) -> list[np.ndarray]:
        """The per-block Hessians of an (order 2) evaluation made positive semi-definite point by
        point (projected Newton), from its stored ``∂²W/∂J²``: nothing is evaluated again.
        With smoothed yarn strains the last block, the node patches', is projected through
        ``∂²Ψ/∂Ĩ²`` (see :meth:`~vares.mechanics.yarn_smoothing.YarnSmoothing.projected`)."""
        if self._smoothing is not None:
            return self._smoothing.projected(evaluation.jacobian_hessians)
        return [
            projected_hessian(ELEMENTS[t], h, self.thickness)
            for t, h in zip(self.mesh.cells, evaluation.jacobian_hessians, strict=True)
        ]

    def energy(self, coordinates: np.ndarray) -> float:
        """Energy of a pattern; ``inf`` when it inverts a cell."""
        if self.inverted_cells(coordinates).size:
            return float("inf")
        return self.evaluate(coordinates, order=0).energy

    def inverted_cells(self, coordinates: np.ndarray) -> np.ndarray:
        """Global ids of the cells with ``det J ≤ 0`` somewhere (inverted or collapsed)."""
        return inverted_cells(self.mesh, coordinates)

    def admissible_step(self, coordinates: np.ndarray, delta: np.ndarray) -> float:
        """Largest ``α`` such that ``coordinates + α delta`` keeps every ``det J`` positive
        (``inf`` if any ``α`` does); ``delta`` ``(n, 2)``.

        ``det(J + α D) = det J + α (J₀₀D₁₁ + D₀₀J₁₁ − J₀₁D₁₀ − D₀₁J₁₀) + α² det D`` at each
        check point: the bound is the smallest positive root over all of them.
        """
        bound = np.inf
        for cell_type, cells in self.mesh.cells.items():
            element = ELEMENTS[cell_type]
            J = element.jacobians(coordinates, cells, at="check")
            D = element.jacobians(delta, cells, at="check")
            bound = min(bound, first_positive_root(J, D))
        return bound

    @property
    def force_scale(self) -> float:
        """Reference force for relative residuals: stiffness × thickness × √(surface area)."""
        return self.material.stiffness_scale * self.thickness * np.sqrt(self.mesh.area)


def first_positive_root(J: np.ndarray, D: np.ndarray) -> float:
    """Smallest positive root of ``det(J + α D)`` over all points (``inf`` if none)."""
    a = determinant(D)
    b = J[..., 0, 0] * D[..., 1, 1] + D[..., 0, 0] * J[..., 1, 1]
    b = b - J[..., 0, 1] * D[..., 1, 0] - D[..., 0, 1] * J[..., 1, 0]
    c = determinant(J)
    with np.errstate(divide="ignore", invalid="ignore"):
        root = np.sqrt(np.maximum(b * b - 4 * a * c, 0.0))
        # the two roots, written to avoid cancellation; keep the positive ones
        q = -0.5 * (b + np.copysign(root, b))
        candidates = np.stack([q / a, c / q])
    real = (b * b - 4 * a * c >= 0) | (np.abs(a) < 1e-300)
    linear = np.where(np.abs(a) < 1e-300, -c / np.where(b == 0, np.inf, b), np.inf)
    candidates = np.where(real, candidates, np.inf)
    candidates = np.concatenate([candidates, linear[None]])
    candidates = np.where((candidates > 0) & np.isfinite(candidates), candidates, np.inf)
    return float(candidates.min(initial=np.inf))
