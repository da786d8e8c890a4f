"""Forming limits of dry reinforcement fabrics: the shear locking angle per fabric kind.

A woven or stitched fabric shears at its yarn crossings with little resistance until the yarns
of one family press against each other; beyond that **locking angle** it wrinkles instead of
shearing further. The drape's producibility check (:mod:`vares.analysis.producibility`) compares
the shear angle with it.

The values below are typical values for each kind, chosen for vares from the ranges that
picture-frame and bias-extension tests in the forming literature report for such fabrics
(Prodromou & Chen 1997, Composites A 28:491, on plain, twill and satin weaves; Cao et al. 2008,
Composites A 39:1037, the woven-fabric benchmark): tighter weaves lock earlier. They are for
trying a ply, not properties of any product: measure the locking angle of the fabric you lay
(picture frame or bias extension) and pass it instead.
"""

from __future__ import annotations

from dataclasses import dataclass

from .base import MaterialError

__all__ = ["FABRIC_KINDS", "FabricKind", "locking_angle"]


@dataclass(frozen=True)
class FabricKind:
    """A kind of reinforcement fabric and its shear locking angle (degrees)."""

    name: str
    description: str
    locking_angle: float
    source: str


_TYPICAL = (
    "typical value chosen for vares from the range reported for this kind in picture-frame and "
    "bias-extension tests (Prodromou & Chen 1997; Cao et al. 2008): {range}"
)

#: The shipped fabric kinds by name.
FABRIC_KINDS: dict[str, FabricKind] = {
    kind.name: kind
    for kind in (
        FabricKind(
            "woven-plain",
            "plain-weave glass or carbon fabric",
            40.0,
            _TYPICAL.format(range="about 30–45° for plain weaves"),
        ),
        FabricKind(
            "woven-twill",
            "2/2 twill glass or carbon fabric",
            50.0,
            _TYPICAL.format(range="about 40–55° for twills"),
        ),
        FabricKind(
            "woven-satin",
            "5- or 8-harness satin glass or carbon fabric",
            55.0,
            _TYPICAL.format(range="about 50–60° for satins"),
        ),
        FabricKind(
            "ncf-biaxial",
            "biaxial (±45° or 0/90°) non-crimp fabric, stitched",
            50.0,
            "typical value chosen for vares: stitched non-crimp fabrics shear as far as twills "
            "before wrinkling, the stitch pattern and the direction of shear matter; "
            "no single test source",
        ),
    )
}


def locking_angle(kind: str) -> float:
    """The locking angle (degrees) of a fabric kind of :data:`FABRIC_KINDS`."""
    if kind not in FABRIC_KINDS:
        raise MaterialError(f"unknown fabric kind {kind!r}; known: {', '.join(FABRIC_KINDS)}")
    return FABRIC_KINDS[kind].locking_angle
