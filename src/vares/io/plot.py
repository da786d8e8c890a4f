"""Pictures of patterns and surfaces (matplotlib, no screen needed).

Every function draws on an ``Axes`` it is given or creates, and returns the figure, so callers
decide where it goes (``fig.savefig("pattern.png")``). Patterns, convergence and the nest on the
roll are drawn here; views of a surface in :mod:`vares.io.surface_plot`, importable from here too.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.colors import to_rgba
from matplotlib.ticker import FuncFormatter, MaxNLocator

from ..geometry.mesh import SurfaceMesh
from ..materials import Fibres
from .drawing import DPI, FACE, MARGINS, MESH, MESH_LINES_UP_TO, SIDE, fibre_arrow_length
from .figures import (
    FIELD_LABELS,
    DrawnField,
    axes_pixels,
    draw_cells,
    each_field,
    field_scale,
    new_figure,
    pixel_count,
    place_title,
    rgba_bytes,
)
from .raster import CellImage, View, rasterise
from .surface_plot import plot_cut_lines, plot_surface, plot_surface_fields

__all__ = [
    "DPI",
    "FIELD_LABELS",
    "MESH_LINES_UP_TO",
    "View",
    "pattern_image",
    "plot_convergence",
    "plot_cut_lines",
    "plot_nest",
    "plot_pattern",
    "plot_pattern_fields",
    "plot_surface",
    "plot_surface_fields",
    "save_pattern_figure",
]


#: Unicode superscripts, for powers of ten written as plain text.
_SUPERSCRIPTS = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def _power_of_ten(value: float, _position=None) -> str:
    """A decade's tick label, ``10⁻⁶``: plain text. Matplotlib's ``$10^{-6}$`` is typeset by
    its mathtext, afresh in every figure: 35 ms of a convergence plot, and 40 ms more in a
    process's first, which builds the parser."""
    return "10" + str(round(math.log10(value))).translate(_SUPERSCRIPTS)


def _pattern_size(coordinates: np.ndarray) -> tuple[float, float]:
    """The size (inches) of :func:`plot_pattern`'s own figure of a pattern: 6.5 inches along the
    pattern's longer side, a colour bar beside it."""
    width, height = np.ptp(coordinates, axis=0)
    aspect = float(np.clip(height / width, 0.3, 3.0)) if width > 0 else 1.0
    return (SIDE, SIDE * aspect * 0.85 + 0.6) if aspect <= 1 else (SIDE / aspect + 1.5, SIDE)


def pattern_image(mesh: SurfaceMesh, coordinates: np.ndarray, dpi: float = DPI) -> CellImage:
    """The cells of a pattern ``(n, 2)`` rasterised as :func:`plot_pattern` does for its own
    figure saved at ``dpi``: several fields of one pattern drawn from one rasterisation (its
    ``image``)."""
    width, height = _pattern_size(coordinates)
    left, right, bottom, top = MARGINS
    pixels = pixel_count(width - left - right, height - bottom - top, dpi)
    return rasterise(mesh.cells, coordinates, pixels=pixels)


def plot_pattern(
    mesh: SurfaceMesh,
    coordinates: np.ndarray,
    values: np.ndarray | None = None,
    *,
    field: str | None = None,
    ax: plt.Axes | None = None,
    fibres: Fibres | None = None,
    title: str | None = None,
    stress_unit: str = "stress",
    value_range: Sequence[float] | None = None,
    edges: bool = False,
    stress_scale: float | None = None,
    marks: np.ndarray | None = None,
    dpi: float = DPI,
    image: CellImage | None = None,
) -> plt.Figure:
    """Draw a pattern ``(n, 2)``, optionally coloured by per-cell ``values`` (global order).

    ``field`` names the values (for the colour bar label and a centred colour scale); ``fibres``
    draws warp (solid) and fill (dashed) arrows; ``value_range`` fixes the colour scale;
    ``edges`` draws the mesh lines over a field (a plain pattern shows them up to
    :data:`MESH_LINES_UP_TO` cells); ``stress_scale`` (e.g. the material's stiffness) sets the
    round-off level of stress fields; ``marks`` ``(k, 2)`` are circled in red (where the
    outline crosses itself). The cells are drawn as an image (:mod:`vares.io.raster`)
    rasterised for the figure saved at ``dpi``, or ``image`` (:func:`pattern_image`, shared by
    pictures of one pattern); the outline, mesh lines and arrows as vectors.
    """
    return _draw_pattern(
        mesh,
        coordinates,
        values,
        field=field,
        ax=ax,
        fibres=fibres,
        title=title,
        stress_unit=stress_unit,
        value_range=value_range,
        edges=edges,
        stress_scale=stress_scale,
        marks=marks,
        dpi=dpi,
        image=image,
    ).figure


