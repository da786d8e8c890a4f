"""Cutting lines (geodesics, plane sections, drawn curves), cutting a mesh along them, strips of
roll width, cut outlines with allowances per edge and nesting on the roll."""

import gc
import itertools
import os
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from shapely.geometry import Polygon

from vares import read_mesh
from vares.geometry.cutting import cut_mesh
from vares.geometry.drawn_lines import closest_points, curves_on_surface
from vares.geometry.examples import cone_segment, cylinder160, hypar, saddle
from vares.geometry.line_families import geodesic_between_ends, line_family
from vares.geometry.outline import allowance_outline
from vares.geometry.refine import refine, refine_once
from vares.geometry.surface_lines import (
    CuttingError,
    geodesic_lines,
    min_angles,
    plane_sections,
    triangulated,
)
from vares.structures import find_seams, nesting, split_panels
from vares.structures.layout import CELLS_ACROSS, plan_strips
from vares.structures.nesting import (
    NestError,
    clearance_of,
    nest_pieces,
    single_precision_step,
    usable_width,
)

#: Form-found design meshes (tests/data/README.md).
DATA = Path(__file__).parent / "data"


def developed(line, flat: np.ndarray) -> np.ndarray:
    """The line's points in a development ``flat`` (n, 2) of the mesh (affine in every cell)."""
    a, b = flat[line.ends[:, 0]], flat[line.ends[:, 1]]
    return (1 - line.fractions)[:, None] * a + line.fractions[:, None] * b


def distance_to_segment(points, a, b):
    t = np.clip((points - a) @ (b - a) / ((b - a) @ (b - a)), 0, 1)
    return np.linalg.norm(a + t[:, None] * (b - a) - points, axis=1)


def test_cylinder_geodesics_unroll_to_straight_lines():
    """The triangulated cylinder is developable (its cells are halves of plane rectangles): a
    helix-like geodesic unrolls onto the straight segment between its ends, a generator is one."""
    n_around, n_along, radius, angle = 32, 16, 1.0, 160.0
    mesh = cylinder160(radius, 2.0, angle, n_around, n_along)
    chord = 2 * radius * np.sin(np.radians(angle) / (2 * n_around))
    i, j = np.meshgrid(np.arange(n_around + 1), np.arange(n_along + 1), indexing="xy")
    flat = np.column_stack([chord * i.ravel(), 2.0 / n_along * j.ravel()])
    start, end = 1 * (n_around + 1) + 2, 15 * (n_around + 1) + 29  # helix-like
    along = 0 * (n_around + 1) + 10, 16 * (n_around + 1) + 10  # generator
    helix, generator = geodesic_lines(mesh, [(start, end), along])
    path = developed(helix, flat)
    exact = np.linalg.norm(flat[end] - flat[start])
    # the edge-flip solver lays its path out cell by cell: straight to ~1e-7 of its length
    assert distance_to_segment(path, flat[start], flat[end]).max() < 1e-6 * exact
    assert helix.length == pytest.approx(exact, rel=1e-12)
    assert len(helix.points) > 20  # it crosses cells, it does not follow edges
    smooth = np.hypot(radius * np.radians(27 * angle / n_around), 28 / 16)  # the smooth helix
    assert abs(helix.length / smooth - 1) < 1e-3
    assert generator.length == pytest.approx(2.0, rel=1e-12)
    np.testing.assert_allclose(generator.points[:, 0], mesh.points[along[0], 0], atol=1e-12)


