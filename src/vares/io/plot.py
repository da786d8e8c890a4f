"""Pictures of patterns and surfaces (matplotlib, no screen needed).

Every function draws on an ``Axes`` it is given or creates, and returns the figure, so callers
decide where it goes (``fig.savefig("pattern.png")``).
"""

from __future__ import annotations

from collections.abc import Sequence

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.colors import Normalize, TwoSlopeNorm

from ..geometry.mesh import SurfaceMesh
from ..materials import Fibres
from ..mechanics.fields import FIELD_DESCRIPTIONS

__all__ = [
    "FIELD_LABELS",
    "plot_convergence",
    "plot_cut_lines",
    "plot_nest",
    "plot_pattern",
    "plot_surface",
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


def _polygons(mesh: SurfaceMesh, coordinates: np.ndarray) -> np.ndarray | list[np.ndarray]:
    """Every cell's corners, in global cell order: one ``(cells, corners, d)`` array for a mesh
    of one cell type (matplotlib takes it whole, 20× faster than a list on 100k cells)."""
    blocks = [coordinates[cells] for cells in mesh.cells.values()]
    if len(blocks) == 1:
        return blocks[0]
    return [polygon for block in blocks for polygon in block]


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
) -> plt.Figure:
    """Draw a pattern ``(n, 2)``, optionally coloured by per-cell ``values`` (global order).

    ``field`` names the values (for the colour bar label and a centred colour scale); ``fibres``
    draws warp (solid) and fill (dashed) arrows; ``value_range`` fixes the colour scale;
    ``stress_scale`` (e.g. the material's stiffness) sets the round-off level of stress fields;
    ``marks`` ``(k, 2)`` are circled in red (where the outline crosses itself).
    """
    if ax is None:
        width, height = np.ptp(coordinates, axis=0)
        aspect = float(np.clip(height / width, 0.3, 3.0)) if width > 0 else 1.0
        size = (6.5, 6.5 * aspect * 0.85 + 0.6) if aspect <= 1 else (6.5 / aspect + 1.5, 6.5)
        fig, ax = plt.subplots(figsize=size, layout="constrained")
    fig = ax.figure
    polygons = _polygons(mesh, coordinates)
    if values is None:
        collection = PolyCollection(
            polygons, facecolors="#d9e6f2", edgecolors="#5b7a99", linewidths=0.2, rasterized=True
        )
        ax.add_collection(collection)
    else:
        values = np.asarray(values, dtype=float)
        norm, cmap = _colour_scale(values, field, value_range, stress_scale)
        collection = PolyCollection(
            polygons,
            array=values,
            cmap=cmap,
            norm=norm,
            edgecolors="k" if edges else "face",
            linewidths=0.1 if edges else 0.3,
            rasterized=True,  # vector drawings keep the outline and arrows, cells as an image
        )
        ax.add_collection(collection)
        label = FIELD_LABELS.get(field, field or "").replace("{stress}", stress_unit)
        fig.colorbar(collection, ax=ax, label=label, shrink=0.85)
    boundary = mesh.boundary_edges()
    ax.add_collection(LineCollection(coordinates[boundary], colors="k", linewidths=0.6))
    if marks is not None and len(marks):
        ax.plot(*np.asarray(marks).T, "o", mfc="none", mec="red", ms=9, mew=1.5, ls="none")
    if fibres is not None:
        centre = coordinates.mean(axis=0)
        size = 0.15 * np.ptp(coordinates, axis=0).max()
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
    if title:
        ax.set_title(title)
    return fig


def save_pattern_figure(path, *args, dpi: int = 150, **kwargs) -> None:
    """:func:`plot_pattern` straight to a file (PNG, SVG, PDF by suffix)."""
    fig = plot_pattern(*args, **kwargs)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)


def plot_surface(
    mesh: SurfaceMesh,
    values: np.ndarray | None = None,
    *,
    field: str | None = None,
    ax=None,
    title: str | None = None,
    stress_unit: str = "stress",
    stress_scale: float | None = None,
) -> plt.Figure:
    """3D view of the surface, optionally coloured by per-cell ``values``."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    if ax is None:
        fig = plt.figure(figsize=(7, 5.5), layout="constrained")
        ax = fig.add_subplot(projection="3d")
    fig = ax.figure
    polygons = _polygons(mesh, mesh.points)
    if values is None:
        collection = Poly3DCollection(
            polygons, facecolors="#d9e6f2", edgecolors="#5b7a99", linewidths=0.1
        )
    else:
        values = np.asarray(values, dtype=float)
        norm, cmap = _colour_scale(values, field, None, stress_scale)
        collection = Poly3DCollection(
            polygons,
            array=values,
            cmap=cmap,
            norm=norm,
            edgecolors=(0.25, 0.25, 0.25, 0.25),  # the shape shows whatever the colours
            linewidths=0.15,
            rasterized=True,
        )
        label = FIELD_LABELS.get(field, field or "").replace("{stress}", stress_unit)
        fig.colorbar(collection, ax=ax, label=label, shrink=0.7)
    ax.add_collection3d(collection)
    low, high = mesh.points.min(axis=0), mesh.points.max(axis=0)
    centre, half = 0.5 * (low + high), 0.5 * float(np.max(high - low))
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("z")
    if title:
        ax.set_title(title)
    return fig


def plot_convergence(history, ax=None, title: str | None = "convergence") -> plt.Figure:
    """Relative residual of every Newton iteration (log scale), steps marked by colour."""
    if ax is None:
        fig, ax = plt.subplots(figsize=(7, 3.8), layout="constrained")
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
    ax.set_xlabel("Newton iteration (all steps)")
    ax.set_ylabel("relative residual")
    ax.grid(True, which="both", alpha=0.3)
    if len({g for g in groups}) <= 8:
        ax.legend(fontsize="small")
    if title:
        ax.set_title(title)
    return fig


def plot_cut_lines(
    mesh: SurfaceMesh,
    panel_ids: np.ndarray,
    lines: Sequence[np.ndarray],
    *,
    title: str | None = None,
) -> plt.Figure:
    """3D view of a cut surface: every strip in its own colour, the cutting lines (node chains)
    drawn over it."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    fig = plt.figure(figsize=(8, 6), layout="constrained")
    ax = fig.add_subplot(projection="3d")
    cells = np.vstack(list(mesh.cells.values()))
    colours = plt.get_cmap("tab20")(np.mod(panel_ids, 20))
    ax.add_collection3d(
        Poly3DCollection(mesh.points[cells], facecolors=colours, edgecolors="none", alpha=0.9)
    )
    for chain in lines:
        path = mesh.points[chain]
        ax.plot(path[:, 0], path[:, 1], path[:, 2], color="black", linewidth=1.2)
    low, high = mesh.points.min(axis=0), mesh.points.max(axis=0)
    for axis, a, b in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), low, high, strict=True):
        axis(a, b)
    ax.set_box_aspect(np.maximum(high - low, 1e-3 * np.max(high - low)))  # true proportions
    ax.view_init(elev=30, azim=-60)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("z")
    if title:
        ax.set_title(title)
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
