"""A double-dome mould: two domes joined by a saddle, on a flat flange (``double-dome``).

The part is in the spirit of the woven-composites forming benchmark's double dome (two domes
side by side along x, a saddle between them, a flat flange all round), parametrised in mm. Its
dimensions are approximate and chosen for this example: they are **not** the benchmark's
drawing, and results on it are not results of the benchmark.

Shape. The height over the plan point ``(x, y)`` is ``height · g(d / radius)``, with ``d``
the smooth minimum ``−b ln(e^{−r₁/b} + e^{−r₂/b})`` (``b = blend``) of the plan distances
``r₁``, ``r₂`` to the domes' centres ``(±spacing/2, 0)`` and the profile ``g(s) = (1 − s²)³``
for ``s < 1`` (0 beyond): a rounded top, walls up to 56° steep, and a base that meets the
flange with zero slope and zero curvature. Where ``e^{−r₁/b}`` and ``e^{−r₂/b}`` are alike
(about ``x = 0``) the level lines of ``d`` bend: the saddle. The flange is the plane ``z = 0``
out to the ellipse of half-lengths ``spacing/2 + radius + flange`` and ``radius + flange``.
The part is symmetric about the planes ``x = 0`` and ``y = 0``. With the defaults (mm): domes
60 high whose centres are 110 apart, a saddle 10.3 high between them, a footprint of
250 × 140 and an outline of 310 × 200; the flange is 30 wide along the axes and 18.6 at its
narrowest (over the diagonals).

Mesh. Irregular triangles whose nodes are at least ``cell_size`` apart in 3D: the outline
sampled at ``cell_size``, then random plan points (reproducible by ``seed``) whose points on the
surface are kept when no kept point is nearer than ``cell_size`` (dart throwing), triangulated in
the plan (Delaunay). With the default 5 mm: 2,773 triangles, edges 4.8–14.9 mm (mean 7.3).
"""

from __future__ import annotations

import numpy as np

from .mesh import SurfaceMesh

__all__ = ["axis_splice", "double_dome", "double_dome_height", "side_darts"]


def double_dome_height(
    x: np.ndarray,
    y: np.ndarray,
    radius: float = 70.0,
    height: float = 60.0,
    spacing: float = 110.0,
    blend: float = 12.0,
) -> np.ndarray:
    """The mould's height ``z`` over plan points ``x``, ``y`` (same shape, mm; module docs)."""
    r1 = np.hypot(x - spacing / 2, y)
    r2 = np.hypot(x + spacing / 2, y)
    low = np.minimum(r1, r2)
    d = low - blend * np.log(np.exp(-(r1 - low) / blend) + np.exp(-(r2 - low) / blend))
    s = np.clip(d / radius, 0.0, 1.0)
    return height * (1.0 - s**2) ** 3


def double_dome(
    radius: float = 70.0,
    height: float = 60.0,
    spacing: float = 110.0,
    blend: float = 12.0,
    flange: float = 30.0,
    cell_size: float = 5.0,
    seed: int = 0,
    cell_type: str = "triangle",
) -> SurfaceMesh:
    """The double-dome mould (module docs), mm: domes of plan ``radius`` (to where they meet the
    flange) and ``height`` whose centres are ``spacing`` apart along x, joined by a saddle whose
    sharpness ``blend`` sets, on a ``flange`` (its width along the axes); irregular triangles
    whose nodes are at least ``cell_size`` apart (``seed``: the random points). Triangles
    only."""
    if cell_type != "triangle":
        raise ValueError("the double dome is meshed with irregular triangles only")
    for name, value in {"radius": radius, "height": height, "blend": blend}.items():
        if not value > 0:
            raise ValueError(f"{name} must be positive; got {value}")
    if not 0 <= spacing < 2 * radius:
        raise ValueError(f"spacing must lie in [0, 2 radius) for the domes to meet; got {spacing}")
    if not flange > 2 * cell_size:
        raise ValueError(f"the flange must be wider than two cells; got {flange}")
    if not 0 < cell_size < radius / 4:
        raise ValueError(f"cell_size must lie in (0, radius/4); got {cell_size}")
    a, b = spacing / 2 + radius + flange, radius + flange
    rng = np.random.default_rng(seed)
    # the outline: the ellipse sampled at about cell_size (by arc length)
    t = np.linspace(0.0, 2 * np.pi, 4096, endpoint=False)
    c, s = np.cos(t), np.sin(t)
    ring = np.column_stack([a * c, b * s])
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(ring, axis=0), axis=1))])
    total = arc[-1] + np.linalg.norm(ring[0] - ring[-1])
    count = int(np.ceil(total / cell_size))
    pick = np.searchsorted(arc, np.arange(count) * total / count)
    outline = ring[np.minimum(pick, len(ring) - 1)]
    # candidates on the surface, about as dense per 3D area everywhere: more in the plan where
    # the surface is steep
    kept = _thinned(outline, a, b, cell_size, rng, radius, height, spacing, blend)
    plane = np.vstack([outline, kept])
    from scipy.spatial import Delaunay

    triangles = Delaunay(plane).simplices
    corners = plane[triangles]
    cross = (corners[:, 1, 0] - corners[:, 0, 0]) * (corners[:, 2, 1] - corners[:, 0, 1]) - (
        corners[:, 1, 1] - corners[:, 0, 1]
    ) * (corners[:, 2, 0] - corners[:, 0, 0])
    triangles = np.where(cross[:, None] > 0, triangles, triangles[:, [0, 2, 1]])
    z = double_dome_height(plane[:, 0], plane[:, 1], radius, height, spacing, blend)
    return SurfaceMesh(np.column_stack([plane, z]), {"triangle": triangles})