def test_cone_geodesic_unrolls_to_a_straight_line():
    n_radial, n_around = 12, 24
    mesh = cone_segment(60.0, 120.0, 1.0, 4.0, n_radial, n_around)
    rays = mesh.points.reshape(n_around + 1, n_radial + 1, 3)[:, -1]
    rays = rays / np.linalg.norm(rays, axis=1)[:, None]
    turns = np.arccos(np.clip(np.sum(rays[1:] * rays[:-1], axis=1), -1, 1))
    alpha = np.concatenate([[0.0], np.cumsum(turns)])  # the development of the polyhedral cone
    slant = np.linspace(1.0, 4.0, n_radial + 1)
    s, a = np.meshgrid(slant, alpha, indexing="xy")
    flat = np.column_stack([(s * np.cos(a)).ravel(), (s * np.sin(a)).ravel()])
    start, end = 0 * (n_radial + 1) + 12, 20 * (n_radial + 1) + 3
    assert distance_to_segment(np.zeros((1, 2)), flat[start], flat[end])[0] > 1.0  # stays on
    (line,) = geodesic_lines(mesh, [(start, end)])
    exact = np.linalg.norm(flat[end] - flat[start])
    assert distance_to_segment(developed(line, flat), flat[start], flat[end]).max() < 1e-6 * exact
    assert line.length == pytest.approx(exact, rel=1e-12)


def test_plane_sections_lie_in_their_plane_and_cross_the_surface():
    mesh = hypar(size=10.0, rise=0.06, n=12)
    (line,) = plane_sections(mesh, (0.3, 1.0, 0.0), 1.7)
    np.testing.assert_allclose(line.points @ np.array([0.3, 1.0, 0.0]), 1.7, atol=1e-12)
    boundary = set(np.unique(mesh.boundary_edges()).tolist())
    for k in (0, -1):  # from boundary to boundary
        assert set(line.ends[k].tolist()) <= boundary


@pytest.mark.parametrize("kind", ["geodesic", "planar"])
def test_cutting_along_lines_keeps_the_surface(kind):
    mesh = saddle(size=10.0, height=2.0, n=12)
    family = line_family(mesh, "parallel", (1.0, 1.0, 0.0))
    sections = [family.sections(mesh, s)[0] for s in (-3.0, -0.4, 2.5)]
    base, lines = (
        (mesh, sections) if kind == "planar" else geodesic_between_ends(mesh, sections, 0.05)
    )
    cut = cut_mesh(base, lines)
    assert cut.num_panels == 4
    assert cut.mesh.area == pytest.approx(mesh.area, rel=1e-12)
    _, _, distance = closest_points(mesh, cut.mesh.points)  # every node on the surface
    assert distance.max() < 1e-12
    panels = split_panels(cut.mesh, cut.panel_ids)
    assert sum(p.mesh.area for p in panels) == pytest.approx(mesh.area, rel=1e-12)
    seams = find_seams(panels)
    assert len(seams) == 3
    for seam, chain, line in zip(
        sorted(
            seams,
            key=lambda s: panels[s.first].mesh.points[s.nodes_first].mean(axis=0) @ family.across,
        ),
        sorted(cut.lines, key=lambda c: cut.mesh.points[c].mean(axis=0) @ family.across),
        sorted(lines, key=lambda li: li.points.mean(axis=0) @ family.across),
        strict=True,
    ):
        first = panels[seam.first].mesh.points[seam.nodes_first]
        np.testing.assert_allclose(first, panels[seam.second].mesh.points[seam.nodes_second])
        length = np.linalg.norm(np.diff(first, axis=0), axis=1).sum()
        assert length == pytest.approx(
            np.linalg.norm(np.diff(cut.mesh.points[chain], axis=0), axis=1).sum()
        )
        assert abs(length / line.length - 1) < 0.01  # the seam follows its line
    assert cut.worst_angle > 1.0


def test_crossing_lines_are_refused():
    mesh = hypar(size=10.0, rise=0.06, n=8)
    lines = plane_sections(mesh, (1, 0, 0), 0.3) + plane_sections(mesh, (0, 1, 0), 0.2)
    with pytest.raises(CuttingError, match=r"cross|meet"):
        cut_mesh(mesh, lines)


