"""Cutting panels of a cut mesh across, along lines from seam to seam: cross seams."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .cutting import SNAP, CutMesh, cut_mesh, panel_regions
from .surface_lines import CuttingError, SurfaceLine

__all__ = ["cut_across"]


def cut_across(
    cut: CutMesh, lines: SurfaceLine | Sequence[SurfaceLine], snap: float = SNAP
) -> CutMesh:
    """``cut`` cut further along ``lines`` (one line or several; on ``cut.mesh``, each from a
    node of a seam or of the boundary to another, none crossing another): every line splits
    the panel it crosses in two. The new chains follow ``cut.lines``; the panels keep their
    order, the parts of one that was split come right after it (by their first cell)."""
    from .surface_points import FaceLocator

    lines = [lines] if isinstance(lines, SurfaceLine) else list(lines)
    further = cut_mesh(cut.mesh, lines, snap, panels=False)
    cells = further.mesh.cells["triangle"]
    seam_edges = np.unique(np.sort(np.vstack([cut.seam_edges, further.seam_edges]), axis=1), axis=0)
    regions = panel_regions(cells, seam_edges, further.mesh.num_points)
    faces, _, _ = FaceLocator(cut.mesh).locate(further.mesh.points[cells].mean(axis=1))
    before = cut.panel_ids[faces]  # every new cell lies in a cell of the cut mesh
    order = []
    for region in range(int(regions.max()) + 1):
        mine = np.flatnonzero(regions == region)
        order.append((int(np.bincount(before[mine]).argmax()), int(mine[0]), region))
    if len(order) != cut.num_panels + len(lines):
        split = "a line across a panel" if len(lines) == 1 else f"{len(lines)} lines across panels"
        raise CuttingError(
            f"{split} must split {len(lines)} panel(s) in two; they left {len(order)} panels "
            f"of {cut.num_panels}"
        )
    renumber = np.empty(len(order), dtype=np.int64)
    for new, (_, _, region) in enumerate(sorted(order)):
        renumber[region] = new
    return CutMesh(
        further.mesh,
        renumber[regions],
        [*cut.lines, *further.lines],
        seam_edges,
        min(cut.worst_angle, further.worst_angle),
        cut.input_worst_angle,
    )
