"""The options of a solve: fibre orientation and solver settings, each declared once.

:class:`SolveOptions` is the single place where a default or a bound of these settings is
written. :func:`vares.solve` takes its fields as keyword arguments, job files hold them in their
``[fibres]`` and ``[solver]`` tables, and the command line has one flag per field.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise

from ..mechanics.yarn_smoothing import YARN_STRAINS
from ..options import Options, OptionsError, option
from .linear import SOLVER_NAMES

__all__ = ["INITIAL_GUESSES", "ORIENTATIONS", "STRATEGIES", "SolveOptions"]

STRATEGIES = ("auto", "newton", "pseudo-time", "damping")
ORIENTATIONS = ("held", "free")
INITIAL_GUESSES = ("auto", "projection", "lscm", "tutte")


@dataclass(frozen=True)
class SolveOptions(Options):
    """How a pattern is oriented and found (see :func:`vares.solve`)."""

    title = "solver option"

    warp_angle: float = option(
        0.0,
        "float",
        "Warp angle in the pattern frame, degrees from the pattern x-axis.",
        section="fibres",
    )
    fill_angle: float | None = option(
        None,
        "float",
        "Fill angle in the pattern frame, degrees (default warp + 90).",
        section="fibres",
    )
    warp_direction: tuple[float, float, float] | None = option(
        None,
        "vector",
        "3D direction 'x,y,z' the warp follows on the erected surface (overrides the warp "
        "angle; the pattern is returned with the warp along +x).",
        section="fibres",
    )
    orientation: str = option(
        "held",
        "str",
        "Anisotropic laws or prestress: keep the initial guess's rotation (held) or let the "
        "energy choose it (free).",
        section="fibres",
        choices=ORIENTATIONS,
    )
    yarn_strain: str = option(
        "element",
        "str",
        "Yarn stretches of the fabric laws cell by cell (element), or averaged over each node's "
        "cells (smoothed) or over pairs of neighbouring nodes (paired): stiff yarns on triangles "
        "that follow no yarn without intra-ply shear locking (docs/locking.md).",
        section="fibres",
        choices=YARN_STRAINS,
    )
    yarn_stabilisation: float = option(
        0.0,
        "float",
        "With smoothed or paired yarn stretches: the share of the yarn energy kept cell by cell "
        "(stabilises the smoothed domains; docs/locking.md uses 10 × G/E).",
        section="fibres",
        minimum=0,
    )
    yarn_continuation: tuple[float, ...] | str = option(
        "auto",
        "floats",
        "Stiff fibre laws: yarn-to-shear ratios E/G 'r1,r2,…' (ascending, below the law's) "
        "solved first with the law's yarns softened to each, every stage from the last "
        "pattern, the law itself last; e.g. 1e2,1e3,1e4,1e5 for E/G = 1e6; auto: one stage "
        "at 1e4 for laws stiffer than that with smoothed or paired yarn stretches, none else; "
        "none: the law directly (docs/locking.md).",
        section="fibres",
        choices=("auto", "none"),
    )
    yarn_align_up_to: float | None = option(
        None,
        "float",
        "With yarn_continuation and a warp direction: the warp is aligned at the stages of "
        "ratio up to this one, its rotation held above (default: aligned at every stage); e.g. "
        "yarn_continuation 1e4 with 1e4 here for E/G = 1e6 (docs/locking.md).",
        section="fibres",
        positive=True,
    )
    strategy: str = option(
        "auto",
        "str",
        "Solution strategy.",
        section="solver",
        choices=STRATEGIES,
        flags=("--strategy", "-s"),
    )
    steps: int = option(
        3, "int", "Equal pseudo-time steps (strategy pseudo-time).", section="solver", minimum=1
    )
    initial_guess: str = option(
        "auto",
        "str",
        "Start: projection onto the plane, the conformal map (lscm), Tutte's embedding (tutte: "
        "never folds a disk), or auto (the projection unless no plane is named and it flattens "
        "a cell below 0.2 of its area, then the conformal map; Tutte's wherever these fold).",
        section="solver",
        choices=INITIAL_GUESSES,
    )
    plane: str | tuple[float, float, float] | None = option(
        None,
        "plane",
        "Initial-guess plane: best-fit, xy, yz, zx, or a normal 'nx,ny,nz' (default: best-fit; "
        "an example's own).",
        section="solver",
    )
    tolerance: float = option(
        1e-10,
        "float",
        "Relative residual tolerance: |residual| ≤ tolerance × stiffness × thickness × "
        "√area (and seam matching's).",
        section="solver",
        positive=True,
    )
    max_iterations: int = option(
        50,
        "int",
        "Newton iterations of each attempt of the strategy and each pseudo-time step (and of "
        "seam matching); a run reports the iterations of all its attempts and steps together.",
        section="solver",
        minimum=1,
    )
    damping: float = option(
        1.0,
        "float",
        "Initial damping of the damping strategy, relative to the mean tangent diagonal.",
        section="solver",
        positive=True,
    )
    linear_solver: str | None = option(
        None,
        "str",
        "Linear solver (default: the fastest installed).",
        section="solver",
        choices=SOLVER_NAMES,
    )

    def check(self) -> None:
        ratios = self.yarn_continuation
        ratios = () if isinstance(ratios, str) else ratios
        if any(r <= 0.0 for r in ratios) or any(b <= a for a, b in pairwise(ratios)):
            raise OptionsError(
                "yarn_continuation", f"must be ascending positive ratios; got {list(ratios)}"
            )
        if self.yarn_align_up_to is not None and self.yarn_continuation in ((), "none"):
            raise OptionsError(
                "yarn_align_up_to", "applies to the stages of a yarn_continuation; none is given"
            )
        if self.warp_direction is not None and self.orientation == "free":
            raise OptionsError(
                None, "a warp direction fixes the orientation; it cannot also be free"
            )
        if self.strategy == "pseudo-time" and self.initial_guess in ("lscm", "tutte"):
            raise OptionsError(
                None, "pseudo-time stepping starts from the projection, not from a flattening"
            )

    @property
    def named_plane(self) -> bool:
        """True when a plane other than the best-fit one is asked for."""
        return self.plane not in (None, "best-fit")