def test_drawn_curves_become_cutting_lines_through_their_points():
    mesh = hypar(size=10.0, rise=0.06, n=12)
    x = np.linspace(-5.0, 5.0, 9)
    across = [y + 0.3 * np.sin(x) for y in (-2.0, 1.5)]
    curves = [np.column_stack([x, y, 0.06 * x * y + 0.02]) for y in across]  # 2 cm above
    base, lines = curves_on_surface(mesh, curves, 0.05)
    cut = cut_mesh(base, lines)
    assert cut.num_panels == 3
    assert cut.mesh.area == pytest.approx(mesh.area, rel=1e-12)
    cell = 10.0 / 12
    for curve, line in zip(curves, lines, strict=True):
        # the line passes through the drawn points (on the surface, moved onto an edge if within
        # 5 % of a cell of it; one point per cell)
        distance = np.linalg.norm(curve[:, None, :] - line.points[None, :, :], axis=2).min(axis=1)
        assert np.median(distance) < 0.03 + 0.05 * cell and distance.max() < cell


def test_strips_fit_the_roll_with_the_least_number():
    mesh = saddle(size=10.0, height=2.0, n=16)
    plan = plan_strips(mesh, 2.0, seam_allowance=0.02, edge_allowance=0.05, direction=(0, 1, 0))
    assert max(plan.widths) <= 2.0
    count = len(plan.panels)
    tried = dict(plan.history)
    assert count - 1 in tried and tried[count - 1] > 2.0  # one strip fewer does not fit
    assert sum(p.mesh.area for p in plan.panels) == pytest.approx(mesh.area, rel=1e-12)


def test_allowance_outline_per_edge():
    square = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 2.0], [0.0, 2.0]])
    outline = allowance_outline(square, [0.1, 0.2, 0.3, 0.4])  # bottom, right, top, left
    low, high = outline.min(axis=0), outline.max(axis=0)
    np.testing.assert_allclose([*low, *high], [-0.4, -0.1, 4.2, 2.3], atol=1e-12)
    assert Polygon(outline).area == pytest.approx(4.6 * 2.4, rel=1e-12)
    hexagon = np.column_stack([np.cos(np.arange(6) * np.pi / 3), np.sin(np.arange(6) * np.pi / 3)])
    buffered = Polygon(hexagon).buffer(0.05, join_style="mitre", mitre_limit=4.0)
    assert Polygon(allowance_outline(hexagon, 0.05)).symmetric_difference(buffered).area < 1e-12


def tapered_pieces(count: int = 7) -> tuple[list[np.ndarray], list[float]]:
    """``count`` tapered pieces 3–8 long, 0.8–1.4 wide at one end, scattered; their areas."""
    rng = np.random.default_rng(3)
    pieces, areas = [], []
    for _ in range(count):
        length, wide, narrow = rng.uniform(3, 8), rng.uniform(0.8, 1.4), rng.uniform(0.2, 0.6)
        shape = np.array(
            [[0, 0], [length, 0.5 * (wide - narrow)], [length, 0.5 * (wide + narrow)], [0, wide]]
        )
        pieces.append(shape + rng.uniform(-5, 5, 2))
        areas.append(Polygon(shape).area)
    return pieces, areas


