"""The options of a fabric's scatter carried into the pattern, declared once (see
:mod:`vares.options`): the ``[scatter]`` table of a job, the flags of ``vares fabric band`` and
the ``--scatter-…`` flags of ``vares pattern``, ``panels`` and ``cut``
(:mod:`vares.analysis.scatter`, :func:`vares.app.fabric_band.fabric_band`)."""

from __future__ import annotations

from dataclasses import dataclass

from ..options import Options, option

__all__ = ["SAMPLED", "ScatterOptions"]

#: What a band samples.
SAMPLED = ("compensation", "constants")


@dataclass(frozen=True)
class ScatterOptions(Options):
    """How the scatter of a fabric's compensation values is sampled and reported."""

    title = "scatter option"

    sampled: str = option(
        "compensation",
        "str",
        "What is sampled: the measured compensation values (the pattern compensated by them) "
        "or the fitted constants E1, E2, nu12 (the pattern compensated by the fitted law).",
        section="scatter",
        choices=SAMPLED,
    )
    samples: int = option(
        16,
        "int",
        "Random samples of what is sampled, each solved (and erected) on its own.",
        section="scatter",
        minimum=1,
    )
    sigmas: float = option(
        2.0,
        "float",
        "Half-width of the band reported, in standard deviations of the samples' figures.",
        section="scatter",
        minimum=0,
    )
    seed: int = option(
        0,
        "int",
        "Seed of the random samples: the same seed draws the same samples.",
        section="scatter",
        minimum=0,
    )
