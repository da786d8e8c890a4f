"""The start of a forward drape: the blank laid on the mould by the kinematic net.

Every blank node goes to the net position of its material point (the blank's coordinates from
its seed node, read on the net's grid of yarn spacing ``s``: bilinear in the net's cells). The
nodes the net does not reach (beyond a cell sheared to 90°, or beyond the mould's flange) are
placed ring by ring outward from those it does: each from the linear map that fits its placed
neighbours within :data:`FIT_RADIUS` spacings (least squares), then put onto the mould. Cells
that still face away from the mould are smoothed (their extrapolated nodes moved to the mean of
their neighbours and put back onto the mould) for up to :data:`SMOOTHING_SWEEPS` sweeps.
"""

from __future__ import annotations

import numpy as np

from ..geometry.blank import Blank
from ..geometry.drape_net import KinematicNet
from ..geometry.mould import Mould
from ..mechanics.contact import turned_over

__all__ = ["kinematic_start"]

#: The placed neighbours an extrapolated node is fitted to lie within this many spacings.
FIT_RADIUS = 2.5
#: Sweeps of smoothing at most before a start with turned cells is refused.
SMOOTHING_SWEEPS = 200


def kinematic_start(
    mould: Mould, blank: Blank, net: KinematicNet
) -> tuple[np.ndarray, np.ndarray, dict[int, tuple[np.ndarray, float]]]:
    """The blank's start positions ``(n, 3)`` on ``mould`` from ``net`` (module docs), the held
    nodes ``(n,)`` (the seed node) and the guided node: the blank node next to the seed along the
    warp, kept in the plane of the warp and the normal at the seed (its unit normal and
    offset)."""
    X = blank.coordinates - blank.coordinates[blank.seed]
    start, reached = _on_net(net, X)
    if not reached[blank.seed]:
        raise ValueError("the kinematic net does not reach the blank's seed")
    extrapolated = ~reached
    _extrapolate(mould, blank, X, start, reached)
    _, _, start = mould.project(start)
    start[blank.seed] = net.positions[net.seed]
    _untangle(mould, blank, start, extrapolated)
    held = np.zeros(len(X), dtype=bool)
    held[blank.seed] = True
    normal = _warp_plane(net)
    return start, held, {_warp_node(blank, X): (normal, float(start[blank.seed] @ normal))}


def _on_net(net: KinematicNet, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bilinear positions ``(n, 3)`` of the material points ``X`` on the net, and ``(n,)`` where
    the net's cell has all four nodes."""
    nu, nv = net.faces.shape
    index = np.array(net.seed) + X / net.spacing
    low = np.clip(np.floor(index).astype(int), 0, [nu - 2, nv - 2])
    t = index - low
    inside = (t >= -1e-9).all(axis=1) & (t <= 1 + 1e-9).all(axis=1)
    t = np.clip(t, 0.0, 1.0)
    i, j = low[:, 0], low[:, 1]
    p = net.positions
    corners = [p[i, j], p[i + 1, j], p[i, j + 1], p[i + 1, j + 1]]
    weights = [(1 - t[:, 0]) * (1 - t[:, 1]), t[:, 0] * (1 - t[:, 1]),
               (1 - t[:, 0]) * t[:, 1], t[:, 0] * t[:, 1]]  # fmt: skip
    out = sum(w[:, None] * c for w, c in zip(weights, corners, strict=True))
    reached = inside & np.isfinite(out).all(axis=1)
    out[~reached] = np.nan
    return out, reached


def _neighbours(blank: Blank) -> list[np.ndarray]:
    tri = blank.triangles
    pairs = np.vstack([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    pairs = np.unique(np.sort(np.vstack([pairs, pairs[:, ::-1]]), axis=1), axis=0)
    pairs = np.vstack([pairs, pairs[:, ::-1]])
    order = np.argsort(pairs[:, 0], kind="stable")
    pairs = pairs[order]
    split = np.searchsorted(pairs[:, 0], np.arange(len(blank.coordinates) + 1))
    return [pairs[split[a] : split[a + 1], 1] for a in range(len(blank.coordinates))]


def _extrapolate(mould: Mould, blank: Blank, X, start, reached) -> None:
    """Place the nodes not reached ring by ring (module docs), in place."""
    from scipy.spatial import cKDTree

    if reached.all():
        return
    neighbours = _neighbours(blank)
    radius = FIT_RADIUS * blank.spacing
    while not reached.all():
        ring = [a for a in np.flatnonzero(~reached) if reached[neighbours[a]].any()]
        if not ring:
            raise ValueError("the blank is in pieces: some of it is not joined to its seed")
        placed = np.flatnonzero(reached)
        tree = cKDTree(X[placed])
        for a in ring:
            near = placed[tree.query_ball_point(X[a], radius)]
            base = near[np.argmin(np.linalg.norm(X[near] - X[a], axis=1))]
            dX, dx = X[near] - X[base], start[near] - start[base]
            if np.linalg.matrix_rank(dX, tol=1e-6 * blank.spacing) < 2:
                start[a] = start[base] + np.pad(X[a] - X[base], (0, 1))
                continue
            J, *_ = np.linalg.lstsq(dX, dx, rcond=None)  # (2, 3)
            start[a] = start[base] + (X[a] - X[base]) @ J
        _, _, start[ring] = mould.project(start[ring])
        reached[ring] = True


def _untangle(mould: Mould, blank: Blank, start, movable) -> None:
    """Smooth the extrapolated nodes of cells that face away from the mould (module docs)."""
    neighbours = None
    for _ in range(SMOOTHING_SWEEPS):
        faces, _, _ = mould.project(start)
        bad = turned_over(start, faces, blank.triangles, mould.normals)
        if not bad.size:
            return
        if neighbours is None:
            neighbours = _neighbours(blank)
        nodes = np.unique(blank.triangles[bad])
        nodes = nodes[movable[nodes]]
        if not nodes.size:
            break
        mean = np.array([start[neighbours[a]].mean(axis=0) for a in nodes])
        _, _, start[nodes] = mould.project(mean)
    raise ValueError(
        f"the kinematic start turns {bad.size} cell(s) of the blank over on the mould "
        "(a smaller blank, or a finer one)"
    )


def _warp_node(blank: Blank, X: np.ndarray) -> int:
    """The blank node nearest to one spacing along +warp from the seed."""
    target = np.array([blank.spacing, 0.0])
    return int(np.argmin(np.linalg.norm(X - target, axis=1)))


def _warp_plane(net: KinematicNet) -> np.ndarray:
    """Unit normal of the plane of the warp and the normal at the seed: the fill there, made
    orthogonal to the warp."""
    si, sj = net.seed
    p = net.positions
    warp = p[si + 1, sj] - p[si, sj]
    fill = p[si, sj + 1] - p[si, sj]
    warp /= np.linalg.norm(warp)
    fill = fill - (fill @ warp) * warp
    return fill / np.linalg.norm(fill)