def _thinned(outline, a, b, cell_size, rng, radius, height, spacing, blend) -> np.ndarray:
    """Random plan points inside the outline whose surface points are at least ``cell_size``
    apart in 3D and from the outline (dart throwing on a hash grid of ``cell_size`` cells)."""
    area = np.pi * a * b * 1.2  # generous: steep walls hold more surface than their plan
    tries = int(12 * area / cell_size**2)
    xy = np.column_stack([rng.uniform(-a, a, tries), rng.uniform(-b, b, tries)])
    margin = 0.5 * cell_size
    inside = (xy[:, 0] / (a - margin)) ** 2 + (xy[:, 1] / (b - margin)) ** 2 < 1
    xy = xy[inside]
    z = double_dome_height(xy[:, 0], xy[:, 1], radius, height, spacing, blend)
    candidates = np.column_stack([xy, z])
    grid: dict[tuple[int, int, int], list[tuple[float, float, float]]] = {}
    size = float(cell_size)
    for x, y in outline.tolist():
        grid.setdefault((int(x // size), int(y // size), 0), []).append((x, y, 0.0))
    kept = []
    limit = size**2
    offsets = [(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)]
    for x, y, z in candidates.tolist():
        i, j, k = int(x // size), int(y // size), int(z // size)
        near = any(
            (x - qx) ** 2 + (y - qy) ** 2 + (z - qz) ** 2 < limit
            for di, dj, dk in offsets
            for qx, qy, qz in grid.get((i + di, j + dj, k + dk), ())
        )
        if not near:
            grid.setdefault((i, j, k), []).append((x, y, z))
            kept.append((x, y))
    return np.array(kept)


def side_darts(
    xs, depth: float, radius: float = 70.0, spacing: float = 110.0, flange: float = 30.0
) -> list[np.ndarray]:
    """Dart lines on the default double dome's surface from its long sides: at every ``x`` of
    ``xs`` and its mirror image ``−x``, from the outline (of ``double_dome(radius, spacing=…,
    flange=…)``) along ∓y, across the warp along x, ``depth`` mm into the plan; 300 points
    each, those strictly inside the outline. Four lines for one ``x`` (mm)."""
    a, b = spacing / 2 + radius + flange, radius + flange
    lines = []
    for x in sorted({float(v) for v in xs} | {-float(v) for v in xs}):
        if not abs(x) < a:
            raise ValueError(f"a side dart's x must lie within ±{a:g}; got {x:g}")
        for sign in (1.0, -1.0):
            y = sign * b * np.sqrt(1.0 - (x / a) ** 2) - sign * np.linspace(0.0, depth, 300)
            y = y[(x / a) ** 2 + (y / b) ** 2 < 0.999]
            xs_ = np.full(len(y), x)
            height = double_dome_height(xs_, y, radius=radius, spacing=spacing)
            lines.append(np.column_stack([xs_, y, height]))
    return lines


def axis_splice(
    along: str = "x", radius: float = 70.0, spacing: float = 110.0, flange: float = 30.0
) -> np.ndarray:
    """A splice line on the default double dome's surface along one of its planes of symmetry,
    from the outline to the outline (of ``double_dome(radius, spacing=…, flange=…)``): ``"x"``
    the long axis (y = 0, through both domes), ``"y"`` the short one (x = 0, across the saddle);
    ``(400, 3)``, the ends within 0.1 mm inside the outline (mm)."""
    if along not in ("x", "y"):
        raise ValueError(f"a splice runs along 'x' or 'y'; got {along!r}")
    half = spacing / 2 + radius + flange if along == "x" else radius + flange
    t = np.linspace(-(half - 0.1), half - 0.1, 400)
    x, y = (t, np.zeros_like(t)) if along == "x" else (np.zeros_like(t), t)
    return np.column_stack([x, y, double_dome_height(x, y, radius=radius, spacing=spacing)])