def search_processes() -> list[int]:
    """The nesting searches this process has running (Linux: from /proc)."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            parent = int(stat.read_text().rsplit(")", 1)[1].split()[1])
            command = (stat.parent / "cmdline").read_bytes()
        except (OSError, IndexError, ValueError):
            continue  # a process that ended meanwhile
        if parent == os.getpid() and b"_nest_search" in command:
            found.append(int(stat.parent.name))
    return found


@pytest.mark.parametrize("turn", [True, False])
def test_nesting_never_overlaps_and_stays_on_the_roll(turn):
    pieces, areas = tapered_pieces()
    nest = nest_pieces(pieces, 2.5, net_areas=areas, allow_turn=turn, time_limit=1, seed=1)
    placed = [Polygon(p.place(pieces[p.index])) for p in nest.pieces]
    assert sorted(p.index for p in nest.pieces) == list(range(7))
    for a, b in itertools.combinations(placed, 2):
        assert not a.intersects(b)
    bounds = np.array([p.bounds for p in placed])
    assert bounds[:, 1].min() >= 0 and bounds[:, 3].max() <= 2.5 and bounds[:, 0].min() >= 0
    assert nest.length == pytest.approx(bounds[:, 2].max())
    assert nest.yield_ == pytest.approx(sum(areas) / (2.5 * nest.length))
    # two rows fit across the roll: far shorter than the pieces laid end to end
    assert nest.length < 0.6 * sum(np.ptp(p[:, 0]) for p in pieces)
    assert all(p.rotation in ((0.0, 180.0) if turn else (0.0,)) for p in nest.pieces)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_the_time_bound_stops_the_search_and_lays_its_shortest_nest():
    """The search runs in a process of its own, stopped at its bound (a fraction of a second
    too: the bound is not rounded to whole seconds) once it has a nest; the shortest nest it
    reported is laid, whole and checked, and no search nor pipe to it is left. These seven pieces
    keep sparrow searching for more than 30 s; before, a bound of 0.5 s was rounded up to one
    second for each of its two phases."""
    pieces, areas = tapered_pieces()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        nest = nest_pieces(pieces, 2.5, net_areas=areas, time_limit=0.5, seed=1)
        gc.collect()
    assert not [w for w in caught if issubclass(w.category, ResourceWarning)]  # pipes closed
    assert not nest.finished and nest.time_limit == 0.5
    assert 0.5 <= nest.search_time < 2.5, nest.search_time  # the process's start included
    assert sorted(p.index for p in nest.pieces) == list(range(7))
    placed = [Polygon(p.place(pieces[p.index])) for p in nest.pieces]
    assert all(not a.intersects(b) for a, b in itertools.combinations(placed, 2))
    assert max(p.bounds[3] for p in placed) <= 2.5
    assert nest.length < 0.6 * sum(np.ptp(p[:, 0]) for p in pieces)  # rows side by side
    assert search_processes() == []
    with pytest.raises(ValueError, match="must be positive"):
        nest_pieces(pieces, 2.5, net_areas=areas, time_limit=0.0)


def test_a_search_that_fails_says_why(tmp_path, monkeypatch):
    """A search that reports its failure, or whose process ends without its result (with or
    without nests reported on its way), is an error with the search's own last word, not a
    nest."""
    pieces, areas = tapered_pieces(2)
    failing = tmp_path / "failing.py"
    failing.write_text(
        'import json, sys\nsys.stdin.read()\nprint(json.dumps({"kind": "error", '
        '"message": "strip too narrow"}))\n'
    )
    monkeypatch.setattr(nesting, "_WORKER", failing)
    with pytest.raises(NestError, match="the nesting search failed: strip too narrow"):
        nest_pieces(pieces, 2.5, net_areas=areas, time_limit=5)
    crashing = tmp_path / "crashing.py"
    crashing.write_text("import sys\nsys.stdin.read()\nraise SystemExit('no spyrrow here')\n")
    monkeypatch.setattr(nesting, "_WORKER", crashing)
    with pytest.raises(NestError, match="ended without its result: no spyrrow here"):
        nest_pieces(pieces, 2.5, net_areas=areas, time_limit=5)
    # a search that reported a nest on its way, then died before its end: no nest is laid
    # from it (a nest is taken before the search's end only at the bound)
    dying = tmp_path / "dying.py"
    dying.write_text(
        "import json, sys\nsys.stdin.read()\n"
        'print(json.dumps({"kind": "feasible", "width": 9.0, "placed": [[0, 0.0, 0.0, 0.0], '
        '[1, 0.0, 5.0, 0.0]]}), flush=True)\nraise SystemExit("killed")\n'
    )
    monkeypatch.setattr(nesting, "_WORKER", dying)
    with pytest.raises(NestError, match="ended without its result: killed"):
        nest_pieces(pieces, 2.5, net_areas=areas, time_limit=5)


def test_the_search_runs_in_a_python_interpreter_or_in_a_thread(monkeypatch):
    """The search's process is started with this Python, or where its executable is an
    application embedding Python, with the interpreter that application gave multiprocessing;
    with neither, in a thread (``None``)."""
    from multiprocessing import spawn

    assert nesting._interpreter() == sys.executable
    monkeypatch.setattr(sys, "executable", "/opt/cad/bin/Designer.exe")
    monkeypatch.setattr(spawn, "get_executable", lambda: "/opt/cad/python/bin/python3.11")
    assert nesting._interpreter() == "/opt/cad/python/bin/python3.11"
    monkeypatch.setattr(spawn, "get_executable", lambda: "/opt/cad/bin/Designer.exe")
    assert nesting._interpreter() is None


def test_a_nest_says_how_it_was_made():
    """Reports and commands say whether a nest is the same for the same input: made in pairs
    (no search), searched to the search's own end, or stopped by the bound."""
    from vares.structures.nesting import RollNest

    pairs = RollNest(2.5, 10.0, [], 20.0, 0.1, 0.0, 0.0, True, "pairs")
    ended = RollNest(2.5, 10.0, [], 20.0, 4.2, 10.0, 4.04, True, seed=3)
    stopped = RollNest(2.5, 10.0, [], 20.0, 10.0, 10.0, 10.0, False)
    assert pairs.stopped is None and "no search: the same nest on every machine" in pairs.how
    assert ended.stopped is None
    assert ended.how == "the search ended by itself in 4.0 s: the same nest for the same input"
    assert stopped.how == stopped.stopped
    assert stopped.stopped.startswith("the nesting search was stopped by its time bound (10 s)")


