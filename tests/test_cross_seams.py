"""Strips cut across into pieces where whole strips fit no roll (cross seams)."""

import json
from pathlib import Path

import ezdxf
import meshio
import numpy as np
import pytest
from conftest import error_line, run
from shapely.geometry import Polygon

from vares.geometry.examples import cylinder160
from vares.geometry.surface_lines import triangulated
from vares.io.meshes import read_mesh
from vares.structures import find_seams
from vares.structures.cross_seams import split_across
from vares.structures.equalise import NoFitError
from vares.structures.layout import plan_strips

DATA = Path(__file__).parent / "data"


def areas(mesh) -> np.ndarray:
    p = mesh.points[mesh.cells["triangle"]]
    return 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)


def test_strips_cut_across_keep_the_surface_and_share_their_cross_seams():
    """Every strip of a cut cylinder wider than asked, cut into three: three pieces a strip in
    order along it (``strip-Na`` …), the strip's area in its pieces, two cross seams a strip
    shared by neighbouring pieces, each cross seam across the strip (along it by at most a
    cell: its ends are moved onto nodes, apart from the neighbouring strips' cross seams)."""
    mesh = triangulated(cylinder160(n_around=24, n_along=12))
    cell = 2.0 / 12  # the cells' length along the axis
    plan = plan_strips(mesh, 1.0, direction=(0, 1, 0))
    strips = len(plan.panels)
    assert strips >= 3
    before = np.bincount(plan.cut.panel_ids, weights=areas(plan.cut.mesh))
    split = split_across(plan, 0.0, 3)  # every strip is wider than 0
    assert len(split.panels) == 3 * strips and split.cross_cut == strips and split.pieces == 3
    assert split.strip_of == [k for k in range(strips) for _ in range(3)]
    names = [p.name for p in split.panels]
    assert names == [f"{plan.panels[k].name}{c}" for k in range(strips) for c in "abc"]
    after = np.bincount(split.cut.panel_ids, weights=areas(split.cut.mesh))
    assert np.allclose(after.reshape(strips, 3).sum(axis=1), before, rtol=1e-12)
    assert split.cut.mesh.area == pytest.approx(mesh.area, rel=1e-12)
    for k in range(strips):  # the pieces follow each other along the strip's warp
        along = [
            p.mesh.points.mean(axis=0) @ plan.warps[k] for p in split.panels[3 * k : 3 * k + 3]
        ]
        assert along[0] < along[1] < along[2]
    seams = find_seams(split.panels)
    cross = [s for s in seams if split.strip_of[s.first] == split.strip_of[s.second]]
    assert len(cross) == 2 * strips
    for seam in cross:
        assert abs(seam.first - seam.second) == 1
        nodes = split.panels[seam.first].mesh.points[seam.nodes_first]
        along = abs((nodes[-1] - nodes[0]) @ plan.warps[split.strip_of[seam.first]])
        assert along <= cell + 1e-12  # across the strip, its ends moved onto nodes
    assert len(split.cut.lines) == len(plan.cut.lines) + 2 * strips
    unchanged = split_across(plan, max(plan.widths), 3)
    assert unchanged is plan


def test_the_wave_at_half_a_metre_is_cut_with_cross_seams():
    """compas-FoFin's wave (10 m, 0.5 m quads) at a 0.5 m roll: its whole strips do not get
    narrower with their number (refused with cross seams off); cut across into pieces, some
    number of them fits: every piece's flattened width within the roll, the pieces are the
    surface, the pieces of a strip named after it."""
    mesh = triangulated(read_mesh(DATA / "fofin_wave.obj"))
    roll = 0.5
    with pytest.raises(NoFitError, match="do not get narrower"):
        plan_strips(mesh, roll, cross_seams=False)
    plan = plan_strips(mesh, roll)
    assert plan.cross_cut >= 1 and plan.pieces >= 2
    assert max(plan.widths) <= roll
    assert len(plan.panels) > len(set(plan.strip_of))
    assert sum(p.mesh.area for p in plan.panels) == pytest.approx(mesh.area, rel=1e-12)
    gaps = dict(plan.history)
    best = min(n for n, widest in gaps.items() if widest <= roll)
    assert gaps[best - 1] > roll
    names = [p.name for p in plan.panels]
    assert len(set(names)) == len(names)
    cut_pieces = [p.name for p in plan.panels if p.name[-1].isalpha()]
    assert len(cut_pieces) == plan.cross_cut * plan.pieces
    for k, panel in enumerate(plan.panels):
        strip = plan.strip_of[k]
        assert panel.name.rstrip("abcdefghijklmnopqrstuvwxyz") == f"strip-{strip + 1}"


