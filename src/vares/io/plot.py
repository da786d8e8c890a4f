"""Pictures of patterns and surfaces (matplotlib, no screen needed).

Every function draws on an ``Axes`` it is given or creates, and returns the figure, so callers
decide where it goes (``fig.savefig("pattern.png")``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import NamedTuple

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.cm import ScalarMappable
from matplotlib.collections import LineCollection
from matplotlib.colors import Normalize, TwoSlopeNorm, to_rgba
from matplotlib.ticker import FuncFormatter, MaxNLocator

from ..geometry.mesh import SurfaceMesh
from ..materials import Fibres
from ..mechanics.fields import FIELD_DESCRIPTIONS
from .raster import CellImage, View, rasterise
from .sketch import DPI, FACE, MARGINS, MESH, MESH_LINES_UP_TO, SIDE, fibre_arrow_length

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

#: Short colour bar labels of the per-cell fields; ``{stress}`` is replaced by the stress unit.
FIELD_LABELS = {
    "det_F": "det F (area erected / pattern) [-]",
    "stretch_max": "larger principal stretch [-]",
    "stretch_min": "smaller principal stretch [-]",
    "stress_max": "larger principal stress [{stress}]",
    "stress_min": "smaller principal stress [{stress}]",
    "warp_stretch": "warp stretch [-]",
    "fill_stretch": "fill stretch [-]",
    "shear_angle": "yarn shear angle [°]",
    "warp_compensation": "warp compensation [%]",
    "fill_compensation": "fill compensation [%]",
    "warp_stress": "warp stress (Cauchy) [{stress}]",
    "fill_stress": "fill stress (Cauchy) [{stress}]",
    "warp_stress_pk2": "warp stress (2nd P-K) [{stress}]",
    "fill_stress_pk2": "fill stress (2nd P-K) [{stress}]",
    "compressed_yarns": "compressed yarns (1 = yes)",
    "wrinkling": "compressive principal stress (1 = yes)",
    "energy": "strain energy",
    "energy_density": "strain energy density [{stress}]",
    "pattern_area": "pattern area",
    "surface_area": "surface area",
    "warp_deviation": "warp deviation from the direction [°]",
    "normal_deviation": "normal deviation from the design (length units)",
    "state": "0 taut, 1 wrinkled, 2 slack",
    "warp_stress_difference": "warp force − intended prestress [{stress}]",
    "fill_stress_difference": "fill force − intended prestress [{stress}]",
}
#: Fields whose colour scale is centred on a neutral value (diverging colours).
_CENTRED = {
    "det_F": 1.0,
    "warp_stretch": 1.0,
    "fill_stretch": 1.0,
    "stretch_max": 1.0,
    "stretch_min": 1.0,
    "shear_angle": 0.0,
    "warp_stress": 0.0,
    "fill_stress": 0.0,
    "warp_stress_pk2": 0.0,
    "fill_stress_pk2": 0.0,
    "stress_max": 0.0,
    "stress_min": 0.0,
    "warp_deviation": 0.0,
    "normal_deviation": 0.0,
    "warp_stress_difference": 0.0,
    "fill_stress_difference": 0.0,
}


#: Spreads below these are round-off: such fields are drawn in one colour (unitless, degrees, %).
_MIN_SPAN = {
    "det_F": 1e-6,
    "warp_stretch": 1e-6,
    "fill_stretch": 1e-6,
    "stretch_max": 1e-6,
    "stretch_min": 1e-6,
    "shear_angle": 1e-4,
    "warp_deviation": 1e-4,
    "warp_compensation": 1e-4,
    "fill_compensation": 1e-4,
}


def _colour_scale(values, field, value_range, stress_scale):
    """Norm and colour map: diverging about the neutral value where there is one; a spread
    below round-off level (per field, or 1e-6 × ``stress_scale`` for stresses) is widened so
    such a field shows as uniform instead of as amplified noise."""
    low, high = value_range if value_range is not None else (np.nanmin(values), np.nanmax(values))
    unit = FIELD_DESCRIPTIONS.get(field, ("", ""))[1]
    span = _MIN_SPAN.get(field, 1e-6 * stress_scale if unit == "stress" and stress_scale else 0)
    if high - low < span:
        middle = 0.5 * (low + high)
        low, high = middle - 0.5 * span, middle + 0.5 * span
    centre = _CENTRED.get(field)
    if centre is not None and low < centre < high:
        return TwoSlopeNorm(centre, low, high), "coolwarm"  # grey, not white, at the centre
    return Normalize(low, high if high > low else low + 1e-12), "viridis"


#: Fixed margins of a picture, inches: left, right, bottom, top (room for a title, tick labels
#: and axis labels; a colour bar takes its room from the axes).
_MARGINS = MARGINS  # as the run's preview (sketch.py)


def _figure(size: tuple[float, float], margins: tuple[float, float, float, float] = _MARGINS):
    """A figure with one axes and fixed margins: a constrained layout took 0.1 s of a 0.25 s
    picture, as of a convergence plot (its log axis has some 90 ticks to measure), and a report
    has nine."""
    fig, ax = plt.subplots(figsize=size)
    width, height = size
    left, right, bottom, top = margins
    fig.subplots_adjust(
        left=left / width, right=1 - right / width, bottom=bottom / height, top=1 - top / height
    )
    return fig, ax


def _title(ax, title: str | None) -> None:
    """The title just above the axes. Placed, not left to matplotlib to place: it would measure
    every tick label to find whether any is on top (none is), 13 ms of a 0.12 s convergence
    plot."""
    if title:
        ax.set_title(title, y=1.0)


#: Unicode superscripts, for powers of ten written as plain text.
_SUPERSCRIPTS = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def _power_of_ten(value: float, _position=None) -> str:
    """A decade's tick label, ``10⁻⁶``: plain text. Matplotlib's ``$10^{-6}$`` is typeset by
    its mathtext, afresh in every figure: 35 ms of a convergence plot, and 40 ms more in a
    process's first, which builds the parser."""
    return "10" + str(round(math.log10(value))).translate(_SUPERSCRIPTS)