def test_a_piece_as_wide_as_the_roll_is_refused_by_the_nest_as_by_the_cut():
    """``cut`` and the nesting agree on the widest piece (``usable_width``): a piece exactly as
    wide as the roll is refused before the search, one at the usable width is laid."""
    roll = 2.0
    square = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, roll], [0.0, roll]])
    for width in (roll, 0.5 * (roll + usable_width(roll))):
        with pytest.raises(ValueError, match="takes at most"):
            nest_pieces([square * [1.0, width / roll]], roll, net_areas=[6.0], time_limit=1)
    fitting = square * [1.0, usable_width(roll) / roll]
    nest = nest_pieces([fitting], roll, net_areas=[Polygon(fitting).area], time_limit=1)
    placed = Polygon(nest.pieces[0].place(fitting))
    assert placed.bounds[1] >= 0 and placed.bounds[3] <= roll
    assert nest.length == pytest.approx(3.0, rel=1e-9)


def test_pieces_far_along_a_long_roll_keep_the_search_precision_apart():
    """The search places pieces in single precision: 9 km along the roll a number is rounded
    to 1/1024 m, twenty times the clearance of a 1 m roll. Pieces there must be kept that far
    apart, or they overlap by round-off (the form-found sail's 91 strips at 2.5 m, 2.6 km of
    roll: pieces 12 and 14 overlapped by 5e-5 m, an internal error after the whole solve)."""
    rng = np.random.default_rng(0)
    pieces = []
    for _ in range(20):
        length = rng.uniform(440.0, 460.0)
        wide, narrow = rng.uniform(0.55, 0.6), rng.uniform(0.45, 0.5)
        pieces.append(np.array([[0, 0], [length, 0], [length, narrow], [0, wide]]))
    step = single_precision_step(pieces, 1.0)
    assert step == 2 * np.spacing(np.float32(1.0 + sum(np.ptp(p[:, 0]) for p in pieces)))
    assert step > 20 * clearance_of(1.0)
    nest = nest_pieces(pieces, 1.0, net_areas=[1.0] * 20, time_limit=1, seed=0)
    placed = [Polygon(p.place(pieces[p.index])) for p in nest.pieces]
    gaps = [a.distance(b) for a, b in itertools.combinations(placed, 2)]
    assert min(gaps) >= 0.999 * (clearance_of(1.0) + step)
    bounds = np.array([p.bounds for p in placed])
    assert bounds[:, 1].min() >= 0 and bounds[:, 3].max() <= 1.0


