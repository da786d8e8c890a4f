"""Strips cut across into pieces: cross seams where whole strips fit no roll.

On some surfaces the strips do not get narrower with their number: over the arches of a
ridge-and-valley wave neighbouring lines run close together in the middle and apart at the
ends, and a long strip's flattened outline bows, so that its extent across its warp stays
wider than the roll however many strips there are (:mod:`.equalise` refuses such a plan).
A piece of a strip bows less than the whole strip (the bow of an arc grows with the square of
its length), and laid with its own warp along its own length it needs less roll than as a part
of the whole strip. So the strips too wide for the roll are cut across into ``pieces`` parts
of equal extent along their warp (:func:`split_across`), each cut by the plane normal to the
strip's warp (the plane section of the strip, its ends moved onto the nearest nodes of its
seams or of the boundary; staggered from one strip to the next, so that no four pieces meet at
a point), and each piece gets its own warp: the direction of its part of the
strip's seams. The pieces of ``strip-N`` are ``strip-Na``, ``strip-Nb`` … along the warp; the
cross seams are matched like every seam.
"""

from __future__ import annotations

import string
from dataclasses import replace

import numpy as np

from ..geometry.cross_cut import cut_across
from ..geometry.cutting import SNAP, CutMesh
from ..geometry.surface_lines import SurfaceLine, plane_sections
from .panels import split_panels
from .strip_plan import StripPlan, along_strips

__all__ = ["MAX_PIECES", "split_across"]

#: The most pieces a strip is cut into (more would be a patchwork, not strips).
MAX_PIECES = 6
#: Neighbouring strips' cross seams are staggered by twice this fraction of a strip's extent
#: along its warp: no four pieces meet at a point.
STAGGER = 0.04


def split_across(
    plan: StripPlan, width: float, pieces: int, snap: float = SNAP, *, own_warps: bool = True
) -> StripPlan:
    """``plan`` with every strip wider than ``width`` (by ``plan.widths``) cut across into
    ``pieces`` parts (module docs); ``strip_of`` of the result gives each piece's strip. Each
    piece's warp runs along its part of the strip's seams, or (not ``own_warps``: a warp
    direction given for all) is its strip's. The widths and lengths are left for the caller to
    measure again. Unchanged where no strip is too wide or ``pieces`` is 1."""
    if pieces < 1 or pieces > MAX_PIECES:
        raise ValueError(f"pieces must be 1 … {MAX_PIECES}; got {pieces!r}")
    wide = [k for k, w in enumerate(plan.widths) if w > width]
    if pieces == 1 or not wide:
        return plan
    cut = plan.cut
    taken: set[int] = set()  # nodes where a cross seam ends
    across = {k: _cross_lines(plan, k, pieces, taken) for k in wide}
    lines = [line for k in wide for line in across[k]]
    if not lines:
        return plan
    further = cut_across(cut, lines, snap)
    # cut_across keeps the panels' order, the parts of a split one right after it: each line
    # adds one part to its strip
    parts = [1 + len(across.get(k, ())) for k in range(cut.num_panels)]
    located = np.repeat(np.arange(cut.num_panels), parts)
    strip_of = np.empty(further.num_panels, dtype=np.int64)
    cells = further.mesh.cells["triangle"]
    order = []
    for piece in range(further.num_panels):
        mine = further.panel_ids == piece
        strip = int(located[piece])
        along = further.mesh.points[cells[mine]].mean(axis=1) @ plan.warps[strip]
        order.append((strip, float(np.median(along)), piece))
    renumber = np.empty(len(order), dtype=np.int64)
    names: dict[int, str] = {}
    count: dict[int, int] = {}
    for new, (strip, _, piece) in enumerate(sorted(order)):
        renumber[piece] = new
        strip_of[new] = strip
        k = count[strip] = count.get(strip, -1) + 1
        alone = np.count_nonzero(located == strip) == 1
        names[new] = plan.panels[strip].name + ("" if alone else string.ascii_lowercase[k])
    ids = renumber[further.panel_ids]
    split = CutMesh(
        further.mesh,
        ids,
        further.lines,
        further.seam_edges,
        further.worst_angle,
        further.input_worst_angle,
    )
    panels = split_panels(split.mesh, ids, names)
    if not own_warps or plan.straight_warp or plan.interlock:
        warps = [plan.warps[s] for s in strip_of]
    else:
        seams_only = replace(split, lines=list(cut.lines))  # each piece's part of its seams
        warps = along_strips(seams_only, panels, plan.family)
    return replace(
        plan,
        cut=split,
        panels=panels,
        lines=[*plan.lines, *lines],
        warps=warps,
        strip_of=strip_of.tolist(),
        pieces=pieces,
        cross_cut=len(wide),
    )


def _cross_lines(plan: StripPlan, index: int, pieces: int, taken: set[int]) -> list[SurfaceLine]:
    """The lines that cut strip ``index`` into ``pieces``: at equal steps of its extent along
    its warp (staggered by ``STAGGER`` from one strip to the next), the longest piece of the
    plane section normal to the warp, on the cut mesh, its ends moved onto nodes (so that no
    seam edge is split; onto the farther node of its edge where the nearer one is ``taken``
    by another cross seam's end, which adds to ``taken``)."""
    cells = plan.cut.mesh.cells["triangle"]
    used = np.unique(cells[plan.cut.panel_ids == index])
    strip = plan.panels[index].mesh
    warp = np.asarray(plan.warps[index], dtype=float)
    along = strip.points @ warp
    low, high = float(along.min()), float(along.max())
    out = []
    for step in range(1, pieces):
        shift = STAGGER if index % 2 else -STAGGER
        found = plane_sections(strip, warp, low + (high - low) * (step / pieces + shift))
        if not found:
            continue
        line = max(found, key=lambda section: section.length)
        ends, fractions, points = line.ends.copy(), line.fractions.copy(), line.points.copy()
        for k in (0, -1):
            a, b = (int(v) for v in ends[k])
            near, far = (a, b) if fractions[k] <= 0.5 else (b, a)
            node = far if int(used[near]) in taken and int(used[far]) not in taken else near
            ends[k], fractions[k], points[k] = (node, node), 0.0, strip.points[node]
        if np.array_equal(ends[0], ends[-1]):
            continue
        taken.update(int(used[node]) for node in ends[[0, -1], 0])
        out.append(SurfaceLine(used[ends], fractions, points))
    return out
