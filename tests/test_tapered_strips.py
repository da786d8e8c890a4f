"""Tapered strips in pairs on the roll (the width two strips need head to tail, the warp along
one seam) and nests that are the same for the same input."""

import itertools

import numpy as np
import pytest
from shapely.geometry import Polygon

import vares
from vares.geometry.cross_cut import cut_across
from vares.geometry.examples import cylinder160, saddle, tent_roof
from vares.geometry.flatten import lscm
from vares.geometry.surface_lines import CuttingError, SurfaceLine, geodesic_lines, triangulated
from vares.structures import find_seams, nesting, split_panels
from vares.structures.cutting import cut
from vares.structures.layout import plan_strips
from vares.structures.nesting import nest_pieces
from vares.structures.pair_nest import pair_nest
from vares.structures.pairing import SAVING, choose_plan
from vares.structures.widths import envelopes, pair_width, pattern_direction, roll_estimate

FABRIC = vares.materials.fabric("pes-pvc-type-2").material()


def turned(points: np.ndarray, degrees: float) -> np.ndarray:
    a = np.radians(degrees)
    return points @ np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]])


def trapezoid(length: float, wide: float, narrow: float, offset: float) -> np.ndarray:
    """Counter-clockwise: the wide end at x = 0 from y = 0 up, the narrow end at x = length
    from y = offset up."""
    return np.array([[0.0, 0.0], [length, offset], [length, offset + narrow], [0.0, wide]])


def test_pair_width_of_rectangles_and_trapezoids():
    """A rectangle needs twice its width; a trapezoid with one edge along the warp its two
    ends' widths added (the pair closes up); a symmetric one (3 W + w) / 2 (the turned copy
    rests on the sloping edge); any of them turned with its warp measures the same."""
    rectangle = trapezoid(5.0, 1.2, 1.2, 0.0)
    assert pair_width(rectangle) == pytest.approx(2.4, rel=1e-12)
    straight = trapezoid(6.0, 2.4, 0.5, 0.0)
    assert pair_width(straight) == pytest.approx(2.9, rel=1e-12)
    symmetric = trapezoid(6.0, 2.4, 0.5, 0.95)
    assert pair_width(symmetric) == pytest.approx((3 * 2.4 + 0.5) / 2, rel=1e-12)
    assert pair_width(symmetric, straight=True) == pytest.approx(2.9, rel=1e-12)
    for shape in (rectangle, straight, symmetric):
        warp = turned(np.array([[1.0, 0.0]]), 37.0)[0]
        assert pair_width(turned(shape, 37.0) + np.array([3.0, -2.0]), warp) == pytest.approx(
            pair_width(shape), rel=1e-9
        )
    s, upper, lower = envelopes(straight)
    assert np.allclose(lower, 0.0, atol=1e-12)
    assert np.allclose(upper, 2.4 + (0.5 - 2.4) * s / 6.0, atol=1e-12)


def test_roll_estimate_lays_pieces_in_turn_or_in_pairs():
    assert roll_estimate([3.0, 5.0, 4.0], 1) == pytest.approx(12.0)
    assert roll_estimate([3.0, 5.0, 4.0, 6.0], 2) == pytest.approx(6.0 + 4.0)
    assert roll_estimate([3.0, 5.0, 4.0], 2) == pytest.approx(5.0 + 3.0)


def tapered_pieces(count: int = 6) -> tuple[list[np.ndarray], list[float]]:
    rng = np.random.default_rng(7)
    pieces, areas = [], []
    for _ in range(count):
        shape = trapezoid(6.0, rng.uniform(1.9, 2.0), rng.uniform(0.35, 0.45), 0.0)
        pieces.append(shape + rng.uniform(-3, 3, 2))
        areas.append(Polygon(shape).area)
    return pieces, areas


