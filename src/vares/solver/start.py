"""The initial guess: where Newton's method starts, and which plane the pseudo-time path uses.

The paper's start is the orthogonal projection onto a plane; it is also the exact solution at
the beginning of the pseudo-time path. Where the surface is steep to the plane, the projection
distorts or folds cells; the least-squares conformal map (LSCM) is then the better start.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.flatten import ProjectionPlane, lscm, projection_distortion, projection_plane
from ..geometry.mesh import SurfaceMesh
from ..options import OptionsError
from .options import SolveOptions

__all__ = ["PROJECTION_MIN_AREA_RATIO", "Start", "initial_guess"]

#: Below this smallest projected/3D area ratio (about 78° of slope) the projection is no start.
PROJECTION_MIN_AREA_RATIO = 0.2


@dataclass(frozen=True)
class Start:
    """An initial pattern ``(n, 2)``, what it is (``"projection"``, ``"lscm"`` or ``"given"``)
    and, for a projection, its plane (the pseudo-time path needs it)."""

    coordinates: np.ndarray
    kind: str
    plane: ProjectionPlane | None


def initial_guess(
    mesh: SurfaceMesh, options: SolveOptions, given: np.ndarray | None = None
) -> Start:
    """The start that ``options.initial_guess`` asks for, or the ``given`` coordinates.

    ``"auto"`` takes the projection onto ``options.plane``, unless no plane is named and the
    best-fit projection folds a cell or flattens one below :data:`PROJECTION_MIN_AREA_RATIO` of
    its area; then the conformal map (not with pseudo-time stepping, whose path needs a plane).
    """
    if given is not None:
        if options.strategy == "pseudo-time":
            raise OptionsError(
                None,
                "pseudo-time stepping starts from the projection; drop the initial guess or "
                "choose another strategy",
            )
        start = np.array(given, dtype=float)
        if start.shape != (mesh.num_points, 2) or not np.all(np.isfinite(start)):
            raise OptionsError(
                "initial_guess",
                f"must be finite coordinates of shape ({mesh.num_points}, 2); got {start.shape}",
            )
        return Start(start, "given", None)
    plane = projection_plane(mesh, options.plane)
    kind = options.initial_guess
    if kind == "auto":
        steep = projection_distortion(mesh, plane) < PROJECTION_MIN_AREA_RATIO
        use_lscm = not options.named_plane and options.strategy != "pseudo-time" and steep
        kind = "lscm" if use_lscm else "projection"
    if kind == "projection":
        return Start(plane.project(mesh.points), "projection", plane)
    return Start(lscm(mesh), "lscm", None)