def _draw_pattern(
    mesh, coordinates, values, *, field, ax, fibres, title, stress_unit, value_range, edges,
    stress_scale, marks, dpi, image,
) -> DrawnField:  # fmt: skip
    """:func:`plot_pattern`, with what a next field re-colours."""
    picture = bar = None
    if ax is None:
        fig, ax = new_figure(_pattern_size(coordinates))
        if image is None:
            image = pattern_image(mesh, coordinates, dpi)
    elif image is None:
        image = rasterise(mesh.cells, coordinates, pixels=axes_pixels(ax, dpi))
    fig = ax.figure
    if values is None:
        draw_cells(ax, image, np.broadcast_to(rgba_bytes(to_rgba(FACE)), (mesh.num_cells, 4)))
        if mesh.num_cells <= MESH_LINES_UP_TO:
            lines = LineCollection(
                coordinates[mesh.edges()], colors=MESH, linewidths=0.2, rasterized=True
            )
            ax.add_collection(lines)
    else:
        values = np.asarray(values, dtype=float)
        shown, label = field_scale(values, field, value_range, stress_scale, stress_unit)
        picture = draw_cells(ax, image, shown.to_rgba(values, bytes=True))
        if edges:
            lines = LineCollection(
                coordinates[mesh.edges()], colors="k", linewidths=0.1, rasterized=True
            )
            ax.add_collection(lines)
        bar = fig.colorbar(shown, ax=ax, label=label, shrink=0.85)
    boundary = mesh.boundary_edges()
    ax.add_collection(LineCollection(coordinates[boundary], colors="k", linewidths=0.6))
    if marks is not None and len(marks):
        ax.plot(*np.asarray(marks).T, "o", mfc="none", mec="red", ms=9, mew=1.5, ls="none")
    if fibres is not None:
        centre = coordinates.mean(axis=0)
        size = fibre_arrow_length(coordinates)
        for direction, style, name in ((fibres.warp, "-", "warp"), (fibres.fill, "--", "fill")):
            ax.annotate(
                "",
                xy=centre + size * direction,
                xytext=centre,
                arrowprops={"arrowstyle": "->", "linestyle": style, "color": "k", "lw": 1.4},
            )
            ax.text(*(centre + 1.12 * size * direction), name, ha="center", va="center")
    ax.set_aspect("equal")
    ax.autoscale_view()
    place_title(ax, title)
    return DrawnField(
        fig, picture, bar, lambda shown, v: image.colours(shown.to_rgba(v, bytes=True))
    )


