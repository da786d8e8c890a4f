"""Parametrised example surfaces.

``cylinder160``
    The seed paper's benchmark: a 160° segment of a circular cylinder. It is developable, so its
    optimal pattern is a rectangle as wide as the discrete arc length (the sum of the chords),
    erected with zero energy.
``hypar``
    A hyperbolic paraboloid ``z = c x y`` over a square: doubly curved (anticlastic), the shape
    of a four-point sail.
``sail``, ``tent``
    A four-point sail (a hypar with two high and two low corners) and one panel of a conic tent
    pulled up to a central ring: the prestressed membranes of the compensation examples.
``saddle``, ``conic-tent``
    Whole membranes to cut into strips of roll width: a four-point sail over a 20 m square, and
    a conic tent all round its high ring.
``scan_like``, ``cad_roof_mm``
    Surfaces as they come from outside (the real-world-like set): a scanned organic shell with
    rough random triangles and measurement noise, and a membrane roof exported from CAD in
    millimetres with long thin triangles.
``rib30``
    A generic 30° segment of a curved composite rib (seed §5.2): a hat-shaped cross-section
    (web, inclined walls, flanges, rounded corners) swept along a circular arc. The rounded
    corners become toroidal, doubly curved patches; the pattern of a fabric ply must stretch and
    shear there.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable

import numpy as np

from .mesh import SurfaceMesh, connected_pieces

__all__ = [
    "CUT_EXAMPLES",
    "EXAMPLES",
    "EXAMPLE_PLANES",
    "PANEL_NAMES",
    "STRUCTURE_EXAMPLES",
    "bumpy",
    "cad_roof_mm",
    "cap_over_square",
    "catenoid_band",
    "catenoid_section",
    "cone_segment",
    "conic_tent",
    "cylinder160",
    "cylinder_arc_length",
    "four_point_sail",
    "graded_hypar",
    "grid_cells",
    "hypar",
    "hypar_strips",
    "irregular_cap",
    "irregular_hypar_strips",
    "real_world_suite",
    "rib30",
    "robustness_suite",
    "ruffled_fan",
    "saddle",
    "scan_like",
    "spherical_cap",
    "tent_roof",
]


def grid_cells(n_u: int, n_v: int, cell_type: str = "triangle") -> dict[str, np.ndarray]:
    """Cells of a structured ``n_u × n_v`` grid of nodes ``j * n_u + i`` (i along u).

    Cells are counter-clockwise in the (u, v) parameter plane. Triangles alternate their diagonal
    so that the mesh has no preferred direction.
    """
    if n_u < 2 or n_v < 2:
        raise ValueError("a grid needs at least 2 × 2 nodes")
    i, j = np.meshgrid(np.arange(n_u - 1), np.arange(n_v - 1), indexing="xy")
    i, j = i.ravel(), j.ravel()
    p00, p10 = j * n_u + i, j * n_u + i + 1
    p01, p11 = (j + 1) * n_u + i, (j + 1) * n_u + i + 1
    if cell_type == "quad":
        return {"quad": np.column_stack([p00, p10, p11, p01])}
    if cell_type != "triangle":
        raise ValueError(f"cell_type must be 'triangle' or 'quad'; got {cell_type!r}")
    even = (i + j) % 2 == 0
    first = np.where(
        even[:, None], np.column_stack([p00, p10, p11]), np.column_stack([p00, p10, p01])
    )
    second = np.where(
        even[:, None], np.column_stack([p00, p11, p01]), np.column_stack([p10, p11, p01])
    )
    return {"triangle": np.vstack([first, second])}


def cylinder160(
    radius: float = 1.0,
    length: float = 2.0,
    angle: float = 160.0,
    n_around: int = 32,
    n_along: int = 16,
    cell_type: str = "triangle",
) -> SurfaceMesh:
    """Cylinder segment of ``angle`` degrees about the y-axis, symmetric about the z-axis.

    Nodes ``x = R sin θ``, ``y ∈ [0, length]``, ``z = R cos θ``, ``θ ∈ [−angle/2, angle/2]``, with
    ``n_around`` cells around and ``n_along`` along. Cells face outwards (+z at the crown), so
    the projection on the x-y plane is the seed's initial guess.
    """
    if not 0 < angle < 360:
        raise ValueError(f"angle must lie in (0, 360) degrees; got {angle}")
    theta = np.radians(np.linspace(-angle / 2, angle / 2, n_around + 1))
    y = np.linspace(0.0, length, n_along + 1)
    t, yy = np.meshgrid(theta, y, indexing="xy")
    points = np.column_stack([radius * np.sin(t.ravel()), yy.ravel(), radius * np.cos(t.ravel())])
    return SurfaceMesh(points, grid_cells(n_around + 1, n_along + 1, cell_type))


def cylinder_arc_length(radius: float = 1.0, angle: float = 160.0, n_around: int = 32) -> float:
    """Discrete arc length of :func:`cylinder160`: the sum of its chords around the axis."""
    return n_around * 2.0 * radius * np.sin(np.radians(angle) / (2 * n_around))


def hypar(
    size: float = 10.0,
    rise: float = 0.06,
    n: int = 20,
    cell_type: str = "triangle",
) -> SurfaceMesh:
    """Hyperbolic paraboloid ``z = rise · x · y`` over the square ``[−size/2, size/2]²``."""
    s = np.linspace(-size / 2, size / 2, n + 1)
    x, y = np.meshgrid(s, s, indexing="xy")
    points = np.column_stack([x.ravel(), y.ravel(), rise * x.ravel() * y.ravel()])
    return SurfaceMesh(points, grid_cells(n + 1, n + 1, cell_type))


def _filleted_profile(corners: np.ndarray, fillet: float, spacing: float, fillet_segments: int):
    """Sample a polyline whose interior corners are rounded with arcs of radius ``fillet``.

    Returns the points ``(k, 2)`` of the profile in order.
    """
    pieces: list[np.ndarray] = []
    start = corners[0]
    for b in range(1, len(corners) - 1):
        a, corner, c = corners[b - 1], corners[b], corners[b + 1]
        t1 = (corner - a) / np.linalg.norm(corner - a)
        t2 = (c - corner) / np.linalg.norm(c - corner)
        turn = np.arctan2(t1[0] * t2[1] - t1[1] * t2[0], t1 @ t2)
        tangent = fillet * np.tan(abs(turn) / 2)
        if tangent >= min(np.linalg.norm(corner - a), np.linalg.norm(c - corner)) / 2:
            raise ValueError("the fillet radius is too large for the profile")
        enter, leave = corner - tangent * t1, corner + tangent * t2
        pieces.append(_segment(start, enter, spacing)[:-1])
        side = np.sign(turn)
        centre = enter + fillet * side * np.array([-t1[1], t1[0]])
        phi0 = np.arctan2(*(enter - centre)[::-1])
        phis = phi0 + np.linspace(0.0, turn, fillet_segments + 1)
        pieces.append((centre + fillet * np.column_stack([np.cos(phis), np.sin(phis)]))[:-1])
        start = leave
    pieces.append(_segment(start, corners[-1], spacing))
    return np.vstack(pieces)


def _segment(a: np.ndarray, b: np.ndarray, spacing: float) -> np.ndarray:
    count = max(1, int(np.ceil(np.linalg.norm(b - a) / spacing)))
    return a + np.linspace(0.0, 1.0, count + 1)[:, None] * (b - a)


def rib30(
    radius: float = 1.0,
    angle: float = 30.0,
    width: float = 0.12,
    height: float = 0.05,
    flange: float = 0.04,
    wall_angle: float = 60.0,
    fillet: float = 0.015,
    spacing: float = 0.01,
    fillet_segments: int = 6,
    cell_type: str = "triangle",
) -> SurfaceMesh:
    """A hat-section rib segment swept by ``angle`` degrees about the z-axis.

    The cross-section (in the radial–vertical plane, centred on ``radius``) is a web of
    ``width`` at z = ``height``, two walls inclined at ``wall_angle`` degrees to the horizontal
    down to z = 0 and two flanges of ``flange`` outwards, every corner rounded with radius
    ``fillet``. The segment spans ``±angle/2`` about the x-axis, so the rib runs along +y at its
    middle. Units are the caller's (metres by default). ``spacing`` is the target cell size.
    """
    if not 0 < angle < 180:
        raise ValueError(f"angle must lie in (0, 180) degrees; got {angle}")
    if not 0 < wall_angle < 90:
        raise ValueError(f"wall_angle must lie in (0, 90) degrees; got {wall_angle}")
    run = height / np.tan(np.radians(wall_angle))
    half, bottom = width / 2, width / 2 + run
    corners = np.array(
        [
            [-bottom - flange, 0.0],
            [-bottom, 0.0],
            [-half, height],
            [half, height],
            [bottom, 0.0],
            [bottom + flange, 0.0],
        ]
    )
    profile = _filleted_profile(corners, fillet, spacing, fillet_segments)
    arc = np.radians(angle) * radius
    phi = np.radians(np.linspace(-angle / 2, angle / 2, max(2, int(np.ceil(arc / spacing))) + 1))
    r = radius + profile[:, 0]
    points = np.column_stack(
        [
            np.outer(np.cos(phi), r).ravel(),
            np.outer(np.sin(phi), r).ravel(),
            np.tile(profile[:, 1], len(phi)),
        ]
    )
    return SurfaceMesh(points, grid_cells(len(profile), len(phi), cell_type))


def four_point_sail(
    size: float = 10.0,
    height: float = 2.0,
    n: int = 24,
    cell_type: str = "triangle",
) -> SurfaceMesh:
    """A four-point sail: the hyperbolic paraboloid over a ``size`` × ``size`` square whose
    opposite corners are ``height`` apart (two high, two low), ``z = 2 height x y / size²``.
    """
    return hypar(size=size, rise=2.0 * height / size**2, n=n, cell_type=cell_type)


def conic_tent(
    outer_radius: float = 10.0,
    ring_radius: float = 1.5,
    height: float = 6.0,
    panels: int = 12,
    n_radial: int = 40,
    n_around: int = 16,
    cell_type: str = "triangle",
) -> SurfaceMesh:
    """One panel of a conic tent: a membrane pulled up to a central ring.

    The surface of revolution ``z = height · ln(R/ρ) / ln(R/r)`` (``R = outer_radius`` at
    ground level, ``r = ring_radius`` at the top) is the equilibrium shape of a radially
    tensioned tent; the panel spans ``360°/panels`` about the x-axis (``panels = 1``: the whole
    tent, a ring). Radial spacing is uniform in ``ln ρ``, so cells are finer at the ring.
    """
    if not 0 < ring_radius < outer_radius:
        raise ValueError("the ring radius must lie between 0 and the outer radius")
    if panels < 1:
        raise ValueError(f"panels must be a positive integer; got {panels}")
    rho = np.exp(np.linspace(np.log(ring_radius), np.log(outer_radius), n_radial + 1))
    z = height * np.log(outer_radius / rho) / np.log(outer_radius / ring_radius)
    whole = panels == 1
    span = 2 * np.pi / panels
    count = n_around * (4 if whole else 1)
    phi = np.linspace(-span / 2, span / 2, count + 1)[: -1 if whole else None]
    r, p = np.meshgrid(rho, phi, indexing="xy")
    points = np.column_stack(
        [(r * np.cos(p)).ravel(), (r * np.sin(p)).ravel(), np.tile(z, len(phi))]
    )
    n_u = len(rho)
    cells = grid_cells(n_u, len(phi) + (1 if whole else 0), cell_type)
    if whole:  # close the ring: the last row of nodes is the first
        cells = {t: np.where(c >= len(points), c - len(points), c) for t, c in cells.items()}
    return SurfaceMesh(points, cells)


def saddle(
    size: float = 20.0, height: float = 5.0, n: int = 40, cell_type: str = "triangle"
) -> SurfaceMesh:
    """The saddle of the cutting examples: a four-point sail over a ``size`` × ``size`` square
    (20 m) whose high and low corners are ``height`` apart (5 m), ``n`` × ``n`` cells."""
    return four_point_sail(size=size, height=height, n=n, cell_type=cell_type)


def tent_roof(
    outer_radius: float = 6.0,
    ring_radius: float = 1.0,
    height: float = 3.5,
    n_radial: int = 24,
    n_around: int = 32,
    cell_type: str = "triangle",
) -> SurfaceMesh:
    """The conic tent of the cutting examples: the whole membrane (all round) from the ground
    ring of ``outer_radius`` (6 m) up to the high ring of ``ring_radius`` (1 m) ``height`` (3.5 m)
    above it; ``4 n_around`` cells round, ``n_radial`` up (see :func:`conic_tent`)."""
    return conic_tent(outer_radius, ring_radius, height, 1, n_radial, n_around, cell_type=cell_type)


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


def hypar_strips(
    strips: int = 6,
    size: float = 10.0,
    height: float = 2.0,
    cells_per_strip: int = 4,
    n: int = 24,
    cell_type: str = "triangle",
) -> tuple[SurfaceMesh, np.ndarray]:
    """A four-point sail cut into ``strips`` strips across x (seams along y), as a membrane is
    welded from fabric of roll width: the mesh and the strip id of every cell."""
    columns = strips * cells_per_strip
    s_x = np.linspace(-size / 2, size / 2, columns + 1)
    s_y = np.linspace(-size / 2, size / 2, n + 1)
    x, y = (a.ravel() for a in np.meshgrid(s_x, s_y, indexing="xy"))
    z = 2.0 * height / size**2 * x * y
    mesh = SurfaceMesh(np.column_stack([x, y, z]), grid_cells(columns + 1, n + 1, cell_type))
    centroid_x = np.concatenate([mesh.points[c][:, :, 0].mean(axis=1) for c in mesh.cells.values()])
    ids = np.clip(((centroid_x + size / 2) / (size / strips)).astype(int), 0, strips - 1)
    return mesh, ids


def catenoid_band(
    panels: int = 12,
    waist: float = 3.0,
    height: float = 3.0,
    n_along: int = 16,
    n_around: int = 4,
    cell_type: str = "triangle",
) -> tuple[SurfaceMesh, np.ndarray]:
    """A whole catenoid band (a minimal surface between two rings: waist radius ``waist``,
    ``±height/2`` along z) cut along its meridians into ``panels`` gores of ``n_around`` cells
    around each: the mesh and the panel id of every cell. Erected, the rings are the supports.
    """
    if panels < 2:
        raise ValueError(f"a band needs at least two panels; got {panels}")
    v = np.linspace(-height / 2, height / 2, n_along + 1)
    count = panels * n_around
    phi = np.linspace(0.0, 2 * np.pi, count + 1)[:-1]
    r, p = np.meshgrid(waist * np.cosh(v / waist), phi, indexing="xy")
    points = np.column_stack([(r * np.cos(p)).ravel(), (r * np.sin(p)).ravel(), np.tile(v, count)])
    cells = grid_cells(len(v), count + 1, cell_type)
    cells = {t: np.where(c >= len(points), c - len(points), c) for t, c in cells.items()}
    mesh = SurfaceMesh(points, cells)
    centroids = np.concatenate([mesh.points[c].mean(axis=1) for c in mesh.cells.values()])
    angle = np.mod(np.arctan2(centroids[:, 1], centroids[:, 0]), 2 * np.pi)
    return mesh, np.minimum((angle / (2 * np.pi / panels)).astype(int), panels - 1)


def irregular_hypar_strips(
    strips: int = 10,
    size: float = 10.0,
    rise: float = 0.06,
    columns_per_strip: int = 4,
    n: int = 40,
    near: float = 0.02,
    seed: int = 0,
) -> tuple[SurfaceMesh, np.ndarray]:
    """A hypar ``z = rise x y`` over a square cut into ``strips`` strips along y, meshed
    irregularly, and the strip id of every cell.

    The seam lines x = const carry their nodes at random heights, a tenth of them ``near`` × the
    mean spacing above another one, as where a cutting line crosses the edges of a mesh close to
    a node (seams through cells); inside a strip the node columns have random spacing too.
    Neighbouring columns are joined by triangles that zip along both (every triangle
    counter-clockwise seen from +z).
    """
    rng = np.random.default_rng(seed)
    half = size / 2
    boundaries = np.linspace(-half, half, strips + 1)
    xs = [boundaries[0]]
    for a, b in itertools.pairwise(boundaries):
        inner = np.sort(rng.uniform(a, b, columns_per_strip - 1))
        xs += [*inner, b]
    columns = []
    for x in xs:
        heights = np.sort(rng.uniform(-half, half, n - 1))
        close = rng.choice(n - 2, size=max(1, n // 10), replace=False)
        heights[close + 1] = heights[close] + near * size / n
        columns.append((x, np.concatenate([[-half], np.sort(heights), [half]])))
    points, index = [], []
    for x, ys in columns:
        index.append(np.arange(len(points), len(points) + len(ys)))
        points += [(x, y, rise * x * y) for y in ys]
    triangles, ids = [], []
    for k in range(len(columns) - 1):
        for triangle in _zip_columns(index[k], columns[k][1], index[k + 1], columns[k + 1][1]):
            triangles.append(triangle)
            ids.append(k // columns_per_strip)
    mesh = SurfaceMesh(np.array(points), {"triangle": np.array(triangles)})
    return mesh, np.array(ids)


def _zip_columns(left, left_y, right, right_y) -> list[tuple[int, int, int]]:
    """Triangles between two node columns (left of right), each column sorted by height."""
    out, i, j = [], 0, 0
    while i < len(left) - 1 or j < len(right) - 1:
        up_left = j == len(right) - 1 or (i < len(left) - 1 and left_y[i + 1] < right_y[j + 1])
        if up_left:
            out.append((left[i], right[j], left[i + 1]))
            i += 1
        else:
            out.append((left[i], right[j], right[j + 1]))
            j += 1
    return out


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


#: Example generators by name (used by ``vares example``).
EXAMPLES: dict[str, Callable[..., SurfaceMesh]] = {
    "cylinder160": cylinder160,
    "hypar": hypar,
    "rib30": rib30,
    "sail": four_point_sail,
    "tent": conic_tent,
}
#: Whole surfaces to cut into strips of roll width (``vares cut --example``).
CUT_EXAMPLES: dict[str, Callable[..., SurfaceMesh]] = {"saddle": saddle, "conic-tent": tent_roof}
#: Example structures by name: generators of a mesh and a panel id per cell (``vares panels``).
STRUCTURE_EXAMPLES: dict[str, Callable[..., tuple[SurfaceMesh, np.ndarray]]] = {
    "hypar-strips": hypar_strips,
    "catenoid-band": catenoid_band,
}
#: What the panels of each example structure are called (name-1, name-2, …).
PANEL_NAMES = {"hypar-strips": "strip", "catenoid-band": "gore"}
#: The initial-guess plane each example is meant to be patterned with.
EXAMPLE_PLANES = {"cylinder160": "xy"}