def test_pieces_of_a_doubly_curved_surface_pattern_with_matched_cross_seams():
    """A hypar's strips, each cut in two, patterned as one structure with the PES/PVC fabric,
    every piece's warp its own: the seam matching converges, both sides of every seam (the
    cross seams and the strips' seams cut at their ends) equally long, and the cross seams of
    neighbouring strips are staggered: no point of the surface lies in four pieces."""
    import vares
    from vares.structures.matching import solve_structure

    mesh = triangulated(vares.examples.hypar(size=10.0, rise=0.06, n=12))
    plan = plan_strips(mesh, 3.0)
    assert len(plan.panels) >= 3
    split = split_across(plan, 0.0, 2)
    assert len(split.panels) == 2 * len(plan.panels)
    # each piece's warp along its own part of the seams; a warp given for all stays as given
    own = [
        np.degrees(np.arccos(min(1.0, w @ plan.warps[s])))
        for w, s in zip(split.warps, split.strip_of, strict=True)
    ]
    assert max(own) > 0.1
    given = split_across(plan, 0.0, 2, own_warps=False)
    assert all(
        np.array_equal(w, plan.warps[s]) for w, s in zip(given.warps, given.strip_of, strict=True)
    )
    fabric = vares.materials.fabric("pes-pvc-type-2").material()
    result = solve_structure(
        split.panels,
        fabric,
        prestress=(2.0, 1.5),
        panel_settings=[{"warp_direction": tuple(w)} for w in split.warps],
    )
    assert result.converged, result.reason
    cross = 0
    for seam, report in zip(result.seams, result.seam_reports, strict=True):
        a, b = report.length_first_after, report.length_second_after
        assert abs(a - b) <= 1e-9 * a
        cross += split.strip_of[seam.first] == split.strip_of[seam.second]
    assert cross == len(plan.panels)
    points = np.vstack([np.unique(p.mesh.points, axis=0) for p in split.panels])
    _, shared = np.unique(points.round(9), axis=0, return_counts=True)
    assert shared.max() <= 3


def test_vares_cut_lays_the_pieces_of_the_half_wave_on_a_half_metre_roll(tmp_path):
    """``vares cut`` of half of compas-FoFin's wave (y ≥ 5 m: one valley, one ridge) at a 0.5 m
    roll: whole strips do not get narrower (exit 2 with ``--cross-seams never``); by default
    some are cut in two, and every piece is patterned (seams matched, each within 1 % of its
    line), fits the roll and lies on it (nest.dxf: one seam outline a piece, none overlapping,
    all within the roll); cut.json, structure.json and the report say how many were cut."""
    wave = read_mesh(DATA / "fofin_wave.obj")
    quads = wave.cells["quad"]
    half = quads[wave.points[quads].mean(axis=1)[:, 1] > 5.0]
    used = np.unique(half)
    index = np.full(wave.num_points, -1)
    index[used] = np.arange(used.size)
    source = tmp_path / "half_wave.obj"
    meshio.write(source, meshio.Mesh(wave.points[used], [("quad", index[half])]))
    args = [
        "cut", source, "--roll-width", 0.5, "--units", "m", "--fabric", "pes-pvc-type-2",
        "--prestress", "2,1.5", "--allowance", 20, "--edge-type", "cable",
        "--cable-allowance", 80, "--nest-time", 2,
    ]  # fmt: skip
    refused = run(*args, "--cross-seams", "never", "-o", tmp_path / "whole", "-q")
    assert refused.exit_code == 2
    assert "do not get narrower with their number" in error_line(refused)
    out = tmp_path / "pieces"
    result = run(*args, "-o", out, "--report")
    assert result.exit_code == 0, result.stderr
    details = json.loads((out / "structure.json").read_text())["cutting"]
    cross = details["cross_seams"]
    assert cross["strips_cut"] >= 1 and cross["pieces_each"] == 2
    assert any("cut across into 2 pieces" in note for note in details["notes"])
    assert details["nest"] is not None and details["widest_pattern_per_round"][-1] <= 0.5
    for line in details["seam_lines"]:
        assert abs(line["excess"]) < 0.01
    data = json.loads((out / "cut.json").read_text())
    panels = data["panels"]
    assert sum(p["name"][-1] in "ab" for p in panels) == 2 * cross["strips_cut"]
    assert sum(p["area"] for p in panels) == pytest.approx(details["panels_area"], rel=1e-12)
    for seam in data["seams"]:
        a, b = seam["length_2d"]
        assert abs(a - b) <= 1e-9 * a
    strips = len({p["name"].rstrip("ab") for p in panels})
    assert f"{len(panels)} pieces of {strips} strips" in (out / "report.html").read_text()
    space = ezdxf.readfile(out / "nest.dxf").modelspace()
    drawn = [Polygon(np.array(e.get_points("xy"))) for e in space.query("LWPOLYLINE[layer=='CUT']")]
    assert len(drawn) == len(panels)
    assert max(p.bounds[3] for p in drawn) <= 500 and min(p.bounds[1] for p in drawn) >= 0
    for k, first in enumerate(drawn):
        for second in drawn[k + 1 :]:
            assert not first.intersects(second)
