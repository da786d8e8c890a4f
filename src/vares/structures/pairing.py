"""Strips in pairs on the roll: when to plan them so, and the lone strip of an odd count.

Tapered strips (a conic tent's) planned in pairs (:mod:`.widths`) lie side by side, head to
tail, two in the roll's width. With an odd number of strips one is left without a partner and
would take the roll's width alone for its whole length: it is cut across at half its length
(a cross seam, matched like every seam) and its two halves, the wide one and the narrow one,
are a pair of their own, half as long.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace

import numpy as np

from ..geometry.cross_cut import cut_across
from ..geometry.surface_lines import CuttingError, SurfaceLine, geodesic_lines
from .panels import split_panels
from .strip_plan import StripPlan
from .widths import pair_width, roll_estimate

__all__ = ["SAVING", "choose_plan", "pair_widths", "split_lone_strip"]

#: Strips are planned in pairs (option ``interlock = "auto"``) where that saves at least this
#: fraction of the roll's length (by the flattened strips) over strips one after the other.
SAVING = 0.1


def choose_plan(
    planned: Callable[[bool], StripPlan], mode: str, earlier: StripPlan | None = None
) -> StripPlan:
    """The strips alone or in pairs (``planned(interlock)``): as ``mode`` says (``always``,
    ``never``) or as an ``earlier`` plan of the same cut chose (planned again narrower: its
    ``compared`` and ``pairs_refused`` carried over), else in pairs where, by the flattened
    strips, that saves at least ``SAVING`` of the roll's length (tried only where the strips
    are tapered enough: two need less than 2 (1 − ``SAVING``) times the width of one, one seam
    along the warp; where they cannot be planned in pairs, ``pairs_refused`` of the plan alone
    says why). ``compared`` of the plan gives both estimates (strips, roll length)."""
    if earlier is not None:
        plan = planned(earlier.interlock)
        plan.compared, plan.pairs_refused = dict(earlier.compared), earlier.pairs_refused
        return plan
    if mode != "auto":
        return planned(mode == "always")
    alone = planned(False)
    alone.compared = {"alone": (len(alone.panels), roll_estimate(alone.lengths, 1))}
    if max(alone.straight_pairs) >= 2 * (1 - SAVING) * max(alone.widths):
        return alone
    try:
        pairs = planned(True)
    except CuttingError as refused:  # in pairs is a saving, not a must: the strips alone
        alone.pairs_refused = str(refused)
        return alone
    estimate = (len(pairs.panels), roll_estimate(pairs.lengths, 2))
    alone.compared = pairs.compared = {**alone.compared, "pairs": estimate}
    if estimate[1] <= (1 - SAVING) * alone.compared["alone"][1]:
        return pairs
    return alone


def _half_way(chain: np.ndarray, points: np.ndarray) -> int:
    """The node of a chain nearest to half its length."""
    steps = np.linalg.norm(np.diff(points[chain], axis=0), axis=1)
    along = np.concatenate([[0.0], np.cumsum(steps)])
    return int(chain[np.argmin(np.abs(along - 0.5 * along[-1]))])


def split_lone_strip(plan: StripPlan, snap: float = 0.0) -> StripPlan:
    """A plan in pairs with an odd number of strips: its last strip cut across at half its
    length (module docs), by the geodesic on the strip between the nodes half way along its
    two seams, the halves named ``strip-Na`` and ``strip-Nb``, each with the strip's warp.
    Returned unchanged when it has an even number, or the strip has not two seams. The cross
    line is cut without moving its crossings onto nodes (``snap`` 0): on the conic tent at
    2.5 m the default snap made its seam 1 % longer than the geodesic, and no cell smaller."""
    count = len(plan.panels)
    if not plan.interlock or count % 2 == 0 or count < 3:
        return plan
    index = count - 1
    cut, points = plan.cut, plan.cut.mesh.points
    cells = cut.mesh.cells["triangle"]
    used = np.unique(cells[cut.panel_ids == index])
    sides = [chain[np.isin(chain, used)] for chain in cut.lines]
    sides = [along for along in sides if len(along) >= 2]
    if len(sides) != 2:
        return plan
    start, end = (int(np.searchsorted(used, _half_way(c, points))) for c in sides)
    strip = plan.panels[index].mesh
    local = geodesic_lines(strip, [(start, end)])[0]
    across = SurfaceLine(used[local.ends], local.fractions, local.points)
    further = cut_across(cut, across, snap)
    name = plan.panels[index].name
    names = {k: p.name for k, p in enumerate(plan.panels[:index])}
    names |= {index: f"{name}a", index + 1: f"{name}b"}
    halves = [0.5 * plan.lengths[index]] * 2 if plan.lengths else []
    return replace(
        plan,
        cut=further,
        panels=split_panels(further.mesh, further.panel_ids, names),
        lines=[*plan.lines, across],
        warps=[*plan.warps, plan.warps[index]],
        widths=[*plan.widths, plan.widths[index]],
        lengths=[*plan.lengths[:index], *halves],
        straight_pairs=[*plan.straight_pairs, plan.straight_pairs[index]],
        split=(index, index + 1),
    )


def pair_widths(
    outlines: Sequence[np.ndarray], warps: Sequence[np.ndarray], split: tuple[int, int] | None
) -> list[float]:
    """The width of roll every piece (cut ring ``(k, 2)``, warp ``(2,)``) needs in a pair: with
    a turned copy of itself, or the halves of a split strip (``split``) with each other."""
    out = [pair_width(o, w) for o, w in zip(outlines, warps, strict=True)]
    if split is not None:
        a, b = split
        both = pair_width(outlines[a], warps[a], other=outlines[b], other_warp=warps[b])
        out[a] = out[b] = both
    return out
