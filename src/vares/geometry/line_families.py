"""Families of cutting lines: one line for every value of a parameter across the strips.

``parallel``
    Planes that contain a strip direction ``d`` and the normal of the surface's best-fit plane,
    at the distance ``s`` across: strips along ``d``, side by side (the layout of a saddle or a
    barrel vault).
``radial``
    Half-planes through the vertical axis of the surface's high point, at the angle ``s``: strips
    that run down from the high point (the layout of a conic tent). A surface all round the axis
    (a ring) gives a closed family.

A family gives the plane section for any parameter (:meth:`LineFamily.sections`); the geodesic
cutting line of the same parameter is the geodesic between that section's end points on the
boundary (:func:`geodesic_between_ends`). Lines are oriented alike: from the low end of the
along-coordinate (the high point, for radial lines) to the high end.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .cutting import cut_mesh
from .flatten import projection_plane
from .mesh import SurfaceMesh
from .surface_lines import CuttingError, SurfaceLine, geodesic_lines, plane_sections

__all__ = ["LAYOUTS", "LineFamily", "geodesic_between_ends", "line_family"]

LAYOUTS = ("auto", "parallel", "radial")


@dataclass(frozen=True)
class LineFamily:
    """Cutting lines by a parameter (module docs).

    ``kind`` is ``"parallel"`` or ``"radial"``; ``normal`` the surface's best-fit normal;
    ``direction`` the strip direction (parallel) ; ``centre`` a point of the vertical axis
    (radial); ``span`` the parameter range covered by the surface, ``closed`` whether the family
    goes all round (a ring: the parameter is periodic with period ``span[1] − span[0]``).
    """

    kind: str
    normal: np.ndarray
    direction: np.ndarray
    centre: np.ndarray
    span: tuple[float, float]
    closed: bool = False

    @property
    def across(self) -> np.ndarray:
        """Normal of the planes of a parallel family."""
        across = np.cross(self.direction, self.normal)
        return across / np.linalg.norm(across)

    def parameter(self, points: np.ndarray) -> np.ndarray:
        """The family parameter of points ``(n, 3)`` (the line through them, roughly)."""
        if self.kind == "parallel":
            return points @ self.across
        angle = np.arctan2(points[:, 1] - self.centre[1], points[:, 0] - self.centre[0])
        return self.span[0] + np.mod(angle - self.span[0], 2 * np.pi)

    def along(self, points: np.ndarray) -> np.ndarray:
        """Coordinate along the strips (distance from the axis, for radial lines)."""
        if self.kind == "parallel":
            return points @ self.direction
        return np.hypot(points[:, 0] - self.centre[0], points[:, 1] - self.centre[1])

    def warp(self, points: np.ndarray) -> np.ndarray:
        """The direction along the strips at the centre of ``points`` ``(n, 3)``."""
        if self.kind == "parallel":
            return self.direction
        mean = points.mean(axis=0) - self.centre
        radial = np.array([mean[0], mean[1], 0.0])
        return radial / np.linalg.norm(radial)

    def sections(self, mesh: SurfaceMesh, s: float) -> list[SurfaceLine]:
        """The plane sections of parameter ``s``, oriented along the strips."""
        if self.kind == "parallel":
            lines = plane_sections(mesh, self.across, float(s))
        else:
            side = np.array([np.cos(s), np.sin(s), 0.0])
            normal = np.array([-np.sin(s), np.cos(s), 0.0])
            lines = [
                line
                for line in plane_sections(mesh, normal, float(normal @ self.centre))
                if np.mean((line.points - self.centre) @ side) > 0
            ]
        return [self._oriented(line) for line in lines]

    def _oriented(self, line: SurfaceLine) -> SurfaceLine:
        along = self.along(line.points[[0, -1]])
        return line if along[0] <= along[1] else line.reversed()


def line_family(
    mesh: SurfaceMesh, layout: str = "auto", direction: Sequence[float] | None = None
) -> LineFamily:
    """The family of cutting lines of a surface: ``parallel`` along ``direction`` (default:
    the best-fit plane's axis of largest extent), ``radial`` about the vertical axis through
    the high point, or ``auto``: radial when the surface's highest boundary is a hole (a tent's
    ring) or its highest point is inside, parallel otherwise."""
    if layout not in LAYOUTS:
        raise ValueError(f"layout must be one of {', '.join(LAYOUTS)}; got {layout!r}")
    plane = projection_plane(mesh)
    normal = plane.normal
    points = mesh.points
    if layout == "auto":
        layout = "radial" if _high_point(mesh)[1] else "parallel"
    if layout == "parallel":
        if direction is None:
            extent = np.ptp(plane.project(points), axis=0)
            axis = plane.axes[int(np.argmax(extent > 1.01 * extent[::-1]))]
        else:
            axis = np.asarray(direction, dtype=float)
        axis = axis - (axis @ normal) * normal
        if np.linalg.norm(axis) < 1e-9:
            raise CuttingError("the strip direction is normal to the surface")
        axis = axis / np.linalg.norm(axis)
        across = np.cross(axis, normal)
        s = points @ (across / np.linalg.norm(across))
        return LineFamily("parallel", normal, axis, plane.origin, (float(s.min()), float(s.max())))
    centre, _ = _high_point(mesh)
    angle = np.sort(np.arctan2(points[:, 1] - centre[1], points[:, 0] - centre[0]))
    gaps = np.diff(np.concatenate([angle, [angle[0] + 2 * np.pi]]))
    widest = int(np.argmax(gaps))
    closed = bool(gaps[widest] < np.pi / 8) or _goes_round(mesh, centre)
    if closed:
        start = float(angle[0])
        span = (start, start + 2 * np.pi)
    else:  # a sector: from after the widest gap round to before it
        start = float(angle[(widest + 1) % len(angle)])
        span = (start, start + 2 * np.pi - float(gaps[widest]))
    return LineFamily("radial", normal, np.array([0.0, 0.0, 1.0]), centre, span, closed)


def _goes_round(mesh: SurfaceMesh, centre: np.ndarray) -> bool:
    """Whether a boundary loop of ``mesh`` winds round the vertical axis through ``centre``
    (in plan): the surface then goes all round it, however few nodes it has round (a coarse
    design's ring of 16 facets leaves gaps of 22.5° between its nodes' azimuths)."""
    for loop in mesh.boundary_loops():
        xy = mesh.points[loop, :2] - centre[:2]
        radius = np.linalg.norm(xy, axis=1)
        if radius.min() <= 1e-9 * max(float(radius.max()), 1e-300):
            continue  # the axis passes through the loop: it winds round nothing
        turn = np.diff(np.arctan2(xy[:, 1], xy[:, 0]), append=np.arctan2(xy[0, 1], xy[0, 0]))
        if abs(float(np.sum((turn + np.pi) % (2 * np.pi) - np.pi))) > np.pi:
            return True
    return False


def _high_point(mesh: SurfaceMesh) -> tuple[np.ndarray, bool]:
    """A point of the vertical axis of radial strips, and whether the surface has a high point
    to run them from: a highest boundary loop that is a hole (its centroid), or a highest node
    inside the surface."""
    points = mesh.points
    loops = mesh.boundary_loops()
    if len(loops) > 1:
        top = max(loops, key=lambda loop: points[loop, 2].mean())
        return points[top].mean(axis=0), True
    highest = int(np.argmax(points[:, 2]))
    inside = highest not in set(loops[0].tolist())
    return points[highest], inside


def geodesic_between_ends(
    mesh: SurfaceMesh, sections: Sequence[SurfaceLine], snap: float
) -> tuple[SurfaceMesh, list[SurfaceLine]]:
    """The geodesics between the end points of ``sections`` (lines on ``mesh``): the end points
    become nodes of the returned mesh, on which the geodesics lie (an end point within ``snap`` ×
    the cell size of a boundary node is moved onto it)."""
    ends = [line for section in sections for line in _end_points(section)]
    inserted = cut_mesh(mesh, ends, snap, panels=False)
    nodes = [int(chain[0]) for chain in inserted.lines]
    pairs = list(zip(nodes[0::2], nodes[1::2], strict=True))
    for start, end in pairs:
        if start == end:
            raise CuttingError("a cutting line's two ends fall on the same node")
    return inserted.mesh, geodesic_lines(inserted.mesh, pairs)


def _end_points(line: SurfaceLine) -> list[SurfaceLine]:
    return [SurfaceLine(line.ends[[k]], line.fractions[[k]], line.points[[k]]) for k in (0, -1)]