def test_a_roll_too_narrow_for_the_surface_is_refused_before_it_is_refined():
    from vares.geometry.example_surfaces import tent_roof
    from vares.structures.layout import MAX_REFINED_CELLS, refined_cells

    tent = triangulated(tent_roof())  # all round: its strips are counted only once refined
    size = np.ptp(tent.points, axis=0).max()
    edge = longest_edge(tent)
    assert refined_cells(tent, 2.0 * edge) == tent.num_cells  # no cell needs a split
    assert refined_cells(tent, 0.499 * edge) <= 16 * tent.num_cells
    with pytest.raises(CuttingError, match=r"refined to about .* cells .*try a wider roll"):
        plan_strips(tent, 1e-4 * size)
    assert refined_cells(tent, 0.5e-4 * size) > MAX_REFINED_CELLS


def longest_edge(mesh) -> float:
    edges = mesh.edges()
    return float(np.linalg.norm(mesh.points[edges[:, 0]] - mesh.points[edges[:, 1]], axis=1).max())


def off_surface(mesh, points: np.ndarray, sample: int = 200) -> float:
    """Largest distance from the surface of ``sample`` of the ``points`` (drawn at random)."""
    chosen = np.random.default_rng(0).choice(len(points), min(sample, len(points)), replace=False)
    return float(closest_points(mesh, points[chosen])[2].max())


def test_refining_keeps_the_surface():
    """Refined on its own faces: edges no longer than asked, the same area, every node on the
    input surface; a round that splits every cell keeps every angle (1-to-4), one that splits
    some keeps the others and leaves no hanging node (the mesh is manifold and one piece)."""
    mesh = triangulated(read_mesh(DATA / "hypar_sail.obj"))
    fine, rounds = refine(mesh, 4.0)
    assert rounds == 2 and longest_edge(fine) <= 4.0
    assert fine.area == pytest.approx(mesh.area, rel=1e-13)
    assert off_surface(mesh, fine.points) <= 1e-12 * np.ptp(mesh.points, axis=0).max()
    assert len(mesh.points) < len(fine.points) and set(map(tuple, mesh.points)) <= set(
        map(tuple, fine.points)
    )
    uniform = refine_once(mesh, 0.0)
    assert len(uniform.cells["triangle"]) == 4 * len(mesh.cells["triangle"])
    assert min_angles(uniform.points, uniform.cells["triangle"]).min() == pytest.approx(
        min_angles(mesh.points, mesh.cells["triangle"]).min(), abs=1e-9
    )
    partial = refine_once(mesh, 8.0)  # only the long cells near the corners
    kept = {tuple(sorted(t)) for t in mesh.cells["triangle"].tolist()}
    now = {tuple(sorted(t)) for t in partial.cells["triangle"].tolist()}
    assert 0 < len(kept & now) < len(kept)
    assert len(partial.boundary_loops()) == 1
    assert partial.area == pytest.approx(mesh.area, rel=1e-13)
    assert refine_once(mesh, 11.0) is mesh  # no edge longer: nothing to do


def line_distance(first: np.ndarray, second: np.ndarray, parts: int = 8) -> float:
    """Smallest distance between two polylines ``(k, 3)``, sampled ``parts`` times per segment."""
    from scipy.spatial import cKDTree

    def dense(points):
        t = np.linspace(0.0, 1.0, parts, endpoint=False)[:, None, None]
        pieces = points[:-1] + t * (points[1:] - points[:-1])
        return np.vstack([pieces.reshape(-1, 3), points[-1:]])

    return float(cKDTree(dense(first)).query(dense(second))[0].min())