def test_tapered_pieces_with_a_straight_edge_are_laid_in_pairs():
    """Six trapezoids 6 m long, 1.9–2.0 m wide at one end and 0.35–0.45 m at the other, one
    long edge straight: each pair fits a 2.5 m roll head to tail, so three lengths of 6 m
    hold them (one after the other they would need 36 m). Laid in pairs they take three
    columns, the same every time to the last bit, also for outlines that differ by round-off;
    the search finds the same length."""
    pieces, areas = tapered_pieces()
    assert all(pair_width(p) <= 2.45 for p in pieces)
    pairs = [(0, 1), (2, 3), (4, 5)]
    laid = pair_nest(pieces, 2.5, pairs, net_areas=areas)
    again = pair_nest(pieces, 2.5, pairs, net_areas=areas)
    assert laid is not None and laid.method == "pairs"
    assert 3 * 6.0 < laid.length < 3 * 6.0 * 1.001
    placed = [Polygon(p.place(pieces[p.index])) for p in laid.pieces]
    assert all(a.disjoint(b) for a, b in itertools.combinations(placed, 2))
    assert all(0 <= p.bounds[1] and p.bounds[3] <= 2.5 for p in placed)
    rounded = [p * (1 + 1e-15 * np.random.default_rng(1).standard_normal(p.shape)) for p in pieces]
    nudged = pair_nest(rounded, 2.5, pairs, net_areas=areas)  # patterns differing by round-off
    for a, b, c in zip(laid.pieces, again.pieces, nudged.pieces, strict=True):
        assert a.rotation == b.rotation == c.rotation
        assert np.array_equal(a.translation, b.translation)
        assert np.array_equal(a.translation, c.translation)
    assert {p.rotation for p in laid.pieces} == {0.0, 180.0}
    assert pair_nest(pieces, 2.2, pairs, net_areas=areas) is None  # a pair too wide
    searched = nest_pieces(pieces, 2.5, net_areas=areas, time_limit=10, seed=0)
    assert searched.length < 3 * 6.0 * 1.01


def test_the_same_pieces_give_the_same_search(monkeypatch):
    """The search runs on one thread from its seed; one that ends by itself (well inside its
    bound) lays every piece at the same place, to the last bit, run after run."""
    pieces, areas = tapered_pieces(2)
    first = nest_pieces(pieces, 2.5, net_areas=areas, time_limit=60, seed=3)
    second = nest_pieces(pieces, 2.5, net_areas=areas, time_limit=60, seed=3)
    assert first.finished and second.finished, (first.search_time, second.search_time)
    assert first.search_time < 0.5 * 60
    assert [p.index for p in first.pieces] == [p.index for p in second.pieces]
    assert [p.rotation for p in first.pieces] == [p.rotation for p in second.pieces]
    for a, b in zip(first.pieces, second.pieces, strict=True):
        assert np.array_equal(a.translation, b.translation)
    assert first.length == second.length
    # where no Python process can be started (an application embedding Python), the same
    # search in a thread of this process: the same nest
    monkeypatch.setattr(nesting, "_interpreter", lambda: None)
    threaded = nest_pieces(pieces, 2.5, net_areas=areas, time_limit=60, seed=3)
    assert threaded.finished
    for a, b in zip(first.pieces, threaded.pieces, strict=True):
        assert a.rotation == b.rotation and np.array_equal(a.translation, b.translation)


