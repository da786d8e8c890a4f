"""The hard and awkward surfaces every strategy change is checked on, and surfaces as they
come from outside.

Caps of a sphere (regular and irregular, shallow to deep), a cap over a square, segments of a
cone and a catenoid, random bumps, graded cells and slivers, a fan whose development laps over
itself; a scanned organic shell with rough random triangles and measurement noise and a
membrane roof exported from CAD in millimetres with long thin triangles (the real-world-like
set). :func:`robustness_suite` and :func:`real_world_suite` name the shipped sets.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .example_surfaces import cylinder160, grid_cells, hypar, rib30
from .mesh import SurfaceMesh, connected_pieces

__all__ = [
    "bumpy",
    "cad_roof_mm",
    "cap_over_square",
    "catenoid_section",
    "cone_segment",
    "graded_hypar",
    "irregular_cap",
    "real_world_suite",
    "robustness_suite",
    "ruffled_fan",
    "scan_like",
    "spherical_cap",
    "square_cup",
]


def spherical_cap(
    radius: float = 12.0,
    half_angle: float = 60.0,
    n_rings: int = 12,
    cell_type: str = "triangle",
) -> SurfaceMesh:
    """Spherical cap of ``half_angle`` degrees about the +z pole (90: a hemisphere, more: a
    deep cap that turns by more than 180°), triangulated from rings of equal arc spacing.
    """
    if cell_type != "triangle":
        raise ValueError("spherical_cap makes triangles only")
    from scipy.spatial import Delaunay

    if not 0 < half_angle < 180:
        raise ValueError(f"half_angle must lie in (0, 180) degrees; got {half_angle}")
    polar = [np.zeros((1, 2))]
    for ring in range(1, n_rings + 1):
        count = 6 * ring
        phi = 2 * np.pi * (np.arange(count) + 0.5 * (ring % 2)) / count
        polar.append(np.column_stack([np.full(count, ring / n_rings), phi]))
    polar = np.vstack(polar)
    theta = np.radians(half_angle) * polar[:, 0]
    plane = np.column_stack([theta * np.cos(polar[:, 1]), theta * np.sin(polar[:, 1])])
    triangles = Delaunay(plane).simplices
    points = np.column_stack(
        [
            radius * np.sin(theta) * np.cos(polar[:, 1]),
            radius * np.sin(theta) * np.sin(polar[:, 1]),
            radius * np.cos(theta),
        ]
    )
    return SurfaceMesh(points, {"triangle": _counter_clockwise(plane, triangles)})


def irregular_cap(
    radius: float = 100.0,
    half_angle: float = 90.0,
    n_rings: int = 40,
    jitter: float = 0.3,
    seed: int = 0,
) -> SurfaceMesh:
    """:func:`spherical_cap` with irregular triangles: every node but the pole and the edge ring
    moved at random along the sphere by up to ``jitter`` ring spacings in each of the polar and
    the azimuthal direction (reproducible by ``seed``), then triangulated anew (Delaunay in the
    azimuthal equidistant plane). The pole stays a node at ``(0, 0, radius)``."""
    from scipy.spatial import Delaunay

    if not 0 < half_angle < 180:
        raise ValueError(f"half_angle must lie in (0, 180) degrees; got {half_angle}")
    if not 0 <= jitter < 0.5:
        raise ValueError(f"jitter must lie in [0, 0.5) ring spacings; got {jitter}")
    rng = np.random.default_rng(seed)
    rings, phis = [np.zeros(1)], [np.zeros(1)]
    for ring in range(1, n_rings + 1):
        count = 6 * ring
        phi = 2 * np.pi * (np.arange(count) + 0.5 * (ring % 2)) / count
        level = np.full(count, float(ring))
        if ring < n_rings:
            level += jitter * rng.uniform(-1, 1, count)
            phi += jitter * rng.uniform(-1, 1, count) / ring
        rings.append(level / n_rings)
        phis.append(phi)
    theta = np.radians(half_angle) * np.concatenate(rings)
    phi = np.concatenate(phis)
    plane = np.column_stack([theta * np.cos(phi), theta * np.sin(phi)])
    triangles = Delaunay(plane).simplices
    points = radius * np.column_stack(
        [np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)]
    )
    return SurfaceMesh(points, {"triangle": _counter_clockwise(plane, triangles)})


def _counter_clockwise(plane: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    a, b, c = plane[triangles[:, 0]], plane[triangles[:, 1]], plane[triangles[:, 2]]
    cross = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
    return np.where(cross[:, None] > 0, triangles, triangles[:, [0, 2, 1]])


def cap_over_square(
    size: float = 10.0, radius: float = 12.0, n: int = 20, cell_type: str = "triangle"
) -> SurfaceMesh:
    """The spherical cap of ``radius`` over the square ``[−size/2, size/2]²`` (synclastic)."""
    s = np.linspace(-size / 2, size / 2, n + 1)
    x, y = np.meshgrid(s, s, indexing="xy")
    z = np.sqrt(radius**2 - x**2 - y**2)
    points = np.column_stack([x.ravel(), y.ravel(), z.ravel() - z.min()])
    return SurfaceMesh(points, grid_cells(n + 1, n + 1, cell_type))


def square_cup(
    cells: int = 60,
    half_width: float = 75.0,
    top: float = 31.0,
    foot: float = 45.0,
    depth: float = 25.0,
    roundness: float = 6.0,
    jitter: float = 0.3,
    seed: int = 1,
) -> SurfaceMesh:
    """A box-shaped mould (mm): a punch face of ``depth`` over the rounded square ``ρ ≤ top``,
    ``ρ = (|x|^p + |y|^p)^(1/p)`` with ``p = roundness`` (round corners), walls falling as a half
    cosine to the flange at ``ρ = foot``, the flange out to the square of ``half_width``. Nodes of
    a grid of ``cells`` × ``cells`` moved at random within the square by up to ``jitter`` cells
    (reproducible by ``seed``; those on the edge stay), triangulated by Delaunay in the plane.
    Draped with the yarns along x and y, its corners shear most at their concave foot, inside
    the ply (:func:`vares.analysis.dart_lines.fall_line_darts`)."""
    from scipy.spatial import Delaunay

    if not 0 < top < foot < half_width:
        raise ValueError(f"need 0 < top < foot < half_width; got {top}, {foot}, {half_width}")
    if not 0 <= jitter < 0.5:
        raise ValueError(f"jitter must lie in [0, 0.5) cells; got {jitter}")
    s = np.linspace(-half_width, half_width, cells + 1)
    x, y = (v.ravel() for v in np.meshgrid(s, s, indexing="ij"))
    inside = (np.abs(x) < half_width) & (np.abs(y) < half_width)
    shift = np.random.default_rng(seed).uniform(-jitter, jitter, (2, len(x))) * (s[1] - s[0])
    x, y = x + inside * shift[0], y + inside * shift[1]
    rho = (np.abs(x) ** roundness + np.abs(y) ** roundness) ** (1.0 / roundness)
    fall = np.clip((rho - top) / (foot - top), 0.0, 1.0)
    points = np.column_stack([x, y, 0.5 * depth * (1.0 + np.cos(np.pi * fall))])
    plane = points[:, :2]
    triangles = Delaunay(plane).simplices
    return SurfaceMesh(points, {"triangle": _counter_clockwise(plane, triangles)})


def _revolution(
    radius: np.ndarray, height: np.ndarray, angle: float, n_around: int, cell_type: str
) -> SurfaceMesh:
    """The profile ``(radius, height)`` swept by ``angle`` degrees (centred on +x) about z."""
    phi = np.radians(np.linspace(-angle / 2, angle / 2, n_around + 1))
    r, p = np.meshgrid(radius, phi, indexing="xy")
    z = np.tile(height, len(phi))
    points = np.column_stack([(r * np.cos(p)).ravel(), (r * np.sin(p)).ravel(), z])
    return SurfaceMesh(points, grid_cells(len(radius), len(phi), cell_type))


def cone_segment(
    apex_angle: float = 60.0,
    angle: float = 120.0,
    inner: float = 1.0,
    outer: float = 4.0,
    n_radial: int = 12,
    n_around: int = 24,
    cell_type: str = "triangle",
) -> SurfaceMesh:
    """Segment of a circular cone (developable): half opening ``apex_angle``/2, ``angle``
    degrees around, slant distances ``inner`` … ``outer`` from the apex."""
    half = np.radians(apex_angle) / 2
    s = np.linspace(inner, outer, n_radial + 1)
    return _revolution(s * np.sin(half), -s * np.cos(half), angle, n_around, cell_type)


def catenoid_section(
    waist: float = 2.0,
    height: float = 3.0,
    angle: float = 120.0,
    n_along: int = 16,
    n_around: int = 24,
    cell_type: str = "triangle",
) -> SurfaceMesh:
    """Section of a catenoid (a minimal surface: anticlastic, zero mean curvature) of waist
    radius ``waist``, ``±height/2`` along its axis (z), ``angle`` degrees around."""
    v = np.linspace(-height / 2, height / 2, n_along + 1)
    return _revolution(waist * np.cosh(v / waist), v, angle, n_around, cell_type)


def bumpy(
    size: float = 10.0,
    amplitude: float = 0.6,
    bumps: int = 12,
    n: int = 24,
    seed: int = 0,
    cell_type: str = "triangle",
) -> SurfaceMesh:
    """A square with ``bumps`` random Gaussian bumps and dents (reproducible by ``seed``)."""
    rng = np.random.default_rng(seed)
    s = np.linspace(-size / 2, size / 2, n + 1)
    x, y = (a.ravel() for a in np.meshgrid(s, s, indexing="xy"))
    centres = rng.uniform(-size / 2, size / 2, (bumps, 2))
    widths = rng.uniform(0.08, 0.2, bumps) * size
    heights = rng.uniform(-1.0, 1.0, bumps) * amplitude
    z = sum(
        h * np.exp(-((x - c[0]) ** 2 + (y - c[1]) ** 2) / (2 * w**2))
        for c, w, h in zip(centres, widths, heights, strict=True)
    )
    return SurfaceMesh(np.column_stack([x, y, z]), grid_cells(n + 1, n + 1, cell_type))


def graded_hypar(
    size: float = 10.0,
    rise: float = 0.06,
    n: int = 20,
    grading: float = 100.0,
    sliver: float = 0.0,
    cell_type: str = "triangle",
) -> SurfaceMesh:
    """A hypar meshed with cells whose size varies by ``grading`` from one side to the other;
    with ``sliver`` > 0 every other column of nodes is moved to within ``sliver`` × the local
    spacing of its neighbour, making cells of aspect ratio about 1/``sliver`` (slivers)."""
    ratio = grading ** (1.0 / (n - 1))
    steps = ratio ** np.arange(n)
    u = np.concatenate([[0.0], np.cumsum(steps)]) / steps.sum()
    if sliver > 0:
        du = np.diff(u)
        u[1:-1:2] = u[0:-2:2] + sliver * du[0:-1:2]
    s = size * (u - 0.5)
    t = np.linspace(-size / 2, size / 2, n + 1)
    x, y = (a.ravel() for a in np.meshgrid(s, t, indexing="xy"))
    return SurfaceMesh(np.column_stack([x, y, rise * x * y]), grid_cells(n + 1, n + 1, cell_type))


def ruffled_fan(
    turn: float = 0.97,
    waves: int = 5,
    amplitude: float = 0.45,
    n_radial: int = 6,
    n_around: int = 120,
) -> SurfaceMesh:
    """A fan between radii 0.3 and 1 that goes ``turn`` × 360° around its axis while its rim
    waves up and down (``z = amplitude · r · sin(waves ψ)``): a cone-like, developable surface
    whose angle around the apex is far more than 360°. Its development laps over itself: no
    pattern of it can be cut in one piece."""
    r = np.linspace(0.3, 1.0, n_radial)
    psi = np.linspace(0.0, 2.0 * np.pi * turn, n_around)
    radius, angle = (a.ravel() for a in np.meshgrid(r, psi, indexing="xy"))
    points = np.column_stack(
        [
            radius * np.cos(angle),
            radius * np.sin(angle),
            amplitude * radius * np.sin(waves * angle),
        ]
    )
    return SurfaceMesh(points, grid_cells(n_radial, n_around))


def robustness_suite(fine: bool = False) -> dict[str, Callable[[], SurfaceMesh]]:
    """The shipped set of hard and awkward surfaces every strategy change is checked on: steep
    and folding shapes, doubly curved ones of both signs, random bumps, graded cells and
    slivers. ``fine`` gives the meshes of ``benchmarks/robustness.py``, else smaller ones."""
    n, rings = (40, 20) if fine else (12, 8)
    return {
        "hypar z = 0.06 xy, 10 m": lambda: hypar(n=n),
        "spherical cap 60°": lambda: spherical_cap(half_angle=60.0, n_rings=rings),
        "hemisphere": lambda: spherical_cap(half_angle=90.0, n_rings=rings),
        "deep cap 120°": lambda: spherical_cap(half_angle=120.0, n_rings=rings),
        "cap R 12 m over 10 m square": lambda: cap_over_square(n=n),
        "cone segment 120°": lambda: cone_segment(
            n_radial=12 if fine else 6, n_around=24 if fine else 12
        ),
        "catenoid section": lambda: catenoid_section(
            n_along=16 if fine else 8, n_around=24 if fine else 12
        ),
        "bumpy random surface": lambda: bumpy(n=n if fine else 16),
        "graded mesh, sizes 1:100": lambda: graded_hypar(n=n),
        "slivers, aspect 1:100": lambda: graded_hypar(n=n, grading=1.0, sliver=0.01),
        "cylinder 220°": lambda: cylinder160(
            angle=220.0, n_around=44 if fine else 22, n_along=16 if fine else 4
        ),
        "steep saddle z = 2.5 xy": lambda: hypar(size=2.0, rise=2.5, n=20 if fine else 10),
        "rib30 (quads)": lambda: rib30(
            cell_type="quad", **({} if fine else {"spacing": 0.02, "fillet_segments": 3})
        ),
    }


def scan_like(
    triangles: int = 20_000,
    size: float = 6.0,
    noise: float = 0.002,
    seed: int = 0,
) -> SurfaceMesh:
    """A scanned organic shell: about ``triangles`` rough triangles on jittered points (sizes
    and angles vary as in a scan, slivers included) inside a wavy outline ``size`` across,
    a double-curved surface of bumps, a dome and a twist, with Gaussian measurement noise of
    standard deviation ``noise`` on every point (metres)."""
    from scipy.spatial import Delaunay

    rng = np.random.default_rng(seed)
    # a jittered grid: irregular triangles of every shape, slivers included, as a scanner's
    # meshing software leaves them, but no two points closer than a fifth of the spacing
    area = np.pi * 0.7 * (size / 2) ** 2 * 1.0126  # the wavy outline's area
    spacing = np.sqrt(4 * area / (np.sqrt(3) * triangles))  # equilateral triangles' side
    rows = np.arange(-size / 2, size / 2 + spacing, spacing * np.sqrt(3) / 2)
    columns = np.arange(-size / 2, size / 2 + spacing, spacing)
    gx, gy = np.meshgrid(columns, rows, indexing="xy")
    gx = gx + (np.arange(rows.size)[:, None] % 2) * spacing / 2
    points = np.column_stack([gx.ravel(), gy.ravel()])
    points += rng.uniform(-0.4, 0.4, points.shape) * spacing
    angle = np.arctan2(points[:, 1] / 0.7, points[:, 0])
    wavy = 1.0 + 0.12 * np.sin(3 * angle + 0.4) + 0.07 * np.cos(5 * angle)
    points = points[np.hypot(points[:, 0], points[:, 1] / 0.7) < wavy * size / 2 - spacing / 2]
    rim_points = int(2 * np.pi * 0.85 * size / 2 * 1.1 / spacing)
    rim = np.linspace(0.0, 2 * np.pi, rim_points, endpoint=False)
    rim_wavy = 1.0 + 0.12 * np.sin(3 * rim + 0.4) + 0.07 * np.cos(5 * rim)
    outline = np.column_stack([np.cos(rim), 0.7 * np.sin(rim)]) * rim_wavy[:, None] * (size / 2)
    plane = np.vstack([points, outline])
    triangles_ = Delaunay(plane).simplices
    # keep the wavy outline (Delaunay fills its convex hull): drop triangles across the bays
    centroid = plane[triangles_].mean(axis=1)
    theta = np.arctan2(centroid[:, 1] / 0.7, centroid[:, 0])
    reach = (1.0 + 0.12 * np.sin(3 * theta + 0.4) + 0.07 * np.cos(5 * theta)) * (size / 2)
    inside = np.hypot(centroid[:, 0], centroid[:, 1] / 0.7) < reach * 0.995
    triangles_ = triangles_[inside]
    x, y = plane[:, 0] / size, plane[:, 1] / size
    z = size * (
        0.12 * (1.0 - 2.0 * (x**2 + y**2))
        + 0.05 * x * y * 8.0
        + 0.03 * np.exp(-((x - 0.2) ** 2 + (y + 0.1) ** 2) / 0.01)
        - 0.025 * np.exp(-((x + 0.25) ** 2 + (y - 0.15) ** 2) / 0.006)
    )
    points3 = np.column_stack([plane, z]) + rng.normal(0.0, noise, (plane.shape[0], 3))
    # one piece (a triangle at the rim may hang on by a corner) and no points left outside
    triangles_ = triangles_[connected_pieces(points3, {"triangle": triangles_}) == 0]
    used, cells = np.unique(triangles_, return_inverse=True)
    return SurfaceMesh(points3[used], {"triangle": cells.reshape(-1, 3)})


def cad_roof_mm(span: float = 12_000.0, depth: float = 8_000.0, n: int = 48) -> SurfaceMesh:
    """A membrane roof as a CAD program exports it, in millimetres: a saddle over
    ``span`` × ``depth`` mm with two high corners 1.8 m up, meshed in long strips (cells 8:1 to
    40:1 long against wide, every diagonal the same way) graded towards the edges."""
    u = np.linspace(-1.0, 1.0, n + 1)
    v = np.sin(np.linspace(-np.pi / 2, np.pi / 2, max(4, n // 6) + 1))
    x, y = np.meshgrid(u * span / 2, v * depth / 2, indexing="xy")
    z = 1_800.0 * (x / (span / 2)) * (y / (depth / 2)) + 600.0 * (1 - (x / (span / 2)) ** 2)
    points = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    return SurfaceMesh(points, grid_cells(n + 1, v.size, "triangle"))


def real_world_suite(large: bool = False) -> dict[str, tuple[Callable[[], SurfaceMesh], str]]:
    """Surfaces as they come from outside, each with the units of its coordinates: a scan, a
    coarse scan, a CAD roof in millimetres and, with ``large``, a 300k-triangle scan."""
    suite = {
        "scan, 20k rough triangles, 2 mm noise": (lambda: scan_like(20_000), "m"),
        "scan, 3k triangles, 5 mm noise": (lambda: scan_like(3_000, noise=0.005, seed=1), "m"),
        "CAD roof in mm, strips 40:1": (lambda: cad_roof_mm(), "mm"),
    }
    if large:
        suite["scan, 300k triangles, 0.5 mm noise"] = (
            lambda: scan_like(300_000, noise=0.0005, seed=2),
            "m",
        )
    return suite
