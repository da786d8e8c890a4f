"""Cutting a panel of a cut mesh in two along a line across it: a cross seam."""

from __future__ import annotations

import numpy as np

from .cutting import SNAP, CutMesh, cut_mesh, panel_regions
from .surface_lines import CuttingError, SurfaceLine

__all__ = ["cut_across"]


def cut_across(cut: CutMesh, line: SurfaceLine, snap: float = SNAP) -> CutMesh:
    """``cut`` cut further along ``line`` (on ``cut.mesh``, its ends on nodes of seams or of
    the boundary): the panel it crosses becomes two. The new chain is the last of ``lines``;
    the panels keep their order, the second part of the one split comes right after it."""
    from .surface_points import FaceLocator

    further = cut_mesh(cut.mesh, [line], snap, panels=False)
    cells = further.mesh.cells["triangle"]
    seam_edges = np.unique(np.sort(np.vstack([cut.seam_edges, further.seam_edges]), axis=1), axis=0)
    regions = panel_regions(cells, seam_edges, further.mesh.num_points)
    faces, _, _ = FaceLocator(cut.mesh).locate(further.mesh.points[cells].mean(axis=1))
    before = cut.panel_ids[faces]  # every new cell lies in a cell of the cut mesh
    order = []
    for region in range(int(regions.max()) + 1):
        mine = np.flatnonzero(regions == region)
        order.append((int(np.bincount(before[mine]).argmax()), int(mine[0]), region))
    if len(order) != cut.num_panels + 1:
        raise CuttingError(
            f"a line across a panel must split one panel in two; it left {len(order)} panels "
            f"of {cut.num_panels}"
        )
    renumber = np.empty(len(order), dtype=np.int64)
    for new, (_, _, region) in enumerate(sorted(order)):
        renumber[region] = new
    return CutMesh(
        further.mesh,
        renumber[regions],
        [*cut.lines, further.lines[0]],
        seam_edges,
        min(cut.worst_angle, further.worst_angle),
        cut.input_worst_angle,
    )