def _pixel_count(width: float, height: float, dpi: float) -> int:
    """Pixels along the longer side of axes ``width`` × ``height`` inches saved at ``dpi``: a
    drawing with equal axes spans at most that many, so its cells rasterised at this count are
    drawn without being enlarged (blocky) nor shrunk (work for nothing)."""
    return max(16, round(dpi * max(width, height)))


def _pixels(ax, dpi: float) -> int:
    """:func:`_pixel_count` of the axes ``ax`` as they are placed in their figure."""
    box = ax.get_position()
    width, height = ax.figure.get_size_inches()
    return _pixel_count(box.width * width, box.height * height, dpi)


def _bytes(rgba: np.ndarray) -> np.ndarray:
    """RGBA colours, floats 0 … 1, as bytes (an image of bytes is drawn without checks for NaN)."""
    return np.round(255 * np.asarray(rgba)).astype(np.uint8)


def _cells(ax, image: CellImage, colours: np.ndarray):
    """The cells as an image, each in its colour (``(cells, 4)`` RGBA bytes)."""
    return ax.imshow(
        image.colours(colours),
        extent=image.extent,
        origin="lower",
        interpolation="nearest",
        zorder=1,
    )


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
    left, right, bottom, top = _MARGINS
    pixels = _pixel_count(width - left - right, height - bottom - top, dpi)
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


class _Drawn(NamedTuple):
    """A drawn field: its figure, the image of the cells and its colour bar, and how per-cell
    values in a colour scale become that image."""

    figure: plt.Figure
    picture: object
    bar: object
    paint: Callable[[ScalarMappable, np.ndarray], np.ndarray]


def _field_scale(values, field, value_range, stress_scale, stress_unit):
    """The colour scale per-cell values are drawn in, and its label."""
    norm, cmap = _colour_scale(values, field, value_range, stress_scale)
    label = FIELD_LABELS.get(field, field or "").replace("{stress}", stress_unit)
    return ScalarMappable(norm=norm, cmap=cmap), label


def _each_field(
    fields: Mapping[str, np.ndarray],
    titles: Mapping[str, str] | None,
    draw: Callable[[str, np.ndarray, str], _Drawn],
    stress_scale: float | None,
    stress_unit: str,
) -> Iterator[tuple[str, plt.Figure]]:
    """Every field on one figure: the first ``draw``-n, each next re-colouring its cells and
    colour bar and re-titling it; the figure closed at the end."""
    drawn = None
    try:
        for name, values in fields.items():
            values = np.asarray(values, dtype=float)
            title = name if titles is None else titles[name]
            if drawn is None:
                drawn = draw(name, values, title)
            else:
                shown, label = _field_scale(values, name, None, stress_scale, stress_unit)
                drawn.picture.set_data(drawn.paint(shown, values))
                drawn.bar.mappable = shown
                drawn.bar.update_normal()  # the new scale, its ticks and their labels
                drawn.bar.set_label(label)
                _title(drawn.figure.axes[0], title)
            yield name, drawn.figure
    finally:
        if drawn is not None:
            plt.close(drawn.figure)


