"""A surface's strips as planned (:func:`vares.structures.layout.plan_strips`): the cut mesh,
its panels, the cutting lines and what the planning tried. Its own module so that the widths
(:mod:`.widths`) and the pairing (:mod:`.pairing`) read a plan without importing the planner."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..geometry.cutting import CutMesh
from ..geometry.line_families import LineFamily
from ..geometry.surface_lines import SurfaceLine
from .panels import Panel

__all__ = ["StripPlan"]


@dataclass
class StripPlan:
    """Strips cut from a surface.

    ``cut`` is the cut mesh (panel ids in strip order), ``panels`` the strips (``strip-1`` …),
    ``lines`` the cutting lines as computed (geodesics or plane sections, on the mesh the cut
    started from) and ``warps`` the 3D direction along every strip. ``widths`` are the flattened
    strips' extents across their warps, allowances included (mesh units); ``evaluations`` counts
    the layouts tried, ``history`` the widest strip for every number of gaps between lines tried.
    ``refinements`` is the number of rounds the surface was refined on its own faces before it
    was cut (``input_cells`` its triangles before, ``refined_cells`` after), and
    ``replaced_geodesics`` the number of geodesics replaced by their plane sections (module docs).
    With ``interlock`` the strips are planned in pairs (``widths`` are pairs' widths);
    ``lengths`` are the strips' extents along the warp, ``straight_pairs`` the widths their
    pairs would need with one seam along the warp, ``compared`` the roll estimates of both
    plans (:mod:`.pairing`), ``pairs_refused`` why strips planned alone could not be planned in
    pairs (where that was tried) and ``split`` the two halves of a strip cut across, if any.
    """

    cut: CutMesh
    panels: list[Panel]
    lines: list[SurfaceLine]
    warps: list[np.ndarray]
    widths: list[float]
    family: LineFamily | None = None
    evaluations: int = 0
    history: list[tuple[int, float]] = field(default_factory=list)  # (gaps, widest)
    refinements: int = 0
    input_cells: int = 0
    refined_cells: int = 0
    replaced_geodesics: int = 0
    interlock: bool = False
    lengths: list[float] = field(default_factory=list)
    straight_pairs: list[float] = field(default_factory=list)
    compared: dict[str, tuple[int, float]] = field(default_factory=dict)
    split: tuple[int, int] | None = None
    pairs_refused: str = ""
    straight_warp: bool = False
