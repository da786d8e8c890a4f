"""The options of an erection analysis, declared once (see :mod:`vares.options`): the
``[erection]`` table of a job, the keywords of :func:`vares.erect` and the flags of
``vares erect`` (and of ``--erect`` on the patterning commands)."""

from __future__ import annotations

from dataclasses import dataclass

from ..options import Options, OptionsError, option

__all__ = ["ErectionOptions"]


@dataclass(frozen=True)
class ErectionOptions(Options):
    """How the structure is built from its patterns (see :func:`vares.erect`)."""

    title = "erection option"

    wrinkling: bool = option(
        True,
        "bool",
        "Tension-field energy: the membrane carries no compression (it wrinkles or goes slack).",
        section="erection",
        flags=("--wrinkling/--no-wrinkling",),
    )
    pressure: float = option(
        0.0,
        "float",
        "Uniform pressure along the surface normal (force/area), following the surface; needs "
        "every boundary node held (no edge cables).",
        section="erection",
    )
    cable_stiffness: float | None = option(
        None,
        "float",
        "Axial stiffness EA (force) of edge cables: given, every boundary stretch between two "
        "corners is a tension-only cable and only the corners are held.",
        section="erection",
        positive=True,
    )
    cable_force: float = option(
        0.0,
        "float",
        "Design force of the edge cables: each is cut to its design length / (1 + force/EA).",
        section="erection",
        minimum=0,
    )
    corner_angle: float = option(
        30.0,
        "float",
        "Boundary nodes where the boundary turns by more than this (degrees) are corners, held "
        "by the supports when there are edge cables.",
        section="erection",
        positive=True,
    )
    regularisation: float = option(
        1e-6,
        "float",
        "Tension of a fictitious soap film, relative to the material's stiffness, whose "
        "stiffness is added to Newton's tangent (never to the forces): it keeps the tangent "
        "definite where cells wrinkle or hang slack; the state found is an equilibrium of the "
        "law itself.",
        section="erection",
        minimum=0,
    )

    erection_iterations: int = option(
        200,
        "int",
        "Newton iterations of each attempt of the erection: where cells go in and out of "
        "wrinkling the tension-field energy has kinks, through which Newton's method converges "
        "slowly (a membrane with 40 % of its area wrinkled took 85–99 iterations).",
        section="erection",
        minimum=1,
    )

    optimise: bool = option(
        False,
        "bool",
        "Optimise the patterns for the erected structure: change them so that it carries the "
        "intended prestress and keeps the design's shape (seams kept matched), starting from "
        "the VaReS patterns.",
        section="erection",
        flags=("--optimise/--no-optimise",),
    )
    shape_weight: float = option(
        0.1,
        "float",
        "With --optimise: the weight of the erected shape's RMS deviation from the design "
        "against the RMS deviation of the forces from the intended, each relative to the VaReS "
        "patterns' erection.",
        section="erection",
        minimum=0,
    )
    shape_bound: float | None = option(
        1.5,
        "float",
        "With --optimise: the largest normal deviation from the design allowed (a node's "
        "displacement along the design's normal, as erect.json's deviation max), relative to "
        "the VaReS patterns' erection; it holds to 0.5 % of itself (nodes at it are held there, "
        "steps cut at it, a trial beyond it refused; none in the API: no bound).",
        section="erection",
        positive=True,
        optional=True,
    )
    optimise_iterations: int = option(
        8,
        "int",
        "With --optimise: at most this many steps of the optimiser (each one erection and one "
        "least-squares solve).",
        section="erection",
        minimum=1,
    )

    def check(self) -> None:
        if self.pressure and self.cable_stiffness is not None:
            raise OptionsError(
                None,
                "pressure with edge cables is not available: the pressure on a membrane whose "
                "boundary moves is not conservative (hold the boundary, or leave out the pressure)",
            )
        if self.corner_angle >= 180.0:
            raise OptionsError("corner_angle", f"must be < 180; got {self.corner_angle!r}")
