"""Pictures of a ply's darts and splices: the shear on the mould before and after the darts were
opened (or the ply was spliced), with the dart or splice lines, and the flat pattern with its
darts, or the flat pieces (:mod:`vares.analysis.darts`, :mod:`vares.analysis.splices`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import matplotlib.pyplot as plt
import numpy as np

from ..analysis.darts import DartedPattern
from ..geometry.face_walk import node_normals

if TYPE_CHECKING:
    from ..analysis.splices import SplicedPly
    from ..geometry.mesh import SurfaceMesh

__all__ = ["plot_darts", "plot_splices"]

#: The oblique view of the mould: elevation and azimuth (degrees).
VIEW = (25.0, -60.0)


class _Colours:
    """The shear magnitude's colours: one scale from 0 to ``top``, cells at or beyond the
    locking angle in red."""

    def __init__(self, top: float, locking: float) -> None:
        from matplotlib.colors import Normalize

        self.map, self.norm, self.locking = plt.get_cmap("viridis"), Normalize(0.0, top), locking

    def __call__(self, shear: np.ndarray) -> np.ndarray:
        magnitude = np.abs(np.nan_to_num(shear))
        rgba = self.map(self.norm(magnitude))
        rgba[magnitude >= self.locking] = (0.85, 0.1, 0.1, 1.0)
        return rgba

    def bar(self, fig: plt.Figure) -> None:
        mappable = plt.cm.ScalarMappable(norm=self.norm, cmap=self.map)
        fig.colorbar(
            mappable, ax=fig.axes, shrink=0.7, label="shear angle [°] (red: at the locking angle)"
        )


def _on_mould(ax, mesh: SurfaceMesh, shear: np.ndarray, lines, title: str, colours) -> None:
    """The shear on the mould in the oblique view, the ``lines`` ``(k, 3)`` on the side seen in
    black."""
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    corners = mesh.points[mesh.cells["triangle"]]
    ax.add_collection3d(
        Poly3DCollection(
            corners, facecolors=colours(shear), edgecolors=colours(shear), linewidths=0.2, zorder=1
        )
    )
    size = float(np.linalg.norm(np.ptp(mesh.points, axis=0)))
    elevation, azimuth = np.radians(VIEW[0]), np.radians(VIEW[1])
    towards = np.array(
        [
            np.cos(elevation) * np.cos(azimuth),
            np.cos(elevation) * np.sin(azimuth),
            np.sin(elevation),
        ]
    )
    segments = []
    if lines:
        from scipy.spatial import cKDTree

        at_nodes, tree = node_normals(mesh), cKDTree(mesh.points)
    for line in lines:  # the parts on the side seen, lifted off the surface a little
        normals = at_nodes[tree.query(line)[1]]
        lifted = line + 0.01 * size * normals
        seen = (normals @ towards > 0)[:-1] & (normals @ towards > 0)[1:]
        segments.append(np.stack([lifted[:-1], lifted[1:]], axis=1)[seen])
    if segments:
        ax.add_collection3d(
            Line3DCollection(np.vstack(segments), colors="k", linewidths=2.0, zorder=2)
        )
    low, high = mesh.points.min(axis=0), mesh.points.max(axis=0)
    for axis, a, b in zip("xyz", low, high, strict=True):
        getattr(ax, f"set_{axis}lim")(a, b)
    ax.set_box_aspect(np.maximum(high - low, 1e-3 * float(np.max(high - low))), zoom=1.3)
    ax.view_init(elev=VIEW[0], azim=VIEW[1])
    largest = float(np.nanmax(np.abs(shear)))
    ax.set_title(f"{title}\nlargest shear {largest:.1f}°", fontsize=10)
    ax.set_axis_off()


def _flat(ax, pieces, colours, title: str, lines=()) -> None:
    """Flat patterns ``(coordinates (n, 2), triangles, shear)`` and open ``lines`` ``(k, 2)``."""
    from matplotlib.collections import PolyCollection

    for coordinates, triangles, shear in pieces:
        ax.add_collection(
            PolyCollection(
                coordinates[triangles],
                facecolors=colours(shear),
                edgecolors="face",
                linewidths=0.2,
            )
        )
    for line in lines:
        ax.plot(line[:, 0], line[:, 1], "k-", linewidth=1.2)
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_axis_off()
    ax.set_title(title, fontsize=10)


def plot_darts(darted: DartedPattern, dpi: float = 100) -> plt.Figure:
    """The shear magnitude (degrees) on the mould without darts and with the darts open (an
    oblique view, the dart lines on the side seen in black) and on the flat pattern with its
    darts' lips, one colour scale from 0 to the larger of the largest shear and the locking
    angle; cells at or beyond the locking angle in red."""
    before, after = darted.before, darted.after
    top = max(darted.locking_angle, float(np.nanmax(np.abs(before.fields["shear_angle"]))))
    colours = _Colours(top, darted.locking_angle)
    count = 1 if after is None else 3
    fig = plt.figure(figsize=(4.4 * count + 0.8, 4.6), dpi=dpi)
    moulds = [(before, [], "without darts")]
    if after is not None:
        moulds.append((after, darted.dart_lines, "darts open"))
    for index, (result, lines, title) in enumerate(moulds, start=1):
        ax = fig.add_subplot(1, count, index, projection="3d", computed_zorder=False)
        _on_mould(ax, result.mesh, result.fields["shear_angle"], lines, title, colours)
    if after is not None:
        ax = fig.add_subplot(1, count, 3)
        pattern = (
            after.material_coordinates,
            after.mesh.cells["triangle"],
            after.fields["shear_angle"],
        )
        _flat(ax, [pattern], colours, "flat pattern with darts", darted.dart_pattern_lines())
    colours.bar(fig)
    return fig


def plot_splices(spliced: SplicedPly, dpi: float = 100) -> plt.Figure:
    """The shear magnitude (degrees) of the whole ply and of its pieces on the mould (the splice
    lines in black), and the flat pieces side by side (each turned so that its warp runs along
    x, a tenth of the widest apart), one colour scale as :func:`plot_darts`."""
    before = spliced.before
    top = max(spliced.locking_angle, float(np.nanmax(np.abs(before.fields["shear_angle"]))))
    colours = _Colours(top, spliced.locking_angle)
    fig = plt.figure(figsize=(14.0, 4.6), dpi=dpi)
    ax = fig.add_subplot(1, 3, 1, projection="3d", computed_zorder=False)
    _on_mould(ax, before.mesh, before.fields["shear_angle"], [], "the whole ply", colours)
    ax = fig.add_subplot(1, 3, 2, projection="3d", computed_zorder=False)
    title = f"spliced: {len(spliced.pieces)} pieces"
    shear = spliced.cell_field("shear_angle")
    _on_mould(ax, spliced.cut.mesh, shear, spliced.splice_lines, title, colours)
    flats, offset = [], 0.0
    widths = [np.ptp(r.material_coordinates[:, 0]) for r in spliced.results]
    for result in spliced.results:
        X = result.material_coordinates
        if result.fibres is not None:
            warp = np.asarray(result.fibres.warp, dtype=float)
            turn = np.array([[warp[0], warp[1]], [-warp[1], warp[0]]]) / np.linalg.norm(warp)
            X = X @ turn.T
        X = X - X.min(axis=0) + np.array([offset, 0.0])
        offset = X[:, 0].max() + 0.1 * max(widths)
        flats.append((X, result.mesh.cells["triangle"], result.fields["shear_angle"]))
    _flat(fig.add_subplot(1, 3, 3), flats, colours, "flat pieces (warp along x)")
    colours.bar(fig)
    return fig