@pytest.mark.parametrize(
    ("name", "subdivisions", "width"),
    [("hypar_sail.obj", 0, 10.0), ("hypar_sail.obj", 1, 10.0), ("fofin_wave.obj", 0, 1.5)],
)
def test_coarse_designs_are_cut_into_strips_of_roll_width(name, subdivisions, width):
    """Form-found meshes with cells as wide as a strip and edges that sag inwards (the sections
    near them cut the surface twice, the geodesics between their ends hug the edge): the
    strips fit, one gap fewer does not, the strips are the surface, the lines stay apart, the
    surface was refined where its cells were too large for the strips."""
    mesh = triangulated(read_mesh(DATA / name))
    if subdivisions:
        mesh, _ = refine(mesh, 0.0, max_rounds=subdivisions)
    plan = plan_strips(mesh, width)
    assert max(plan.widths) <= width
    gaps = dict(plan.history)
    best = min(n for n, widest in gaps.items() if widest <= width)
    assert gaps[best - 1] > width
    assert len(plan.panels) >= best
    assert sum(p.mesh.area for p in plan.panels) == pytest.approx(mesh.area, rel=1e-12)
    size = np.ptp(mesh.points, axis=0).max()
    assert off_surface(mesh, plan.cut.mesh.points) <= 1e-9 * size
    assert longest_edge(plan.cut.mesh) <= width / CELLS_ACROSS
    if longest_edge(mesh) > width / CELLS_ACROSS:
        assert plan.refinements >= 1 and plan.input_cells == len(mesh.cells["triangle"])
    chains = [plan.cut.mesh.points[c] for c in plan.cut.lines]
    for first, second in itertools.combinations(chains, 2):
        assert line_distance(first[1:-1], second[1:-1]) > 0.02 * width


def test_a_per_cell_prestress_follows_the_cells_the_strips_are_cut_from():
    """A coarse hypar with quads (refined and cut into strips on its own faces) and a prestress
    that differs from cell to cell: every strip cell takes the row of the input cell it lies in
    (found here by brute force: the input quad one of whose triangles, of either diagonal,
    contains its centroid)."""
    import vares

    mesh = hypar(size=6.0, rise=0.05, n=6, cell_type="quad")
    quads = mesh.cells["quad"]
    rows = np.column_stack([1.0 + np.arange(len(quads)), 0.5 + 0.1 * np.arange(len(quads))])
    result = vares.cut(
        mesh,
        vares.materials.fabric("pes-pvc-type-2").material(),
        prestress=rows,
        roll_width=2.0,
        nest_time=1.0,
    )
    assert result.converged and len(result.plan.panels) >= 3
    corners = mesh.points[quads]

    def containing(point):
        for k, quad in enumerate(corners):
            for tri in (quad[[0, 1, 2]], quad[[0, 2, 3]], quad[[0, 1, 3]], quad[[1, 2, 3]]):
                a, b, c = tri
                normal = np.cross(b - a, c - a)
                area = np.linalg.norm(normal)
                lam = [
                    np.dot(np.cross(q - p, point - p), normal) / area**2
                    for p, q in ((b, c), (c, a), (a, b))
                ]
                if min(lam) > -1e-9 and abs(np.dot(point - a, normal / area)) < 1e-9:
                    return k
        raise AssertionError("no input cell contains the point")

    for panel, solved in zip(result.plan.panels, result.structure.results, strict=True):
        centres = panel.mesh.points[panel.mesh.cells["triangle"]].mean(axis=1)
        expected = rows[[containing(c) for c in centres]]
        np.testing.assert_array_equal(solved.prestress[:, :2], expected)
    with pytest.raises(ValueError, match="one row per cell of the surface"):
        vares.cut(
            mesh, vares.materials.NeoHooke(E=600.0, nu=0.3), prestress=rows[:-1], roll_width=2.0
        )