def _draw_pattern(
    mesh, coordinates, values, *, field, ax, fibres, title, stress_unit, value_range, edges,
    stress_scale, marks, dpi, image,
) -> _Drawn:  # fmt: skip
    """:func:`plot_pattern`, with what a next field re-colours."""
    picture = bar = None
    if ax is None:
        fig, ax = _figure(_pattern_size(coordinates))
        if image is None:
            image = pattern_image(mesh, coordinates, dpi)
    elif image is None:
        image = rasterise(mesh.cells, coordinates, pixels=_pixels(ax, dpi))
    fig = ax.figure
    if values is None:
        _cells(ax, image, np.broadcast_to(_bytes(to_rgba(FACE)), (mesh.num_cells, 4)))
        if mesh.num_cells <= MESH_LINES_UP_TO:
            lines = LineCollection(
                coordinates[mesh.edges()], colors=MESH, linewidths=0.2, rasterized=True
            )
            ax.add_collection(lines)
    else:
        values = np.asarray(values, dtype=float)
        shown, label = _field_scale(values, field, value_range, stress_scale, stress_unit)
        picture = _cells(ax, image, shown.to_rgba(values, bytes=True))
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
    _title(ax, title)
    return _Drawn(fig, picture, bar, lambda shown, v: image.colours(shown.to_rgba(v, bytes=True)))


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

    def draw(name: str, values: np.ndarray, title: str) -> _Drawn:
        return _draw_pattern(
            mesh, coordinates, values, field=name, ax=None, fibres=fibres, title=title,
            stress_unit=stress_unit, value_range=None, edges=False, stress_scale=stress_scale,
            marks=None, dpi=dpi, image=image,
        )  # fmt: skip

    return _each_field(fields, titles, draw, stress_scale, stress_unit)


def save_pattern_figure(path, *args, dpi: float = DPI, **kwargs) -> None:
    """:func:`plot_pattern` straight to a file (PNG, SVG, PDF by suffix)."""
    fig = plot_pattern(*args, dpi=dpi, **kwargs)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)


class _SurfaceView:
    """The surface seen from a :class:`View`: its cells rasterised with a depth buffer and
    shaded by how squarely they face the viewer, lines drawn where the view sees them, and a
    small triad of the model axes."""

    def __init__(self, mesh: SurfaceMesh, ax, view: View, dpi: float):
        self.ax, self.view = ax, view
        self.screen, self.depth = view.project(mesh.points)
        self.image = rasterise(mesh.cells, self.screen, self.depth, pixels=_pixels(ax, dpi))
        facing = mesh.area_vectors() @ view.axes()[2]
        self.shade = 0.55 + 0.45 * np.abs(facing) / np.maximum(mesh.cell_areas(), 1e-300)

    def shaded(self, colours: np.ndarray) -> np.ndarray:
        """Per-cell RGBA colours ``(cells, 4)``, floats, shaded, as bytes."""
        shaded = np.array(colours, dtype=float)
        shaded[:, :3] *= self.shade[:, None]
        return _bytes(shaded)

    def cells(self, colours: np.ndarray):
        """Per-cell RGBA colours ``(cells, 4)``, shaded: the image drawn."""
        return _cells(self.ax, self.image, self.shaded(colours))

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
        _title(ax, title)


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
) -> tuple[plt.Figure, _Drawn | None]:
    """:func:`plot_surface`, with what a next field re-colours (where values colour it)."""
    view = view or View()
    if ax is None:
        fig, ax = _figure(_view_size(mesh, view, 7.0, 5.2))
    fig = ax.figure
    seen = _SurfaceView(mesh, ax, view, dpi)
    drawn = None
    if values is None:
        seen.cells(np.tile(to_rgba(FACE), (mesh.num_cells, 1)))
    else:
        values = np.asarray(values, dtype=float)
        shown, label = _field_scale(values, field, None, stress_scale, stress_unit)
        picture = seen.cells(shown.to_rgba(values))
        bar = fig.colorbar(shown, ax=ax, label=label, shrink=0.7)
        drawn = _Drawn(fig, picture, bar, seen.paint)
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

    def draw(name: str, values: np.ndarray, title: str) -> _Drawn:
        args = (name, None, title, stress_unit, stress_scale, view, dpi)
        return _draw_surface(mesh, values, *args)[1]

    return _each_field(fields, titles, draw, stress_scale, stress_unit)


def plot_convergence(history, ax=None, title: str | None = "convergence") -> plt.Figure:
    """Relative residual of every Newton iteration (log scale), steps marked by colour."""
    if ax is None:
        fig, ax = _figure((7, 3.8), margins=(0.8, 0.15, 0.5, 0.3))
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
    _title(ax, title)
    return fig


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
    fig, ax = _figure(_view_size(mesh, View(), 8.0, 7.0))
    seen = _SurfaceView(mesh, ax, View(), dpi)
    seen.cells(plt.get_cmap("tab20")(np.mod(panel_ids, 20)))
    segments = [np.column_stack([chain[:-1], chain[1:]]) for chain in lines if len(chain) > 1]
    if segments:
        seen.lines(np.vstack(segments), colors="k", linewidths=1.2)
    seen.lines(mesh.boundary_edges(), colors="k", linewidths=0.6)
    seen.finish(title)
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