def straightness(panel, warp) -> tuple[float, float]:
    """The flattened strip's straighter and more sloping long sides: how far each strays
    across the warp (the ends' tenths left out)."""
    flat = lscm(panel.mesh)
    s, upper, lower = envelopes(
        flat[panel.mesh.boundary_loops()[0]], pattern_direction(panel.mesh, flat, warp)
    )
    inner = slice(len(s) // 10, len(s) - len(s) // 10)
    return tuple(sorted((float(np.ptp(upper[inner])), float(np.ptp(lower[inner])))))


def test_tapered_strips_planned_in_pairs_have_one_seam_along_the_warp():
    """The conic tent at a 2.5 m roll: alone, 16 strips as wide as the roll, symmetric about
    their warps; in pairs, more strips, two of which fit the roll side by side head to tail,
    each with one side along its warp: it strays across the warp by less than a tenth of the
    other (measured 3–6 %: the flattening bends the seams a little)."""
    mesh = tent_roof(n_radial=12, n_around=16)
    alone = plan_strips(mesh, 2.5)
    paired = plan_strips(mesh, 2.5, interlock=True)
    assert len(alone.panels) == 16 and not alone.interlock
    assert len(paired.panels) > len(alone.panels) and paired.interlock
    assert max(paired.widths) <= 2.5
    for panel, warp in zip(alone.panels, alone.warps, strict=True):
        low, high = straightness(panel, warp)
        assert low == pytest.approx(high, rel=1e-3)  # symmetric
    for panel, warp in zip(paired.panels, paired.warps, strict=True):
        low, high = straightness(panel, warp)
        assert low < 0.1 * high
    assert sum(p.mesh.area for p in paired.panels) == pytest.approx(mesh.area, rel=1e-12)


def test_strips_that_are_not_tapered_are_not_paired():
    """The saddle's strips are nearly rectangles: two would need twice the width of one, and
    the pairs are not even planned."""
    mesh = saddle(size=8.0, height=1.6, n=12)
    asked = []

    def planned(interlock: bool):
        asked.append(interlock)
        return plan_strips(mesh, 2.5, interlock=interlock)

    plan = choose_plan(planned, "auto", None)
    assert asked == [False] and not plan.interlock
    assert max(plan.straight_pairs) > 2 * (1 - SAVING) * max(plan.widths)
    assert choose_plan(planned, "always", None).interlock and asked[-1] is True


def test_cutting_a_panel_across_keeps_the_surface_and_shares_the_seam():
    """A strip of a cut cylinder cut across by a geodesic between its seams' middle nodes:
    one panel more, the others as they were, the area kept, the new seam's nodes shared by
    both halves and its 3D length that of the line."""
    mesh = triangulated(cylinder160(n_around=24, n_along=12))
    plan = plan_strips(mesh, 1.0, direction=(0, 1, 0))
    index = len(plan.panels) // 2
    cut = plan.cut
    used = np.unique(cut.mesh.cells["triangle"][cut.panel_ids == index])
    sides = [c[np.isin(c, used)] for c in cut.lines if np.isin(c, used).sum() >= 2]
    assert len(sides) == 2
    ends = [int(np.searchsorted(used, c[len(c) // 2])) for c in sides]
    local = geodesic_lines(plan.panels[index].mesh, [tuple(ends)])[0]
    line = SurfaceLine(used[local.ends], local.fractions, local.points)
    across = cut_across(cut, line, snap=0.0)
    assert across.num_panels == cut.num_panels + 1
    assert across.mesh.area == pytest.approx(mesh.area, rel=1e-12)
    before = np.bincount(cut.panel_ids, weights=areas(cut.mesh))
    after = np.bincount(across.panel_ids, weights=areas(across.mesh))
    assert np.allclose(np.delete(after, [index, index + 1]), np.delete(before, index), rtol=1e-12)
    assert after[index] + after[index + 1] == pytest.approx(before[index], rel=1e-12)
    chain = across.lines[-1]
    length = np.linalg.norm(np.diff(across.mesh.points[chain], axis=0), axis=1).sum()
    assert length == pytest.approx(line.length, rel=1e-12)
    panels = split_panels(across.mesh, across.panel_ids)
    seams = [s for s in find_seams(panels) if {s.first, s.second} == {index, index + 1}]
    assert len(seams) == 1 and seams[0].segments == len(chain) - 1


def areas(mesh) -> np.ndarray:
    p = mesh.points[mesh.cells["triangle"]]
    return 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)


@pytest.mark.parametrize("roll", [2.5, 1.5])
def test_the_conic_tent_uses_four_fifths_of_the_roll(roll):
    """``vares cut --example conic-tent`` (its options in docs/cutting.md): 16 or 26 strips
    alone used 49.9 % and 49.3 % of the roll; planned in pairs they use more than 80 %, every
    piece on the roll, both sides of every seam equally long and every seam within 1 % of its
    line; a lone strip of an odd count is cut across into two halves that are a pair."""
    mesh = tent_roof()
    result = cut(
        mesh, FABRIC, prestress=(2.0, 1.5), roll_width=roll, allowance=20.0, edge_type="cable",
        cable_allowance=80.0, high_edge_type="clamp", clamp_allowance=50.0,
    )  # fmt: skip
    assert result.converged and result.plan.interlock
    nest = result.nest
    assert nest.method == "pairs" and nest.yield_ > 0.8
    assert nest.seed is None and nest.finished and "no search" in nest.how  # made, not searched
    assert sorted(p.index for p in nest.pieces) == list(range(len(result.plan.panels)))
    assert max(result.widths) <= result.usable_width
    assert result.panel_area == pytest.approx(mesh.area, rel=1e-12)
    for seam in result.seams:
        a, b = seam.length_2d
        assert abs(a - b) <= 1e-9 * a
        assert abs(seam.length_3d / seam.line_length - 1) < 0.01
    if result.plan.split is not None:  # an odd count: the last strip's halves are a pair
        first, second = result.plan.split
        assert second == first + 1 == len(result.plan.panels) - 1
        names = [result.plan.panels[k].name for k in result.plan.split]
        assert names == [f"strip-{first + 1}a", f"strip-{first + 1}b"]


@pytest.mark.parametrize(
    ("interlock", "strips"), [(False, "strips of 0.001"), (True, "strips in pairs 0.001 wide")]
)
def test_a_refusal_says_what_the_strips_are_planned_as(interlock, strips):
    """In pairs two strips share the roll's width, each about half of it: the refusal of a
    roll too narrow for the surface's refinement says so, not that the strips are as wide as
    the roll."""
    mesh = saddle(size=8.0, height=1.6, n=6)
    with pytest.raises(CuttingError) as info:
        plan_strips(mesh, 1e-3, interlock=interlock, max_strips=10**9)
    assert str(info.value).startswith(f"{strips} would need the surface refined to about")