def test_planned_lines_that_meet_refine_the_surface_then_become_plane_sections(monkeypatch):
    """Should planned geodesics meet (forced here), the surface is refined twice more, then the
    lines are plane sections, which keep apart: the plan is made, no error."""
    from vares.geometry.cutting import LinesMeetError
    from vares.structures import layout

    real, calls = layout._layout, []

    def meeting(surface, family, spans, seams, *rest):
        calls.append((seams, len(surface.cells["triangle"])))
        if seams == "geodesic" and len(spans) > 1:
            raise LinesMeetError("cutting lines 1 and 2 meet")
        return real(surface, family, spans, seams, *rest)

    monkeypatch.setattr(layout, "_layout", meeting)
    mesh = saddle(size=8.0, height=1.6, n=12)
    plan = plan_strips(mesh, 2.0)
    assert max(plan.widths) <= 2.0 and len(plan.lines) >= 3
    assert plan.refinements == 2 and plan.replaced_geodesics == len(plan.lines)
    assert plan.refined_cells == 16 * len(mesh.cells["triangle"])
    assert {"geodesic", "planar"} <= {seams for seams, _ in calls}


def test_a_coarse_ring_of_facets_is_cut_all_round():
    """A coarse design of the conic tent (16 facets round: its nodes' azimuths 22.5° apart) goes
    all round its axis, as its high ring's boundary loop does: radial strips all round, that fit
    the roll, the least number that does."""
    from vares.geometry.example_surfaces import tent_roof

    tent = triangulated(tent_roof(n_radial=3, n_around=4))
    assert tent.num_cells == 96
    family = line_family(tent)
    assert family.kind == "radial" and family.closed
    assert family.span[1] - family.span[0] == pytest.approx(2 * np.pi)
    plan = plan_strips(tent, 2.5, max_strips=40)
    assert max(plan.widths) <= 2.5 and len(plan.panels) == 15
    assert dict(plan.history)[14] > 2.5
    assert sum(p.mesh.area for p in plan.panels) == pytest.approx(tent.area, rel=1e-12)


def test_strips_in_pairs_are_refined_for_their_own_width():
    """Strips planned in pairs are each about half as wide as the roll: the surface is refined
    so that they, not a roll-wide strip, are ``CELLS_ACROSS`` cells across."""
    from vares.geometry.example_surfaces import tent_roof

    tent = triangulated(tent_roof(n_radial=3, n_around=4))
    alone = plan_strips(tent, 4.0)
    paired = plan_strips(tent, 4.0, interlock=True)
    assert paired.interlock and max(paired.widths) <= 4.0
    assert longest_edge(alone.cut.mesh) <= 4.0 / CELLS_ACROSS
    assert longest_edge(alone.cut.mesh) > 4.0 / (2 * CELLS_ACROSS)  # no finer than it needs
    assert longest_edge(paired.cut.mesh) <= 4.0 / (2 * CELLS_ACROSS)
    assert paired.refinements == alone.refinements + 1


def test_a_surface_narrower_than_the_roll_is_cut_as_one_strip(tmp_path):
    """The saddle (20 m, a 100 m roll): one strip, no seam, the whole surface on the roll (it
    failed in the search for the number of strips, then in the seams' line lengths)."""
    import json

    from conftest import run

    out = tmp_path / "one"
    result = run("cut", "--example", "saddle", "--roll-width", "100", "-o", out, "-q")
    assert result.exit_code == 0, result.stderr
    data = json.loads((out / "cut.json").read_text())
    assert len(data["panels"]) == 1 and data["seams"] == []
    assert data["panels"][0]["width"] <= 100.0
    structure = json.loads((out / "structure.json").read_text())
    assert structure["converged"] and structure["seams"] == [] and not structure["too_wide"]
    assert data["nesting"]["length"] == pytest.approx(data["panels"][0]["width"], rel=0.05)
