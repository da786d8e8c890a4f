"""Pictures of a ply's darts: the shear on the mould before and after the darts were opened,
with the dart lines, and the flat pattern with its darts (:mod:`vares.analysis.darts`)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ..analysis.darts import DartedPattern
from ..geometry.face_walk import node_normals

__all__ = ["plot_darts"]


def plot_darts(darted: DartedPattern, dpi: float = 100) -> plt.Figure:
    """The shear magnitude (degrees) on the mould without darts and with the darts open (an
    oblique view, the dart lines on the side seen in black) and on the flat pattern with its
    darts' lips, one colour scale from 0 to the larger of the largest shear and the locking
    angle; cells at or beyond the locking angle in red."""
    from matplotlib.colors import Normalize
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    before, after = darted.before, darted.after
    top = max(darted.locking_angle, float(np.nanmax(np.abs(before.fields["shear_angle"]))))
    colours = plt.get_cmap("viridis")
    norm = Normalize(0.0, top)

    def faces(shear: np.ndarray) -> np.ndarray:
        magnitude = np.abs(np.nan_to_num(shear))
        rgba = colours(norm(magnitude))
        rgba[magnitude >= darted.locking_angle] = (0.85, 0.1, 0.1, 1.0)
        return rgba

    count = 1 if after is None else 3
    fig = plt.figure(figsize=(4.4 * count + 0.8, 4.6), dpi=dpi)
    moulds = [(before, [], "without darts")]
    if after is not None:
        moulds.append((after, darted.dart_lines, "darts open"))
    for index, (result, lines, title) in enumerate(moulds, start=1):
        ax = fig.add_subplot(1, count, index, projection="3d", computed_zorder=False)
        mesh = result.mesh
        corners = mesh.points[mesh.cells["triangle"]]
        ax.add_collection3d(
            Poly3DCollection(
                corners,
                facecolors=faces(result.fields["shear_angle"]),
                edgecolors=faces(result.fields["shear_angle"]),
                linewidths=0.2,
                zorder=1,
            )
        )
        size = float(np.linalg.norm(np.ptp(mesh.points, axis=0)))
        elevation, azimuth = np.radians(25.0), np.radians(-60.0)
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
        ax.view_init(elev=np.degrees(elevation), azim=np.degrees(azimuth))
        largest = float(np.nanmax(np.abs(result.fields["shear_angle"])))
        ax.set_title(f"{title}\nlargest shear {largest:.1f}°", fontsize=10)
        ax.set_axis_off()
    if after is not None:
        ax = fig.add_subplot(1, count, 3)
        flat = after.material_coordinates
        corners = flat[after.mesh.cells["triangle"]]
        from matplotlib.collections import PolyCollection

        ax.add_collection(
            PolyCollection(
                corners,
                facecolors=faces(after.fields["shear_angle"]),
                edgecolors="face",
                linewidths=0.2,
            )
        )
        for lips in darted.dart_pattern_lines():
            ax.plot(lips[:, 0], lips[:, 1], "k-", linewidth=1.2)
        ax.autoscale_view()
        ax.set_aspect("equal")
        ax.set_axis_off()
        ax.set_title("flat pattern with darts", fontsize=10)
    mappable = plt.cm.ScalarMappable(norm=norm, cmap=colours)
    fig.colorbar(
        mappable, ax=fig.axes, shrink=0.7, label="shear angle [°] (red: at the locking angle)"
    )
    return fig
