"""The named example surfaces (``vares example``, the cutting examples) and the structured grid
they are meshed on.

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
``rib30``
    A generic 30° segment of a curved composite rib (seed §5.2): a hat-shaped cross-section
    (web, inclined walls, flanges, rounded corners) swept along a circular arc. The rounded
    corners become toroidal, doubly curved patches; the pattern of a fabric ply must stretch and
    shear there.
"""

from __future__ import annotations

import numpy as np

from .mesh import SurfaceMesh

__all__ = [
    "conic_tent",
    "cylinder160",
    "cylinder_arc_length",
    "four_point_sail",
    "grid_cells",
    "hypar",
    "rib30",
    "saddle",
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