def plot_pattern_fields(
    mesh: SurfaceMesh,
    coordinates: np.ndarray,
    fields: Mapping[str, np.ndarray],
    *,
    titles: Mapping[str, str] | None = None,
    fibres: Fibres | None = None,
    stress_unit: str = "stress",
    stress_scale: float | None = None,
    dpi: float = DPI,
    image: CellImage | None = None,
) -> Iterator[tuple[str, plt.Figure]]:
    """:func:`plot_pattern` of each of ``fields`` (name → per-cell values) in turn, titled by
    ``titles`` (by name; else the name), as ``(name, figure)``: one figure, its axes, outline,
    arrows and colour bar made once, that each field re-colours (cells, colour bar, label,
    title). Each picture is, to the byte, :func:`plot_pattern`'s own of that field, for a
    quarter less work (a report draws five); but the figure is the same, so save it before
    taking the next. It is closed at the end."""

    def draw(name: str, values: np.ndarray, title: str) -> DrawnField:
        return _draw_pattern(
            mesh, coordinates, values, field=name, ax=None, fibres=fibres, title=title,
            stress_unit=stress_unit, value_range=None, edges=False, stress_scale=stress_scale,
            marks=None, dpi=dpi, image=image,
        )  # fmt: skip

    return each_field(fields, titles, draw, stress_scale, stress_unit)


def save_pattern_figure(path, *args, dpi: float = DPI, **kwargs) -> None:
    """:func:`plot_pattern` straight to a file (PNG, SVG, PDF by suffix)."""
    fig = plot_pattern(*args, dpi=dpi, **kwargs)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)


def plot_convergence(history, ax=None, title: str | None = "convergence") -> plt.Figure:
    """Relative residual of every Newton iteration (log scale), steps marked by colour."""
    if ax is None:
        fig, ax = new_figure((7, 3.8), margins=(0.8, 0.15, 0.5, 0.3))
    fig = ax.figure
    residuals = np.array([r.relative_residual for r in history])
    groups = [(r.strategy, r.step) for r in history]
    start = 0
    for k in range(1, len(history) + 1):
        if k == len(history) or groups[k] != groups[start]:
            strategy, step = groups[start]
            ax.semilogy(
                range(start, k),
                residuals[start:k],
                "o-",
                markersize=3,
                label=f"{strategy}, step {step}" if k - start > 0 else None,
            )
            start = k
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.yaxis.set_major_formatter(FuncFormatter(_power_of_ten))
    ax.set_xlabel("Newton iteration (all steps)")
    ax.set_ylabel("relative residual")
    ax.grid(True, which="both", alpha=0.3)
    if len({g for g in groups}) <= 8:
        ax.legend(fontsize="small")
    place_title(ax, title)
    return fig


def plot_nest(roll_width: float, length: float, pieces, *, units: str = "m") -> plt.Figure:
    """The pieces on the roll (``vares.io.dxf.NestedDrawing``): cut lines filled, seam lines and
    strip numbers; the roll's used length framed. A long roll is drawn in rows of at most 16
    roll widths."""
    rows = max(1, int(np.ceil(length / (16.0 * roll_width))))
    piece_length = length / rows
    fig, axes = plt.subplots(
        rows,
        1,
        figsize=(12, 0.4 + rows * 12 * roll_width / piece_length),
        layout="constrained",
        squeeze=False,
    )
    for row, ax in enumerate(axes[:, 0]):
        ax.add_patch(
            plt.Rectangle((0, 0), length, roll_width, fill=False, edgecolor="grey", linewidth=1.0)
        )
        for number, piece in enumerate(pieces):
            colour = plt.get_cmap("tab20")(number % 20)
            ax.fill(piece.cut[:, 0], piece.cut[:, 1], color=colour, alpha=0.4, linewidth=0)
            closed = np.vstack([piece.seam, piece.seam[:1]])
            ax.plot(closed[:, 0], closed[:, 1], color="black", linewidth=0.5)
            centre = piece.seam.mean(axis=0)
            if row * piece_length <= centre[0] <= (row + 1) * piece_length:
                label = piece.name.replace("strip-", "")
                ax.text(*centre, label, ha="center", va="center", fontsize=7)
        ax.set_xlim(row * piece_length - 0.005 * length, (row + 1) * piece_length + 0.005 * length)
        ax.set_ylim(-0.05 * roll_width, 1.05 * roll_width)
        ax.set_aspect("equal")
        ax.set_ylabel(f"[{units}]")
    axes[-1, 0].set_xlabel(f"along the roll [{units}]; width {roll_width:g}, length {length:.4g}")
    return fig
