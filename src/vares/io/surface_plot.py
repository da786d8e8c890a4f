"""Views of a surface (matplotlib): its cells rasterised with a depth buffer and shaded, coloured
by a per-cell field or by panel, lines drawn where the view sees them; the cut surface with its
cutting lines.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.cm import ScalarMappable
from matplotlib.collections import LineCollection
from matplotlib.colors import to_rgba

from ..geometry.mesh import SurfaceMesh
from .drawing import DPI, FACE, MESH_LINES_UP_TO
from .figures import (
    DrawnField,
    axes_pixels,
    draw_cells,
    each_field,
    field_scale,
    new_figure,
    place_title,
    rgba_bytes,
)
from .raster import View, rasterise

__all__ = ["plot_cut_lines", "plot_surface", "plot_surface_fields"]


class _SurfaceView:
    """The surface seen from a :class:`View`: its cells rasterised with a depth buffer and
    shaded by how squarely they face the viewer, lines drawn where the view sees them, and a
    small triad of the model axes."""

    def __init__(self, mesh: SurfaceMesh, ax, view: View, dpi: float):
        self.ax, self.view = ax, view
        self.screen, self.depth = view.project(mesh.points)
        self.image = rasterise(mesh.cells, self.screen, self.depth, pixels=axes_pixels(ax, dpi))
        facing = mesh.area_vectors() @ view.axes()[2]
        self.shade = 0.55 + 0.45 * np.abs(facing) / np.maximum(mesh.cell_areas(), 1e-300)

    def shaded(self, colours: np.ndarray) -> np.ndarray:
        """Per-cell RGBA colours ``(cells, 4)``, floats, shaded, as bytes."""
        shaded = np.array(colours, dtype=float)
        shaded[:, :3] *= self.shade[:, None]
        return rgba_bytes(shaded)

    def cells(self, colours: np.ndarray):
        """Per-cell RGBA colours ``(cells, 4)``, shaded: the image drawn."""
        return draw_cells(self.ax, self.image, self.shaded(colours))

    def paint(self, shown: ScalarMappable, values: np.ndarray) -> np.ndarray:
        """Per-cell values in the colour scale ``shown``: the image of the cells, shaded."""
        return self.image.colours(self.shaded(shown.to_rgba(values)))

    def lines(self, segments: np.ndarray, **style) -> None:
        """Node pairs ``(k, 2)`` drawn where they are seen (tested at their ends and middle)."""
        if not len(segments):
            return
        seen = np.ones(len(segments), dtype=bool)
        a, b = segments[:, 0], segments[:, 1]
        for t in (0.0, 0.5, 1.0):
            points = (1 - t) * self.screen[a] + t * self.screen[b]
            depth = (1 - t) * self.depth[a] + t * self.depth[b]
            seen &= self.image.seen(points, depth)
        self.ax.add_collection(LineCollection(self.screen[segments[seen]], **style))

    def finish(self, title: str | None) -> None:
        ax = self.ax
        ax.set_aspect("equal")
        ax.set_axis_off()
        right, up, _ = self.view.axes()
        x0, x1, y0, y1 = self.image.extent
        size = 0.07 * max(x1 - x0, y1 - y0)
        origin = np.array([x0 - 1.5 * size, y0])
        for k, name in enumerate("xyz"):
            tip = origin + size * np.array([right[k], up[k]])
            ax.plot(*np.column_stack([origin, tip]), color="k", lw=1)  # also widens the limits
            ax.plot(*tip, marker="o", ms=2, color="k")
            label = origin + 1.3 * size * np.array([right[k], up[k]])
            ax.text(*label, name, fontsize=8, ha="center", va="center")
        place_title(ax, title)


def _view_size(mesh: SurfaceMesh, view: View, width: float, drawing: float) -> tuple:
    """A figure ``width`` inches wide whose height fits the view of the surface drawn
    ``drawing`` inches wide (between 0.35 and 1.5 times as high as wide)."""
    across, high = np.ptp(view.project(mesh.points)[0], axis=0)
    aspect = float(np.clip(high / across, 0.35, 1.5)) if across > 0 else 1.0
    return width, 0.9 + drawing * aspect


def plot_surface(
    mesh: SurfaceMesh,
    values: np.ndarray | None = None,
    *,
    field: str | None = None,
    ax=None,
    title: str | None = None,
    stress_unit: str = "stress",
    stress_scale: float | None = None,
    view: View | None = None,
    dpi: float = DPI,
) -> plt.Figure:
    """A view of the surface (``view``: from 30° above, azimuth −60°, as matplotlib's 3D axes),
    optionally coloured by per-cell ``values``; hidden cells stay hidden (depth buffer). The
    cells are rasterised for the figure saved at ``dpi``."""
    return _draw_surface(mesh, values, field, ax, title, stress_unit, stress_scale, view, dpi)[0]


def _draw_surface(
    mesh, values, field, ax, title, stress_unit, stress_scale, view, dpi
) -> tuple[plt.Figure, DrawnField | None]:
    """:func:`plot_surface`, with what a next field re-colours (where values colour it)."""
    view = view or View()
    if ax is None:
        fig, ax = new_figure(_view_size(mesh, view, 7.0, 5.2))
    fig = ax.figure
    seen = _SurfaceView(mesh, ax, view, dpi)
    drawn = None
    if values is None:
        seen.cells(np.tile(to_rgba(FACE), (mesh.num_cells, 1)))
    else:
        values = np.asarray(values, dtype=float)
        shown, label = field_scale(values, field, None, stress_scale, stress_unit)
        picture = seen.cells(shown.to_rgba(values))
        bar = fig.colorbar(shown, ax=ax, label=label, shrink=0.7)
        drawn = DrawnField(fig, picture, bar, seen.paint)
    if mesh.num_cells <= MESH_LINES_UP_TO:
        seen.lines(mesh.edges(), colors=(0.25, 0.25, 0.25, 0.35), linewidths=0.15, rasterized=True)
    seen.lines(mesh.boundary_edges(), colors="k", linewidths=0.6)
    seen.finish(title)
    return fig, drawn


def plot_surface_fields(
    mesh: SurfaceMesh,
    fields: Mapping[str, np.ndarray],
    *,
    titles: Mapping[str, str] | None = None,
    stress_unit: str = "stress",
    stress_scale: float | None = None,
    view: View | None = None,
    dpi: float = DPI,
) -> Iterator[tuple[str, plt.Figure]]:
    """:func:`plot_surface` of each of ``fields`` (name → per-cell values) in turn, titled by
    ``titles`` (by name; else the name), as ``(name, figure)``: one figure, its cells
    rasterised, its lines and colour bar made once, that each field re-colours. Each picture
    is, to the byte, :func:`plot_surface`'s own; the figure is the same, so save it before
    taking the next. It is closed at the end."""

    def draw(name: str, values: np.ndarray, title: str) -> DrawnField:
        args = (name, None, title, stress_unit, stress_scale, view, dpi)
        return _draw_surface(mesh, values, *args)[1]

    return each_field(fields, titles, draw, stress_scale, stress_unit)


def plot_cut_lines(
    mesh: SurfaceMesh,
    panel_ids: np.ndarray,
    lines: Sequence[np.ndarray],
    *,
    title: str | None = None,
    dpi: float = DPI,
) -> plt.Figure:
    """A view of a cut surface: every strip in its own colour, the cutting lines (node chains)
    drawn over it where they are seen; the cells rasterised for the figure saved at ``dpi``."""
    fig, ax = new_figure(_view_size(mesh, View(), 8.0, 7.0))
    seen = _SurfaceView(mesh, ax, View(), dpi)
    seen.cells(plt.get_cmap("tab20")(np.mod(panel_ids, 20)))
    segments = [np.column_stack([chain[:-1], chain[1:]]) for chain in lines if len(chain) > 1]
    if segments:
        seen.lines(np.vstack(segments), colors="k", linewidths=1.2)
    seen.lines(mesh.boundary_edges(), colors="k", linewidths=0.6)
    seen.finish(title)
    return fig
