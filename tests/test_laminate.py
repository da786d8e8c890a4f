"""Laminates: job parsing, every ply draped, the ply-stack check, fibre angles for FE."""

import json
import tomllib

import meshio
import numpy as np
import pytest
from conftest import error_line, run

from vares.app.job import JobError
from vares.app.laminate_job import LaminateJob, load_laminate_job
from vares.app.laminate_outputs import orientation_tables, run_laminate
from vares.geometry.examples import cap_over_square
from vares.io.meshes import write_surface
from vares.io.orientations import read_abaqus_orientations, read_orientation_csv
from vares.materials import NonCrimpFabric
from vares.options import OptionsError
from vares.structures.laminate import Ply, PlyOptions, drape_laminate, ply_warp

NCF = NonCrimpFabric.from_moduli(1000.0, 1000.0, 1.0)
STACK = (0.0, 45.0, -45.0, 90.0)


def mould():
    """A spherical cap over a square (doubly curved, not axisymmetric), 200 triangles."""
    return cap_over_square(10.0, 12.0, 10)


JOB = """
[input]
mesh = "mould.obj"

[material]
law = "ncf"
A = [-250.0, 250.0]
B = [-250.0, 250.0]
C = [0.5]

[laminate]
spacing = 0.25

[output]
directory = "out"
"""


def job_text(angles=STACK, extra="") -> str:
    plies = "".join(
        f'\n[[ply]]\nname = "P{i}"\norientation = {a}\n' for i, a in enumerate(angles, start=1)
    )
    return JOB + extra + plies


@pytest.fixture(scope="module")
def laminate():
    plies = [Ply(PlyOptions(name=f"P{i}", orientation=a), NCF) for i, a in enumerate(STACK, 1)]
    return drape_laminate(mould(), plies, workers=1, spacing=0.25, compression_strain=2e-3)


# ------------------------------------------------------------------ the job


def parse(text: str) -> LaminateJob:
    return LaminateJob.from_dict(tomllib.loads(text), "job.toml")


def test_job_reads_plies_and_tables():
    job = parse(job_text(extra='[materials.glass]\nfabric = "glass-ptfe"\n'))
    assert [p.name for p in job.plies] == ["P1", "P2", "P3", "P4"]
    assert [p.orientation for p in job.plies] == list(STACK)
    assert job.laminate.spacing == 0.25
    assert job.job.input.mesh == "mould.obj"
    assert set(job.materials) == {"glass"}


def test_unknown_ply_key_names_the_closest():
    text = job_text().replace("orientation = 45.0", "orientaton = 45.0")
    with pytest.raises(JobError, match=r"\[\[ply\]\] 2 unknown key 'orientaton'.*'orientation'"):
        parse(text)


def test_unknown_laminate_key_and_table_name_the_closest():
    with pytest.raises(JobError, match=r"\[laminate\] unknown key 'spacng'.*'spacing'"):
        parse(job_text().replace("spacing = 0.25", "spacng = 0.25"))
    with pytest.raises(JobError, match=r"unknown table \[laminat\].*\[laminate\]"):
        parse(job_text().replace("[laminate]", "[laminat]"))


def test_job_refuses_bad_plies():
    with pytest.raises(JobError, match=r"needs \[\[ply\]\]"):
        parse(JOB)
    with pytest.raises(JobError, match=r"material 'glas' names no .*'glass'"):
        parse(
            job_text(extra='[materials.glass]\nfabric = "glass-ptfe"\n').replace(
                'name = "P2"', 'name = "P2"\nmaterial = "glas"'
            )
        )
    with pytest.raises(JobError, match="warp_direction is set by each ply"):
        parse(job_text(extra="[fibres]\nwarp_direction = [1.0, 0.0, 0.0]\n"))
    with pytest.raises(JobError, match=r"\[\[ply\]\] 3 region_value needs a region"):
        parse(job_text().replace('name = "P3"', 'name = "P3"\nregion_value = 2.0'))
    with pytest.raises(JobError, match=r"\[structure\] is not for a laminate"):
        parse(job_text(extra="[structure]\n"))
    with pytest.raises(JobError, match=r"\[output\] report is not used by a laminate job"):
        parse(job_text().replace('directory = "out"', 'directory = "out"\nreport = true'))


def test_laminate_refuses_repeated_names_and_drop_offs():
    ply = Ply(PlyOptions(name="A", drop_off=1), NCF)
    with pytest.raises(OptionsError, match="unique"):
        drape_laminate(mould(), [ply, ply])
    other = Ply(PlyOptions(name="B", drop_off=1), NCF)
    with pytest.raises(OptionsError, match="drop_off"):
        drape_laminate(mould(), [ply, other])


# ------------------------------------------------------------------ draping and pairs


def test_ply_warp_turns_the_reference_about_the_normal():
    mesh = mould()
    top = mesh.points[np.argmax(mesh.points[:, 2])]
    warp, normal = ply_warp(mesh, top, np.array([1.0, 0.0, 0.0]), 45.0)
    np.testing.assert_allclose(normal, [0.0, 0.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(warp, [np.sqrt(0.5), np.sqrt(0.5), 0.0], atol=1e-12)


def test_four_plies_converge_and_follow_their_orientations(laminate):
    assert laminate.converged
    assert laminate.labels == ["0°", "45°", "-45°", "90°"]
    mesh = laminate.mesh
    for drape in laminate.drapes:
        assert drape.pattern.converged
        assert abs(drape.pattern.warp_deviation) < 1e-6
        # the erected warp is a unit tangent vector of every cell, near the seed's direction
        normals = mesh.area_vectors() / mesh.cell_areas()[:, None]
        np.testing.assert_allclose(np.linalg.norm(drape.warp, axis=1), 1.0, atol=1e-12)
        assert np.abs(np.einsum("mi,mi->m", drape.warp, normals)).max() < 1e-12
        near = np.linalg.norm(mesh.points[mesh.cells["triangle"]].mean(axis=1)[:, :2], axis=1)
        assert (drape.warp[near < 1.0] @ drape.warp_direction > 0.99).all()
        # the kinematic net beside it agrees on the shear
        against = drape.summary()["kinematic_drape"]["against_pattern"]
        assert against["correlation"] > 0.95
        assert against["mean_abs_difference"] < 0.5


def test_pair_matrix_shows_the_seeds_dilemma(laminate):
    labels = laminate.labels
    warp = laminate.pair_matrix("warp_compressed_fraction")
    compressed = laminate.pair_matrix("compressed_area_fraction")
    largest = laminate.pair_matrix("largest_compression")
    deviation = laminate.pair_matrix("mean_deviation")
    i0, i45, im45, i90 = (labels.index(x) for x in ("0°", "45°", "-45°", "90°"))
    for blank in (i45, im45):
        for ply in (i0, i90):
            # the ±45° blank used for a 0/90° ply puts the warp into compression
            assert warp[blank, ply] > 0.3
            assert largest[blank, ply] > 0.02
    for k in range(4):  # each ply on its own blank: yarns shortened by 0.1 % at most (locking)
        assert compressed[k, k] == 0.0
        assert largest[k, k] < 0.0015
        assert deviation[k, k] < 1e-9
    # the 0° blank's fill is where the 90° ply's warp goes (a balanced fabric)
    assert deviation[i0, i90] < 0.05


def test_plies_that_drape_alike_share_one_drape():
    """A symmetric stack's halves are draped once, also when a ply spells out the laminate's
    fabric kind or the locking angle it would take anyway."""
    alike = [
        PlyOptions(name="P1", orientation=0.0),
        PlyOptions(name="P2", orientation=45.0),
        PlyOptions(name="P3", orientation=45.0, fabric_kind="ncf-biaxial"),
        PlyOptions(name="P4", orientation=360.0, locking_angle=50.0),
        PlyOptions(name="P5", orientation=0.0, fabric_kind="woven-plain"),
    ]
    plies = [Ply(o, NCF) for o in alike]
    result = drape_laminate(mould(), plies, workers=1, kinematic=False)
    assert result.ply_drape == {"P1": "0°", "P2": "45°", "P3": "45°", "P4": "0°", "P5": "0° (2)"}
    assert result.drape("P5").locking_angle == 40.0


def test_a_region_ply_covers_its_cells_only():
    mesh = mould()
    centroids = mesh.points[mesh.cells["triangle"]].mean(axis=1)
    zone = (np.abs(centroids[:, 0]) < 3.0).astype(float)
    plies = [
        Ply(PlyOptions(name="full", orientation=0.0), NCF),
        Ply(PlyOptions(name="strip", orientation=0.0, region="zone", drop_off=1), NCF),
    ]
    result = drape_laminate(mesh, plies, cell_data={"zone": zone}, workers=1, kinematic=False)
    strip = result.drape("strip")
    assert strip.pattern.converged
    np.testing.assert_array_equal(strip.cells, np.flatnonzero(zone))
    assert np.isnan(strip.warp[zone == 0]).all() and np.isfinite(strip.warp[zone == 1]).all()
    assert not result.pairs["0°", "0° (2)"].checked
    with pytest.raises(OptionsError, match="names no cell field"):
        drape_laminate(mesh, plies, workers=1, kinematic=False)


# ------------------------------------------------------------------ outputs and command


@pytest.fixture(scope="module")
def job_folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("laminate")
    write_surface(folder / "mould.obj", mould())
    (folder / "job.toml").write_text(job_text(), encoding="utf-8")
    return folder


@pytest.fixture(scope="module")
def written(job_folder):
    job = load_laminate_job(job_folder / "job.toml")
    return run_laminate(job.with_output(job_folder / "api-out"), workers=1), job_folder / "api-out"


def test_orientation_table_reads_back_the_draped_directions(written):
    result, out = written
    tables = {t.name: t for t in orientation_tables(result)}
    for read in (read_abaqus_orientations(out / "orientations.inp"),):
        assert list(read) == ["P1", "P2", "P3", "P4"]
        for name, ply in read.items():
            drape = result.drape(name)
            np.testing.assert_array_equal(ply.elements, np.arange(1, result.mesh.num_cells + 1))
            np.testing.assert_allclose(ply.warp, drape.warp[ply.elements - 1], rtol=0, atol=1e-9)
            np.testing.assert_allclose(ply.fill, drape.fill[ply.elements - 1], rtol=0, atol=1e-9)
            np.testing.assert_allclose(ply.default_warp, drape.warp_direction, atol=1e-12)
    csv = read_orientation_csv(out / "orientations.csv")
    for name, ply in csv.items():
        drape = result.drape(name)
        np.testing.assert_allclose(ply.warp, drape.warp, rtol=0, atol=1e-9)
        np.testing.assert_allclose(ply.fill, drape.fill, rtol=0, atol=1e-9)
        np.testing.assert_allclose(ply.shear_angle, drape.shear_angle, rtol=0, atol=1e-9)
        np.testing.assert_array_equal(ply.elements, tables[name].elements)
    text = (out / "orientations.inp").read_text()
    assert text.count("*ORIENTATION, NAME=") == 4
    assert "*DISTRIBUTION, NAME=P2_DIST, LOCATION=ELEMENT, TABLE=P2_TABLE" in text


def test_vtu_has_cell_vectors_per_ply(written):
    result, out = written
    data = meshio.read(out / "laminate.vtu").cell_data
    for ply in ("P1", "P2", "P3", "P4"):
        drape = result.drape(ply)
        assert data[f"{ply}_warp"][0].shape == (result.mesh.num_cells, 3)
        np.testing.assert_allclose(data[f"{ply}_warp"][0], drape.warp, atol=1e-12)
        np.testing.assert_allclose(data[f"{ply}_fill"][0], drape.fill, atol=1e-12)
        np.testing.assert_allclose(data[f"{ply}_shear_angle"][0], drape.shear_angle, atol=1e-12)
        assert np.isfinite(data[f"{ply}_kinematic_warp"][0]).all()
    assert (out / "patterns" / "drape_-45deg.vtu").is_file()
    assert "| 45° |" in (out / "laminate.md").read_text()


def test_cli_runs_in_parallel_and_matches_the_api(job_folder, written):
    result, _ = written
    out = job_folder / "cli-out"
    done = run("laminate", job_folder / "job.toml", "-o", out, "--workers", "2")
    assert done.exit_code == 0, done.stderr
    assert "ply-stack check" in done.stderr
    data = json.loads((out / "laminate.json").read_text())
    assert data["converged"] and data["workers"] == 2
    np.testing.assert_allclose(
        data["pairs"]["warp_compressed_fraction"],
        result.pair_matrix("warp_compressed_fraction"),
        atol=1e-8,
    )
    again = run("laminate", job_folder / "job.toml", "-o", out, "-q")
    assert again.exit_code == 2 and "--force" in error_line(again)


def test_cli_names_the_closest_key(job_folder):
    bad = job_folder / "bad.toml"
    bad.write_text(job_text().replace("orientation = 90.0", "orientatoin = 90.0"))
    done = run("laminate", bad, "-o", job_folder / "bad-out")
    assert done.exit_code == 2
    assert "did you mean 'orientation'" in error_line(done)


def test_a_ply_with_its_own_seed_is_draped_from_there():
    mesh = mould()
    seed = mesh.points[np.argmin(np.linalg.norm(mesh.points - [2.0, 1.0, 0.0], axis=1))]
    plies = [
        Ply(PlyOptions(name="top", orientation=30.0), NCF),
        Ply(PlyOptions(name="side", orientation=30.0, seed=tuple(seed)), NCF),
    ]
    result = drape_laminate(mesh, plies, workers=1, kinematic=False)
    assert result.labels == ["30°", "30° (2)"]
    side = result.drape("side")
    np.testing.assert_allclose(side.seed, seed)
    warp, normal = ply_warp(mesh, seed, np.array([1.0, 0.0, 0.0]), 30.0)
    np.testing.assert_allclose(side.warp_direction, warp)
    assert abs(warp @ normal) < 1e-12 and normal[2] < 0.99  # the cap's slope there
    assert result.converged


def test_a_ply_seed_off_the_mould_is_refused():
    from vares.geometry.drape import DrapeError

    mesh = mould()
    top = mesh.points[np.argmax(mesh.points[:, 2])]
    above = tuple(top + np.array([0, 0, 50.0]))  # 50 above the cap (10 wide)
    plies = [Ply(PlyOptions(name="P1", orientation=0.0, seed=above), NCF)]
    with pytest.raises(DrapeError, match=r"ply 'P1': the seed .* is not on the mould"):
        drape_laminate(mesh, plies, workers=1, kinematic=False)
    with pytest.raises(DrapeError, match=r"the laminate: the seed .* is not on the mould"):
        drape_laminate(mesh, [Ply(PlyOptions(name="P1"), NCF)], seed=tuple(top + 50.0),
                       workers=1, kinematic=False)  # fmt: skip


def test_abaqus_names_are_labels_and_unique():
    from vares.io.orientations import abaqus_name

    assert abaqus_name("P1") == "P1"
    assert abaqus_name("0° ply") == "PLY_0__PLY"
    assert abaqus_name("p 1", ["P_1"]) == "P_1_2"


def test_the_shipped_example(tmp_path):
    from pathlib import Path

    job = load_laminate_job(Path(__file__).parents[1] / "examples" / "laminate" / "laminate.toml")
    assert [p.orientation for p in job.plies] == [0.0, 45.0, -45.0, 90.0, 90.0, -45.0, 45.0, 0.0]
    result = run_laminate(job.with_output(tmp_path / "out"), workers=1)
    assert result.converged and result.labels == ["0°", "45°", "-45°", "90°"]
    warp = result.pair_matrix("warp_compressed_fraction")
    largest = result.pair_matrix("largest_compression")
    for blank in (1, 2):  # ±45° blanks used for 0° and 90° plies
        for ply in (0, 3):
            assert warp[blank, ply] > 0.4 and largest[blank, ply] > 0.04
    assert np.diag(largest).max() < 0.002
    read = read_abaqus_orientations(tmp_path / "out" / "orientations.inp")
    assert len(read) == 8
    for name, ply in read.items():
        drape = result.drape(name)
        np.testing.assert_allclose(ply.warp, drape.warp[ply.elements - 1], rtol=0, atol=1e-9)
        np.testing.assert_allclose(ply.fill, drape.fill[ply.elements - 1], rtol=0, atol=1e-9)


def test_a_job_takes_a_region_from_the_moulds_cell_data(tmp_path):
    mesh = mould()
    centroids = mesh.points[mesh.cells["triangle"]].mean(axis=1)
    zone = np.where(centroids[:, 0] > 1.0, 2.0, 1.0)
    write_surface(tmp_path / "mould.vtu", mesh, None, {"zone": zone})
    text = job_text((0.0, 90.0)).replace('"mould.obj"', '"mould.vtu"')
    text = text.replace(
        'name = "P2"', 'name = "P2"\nregion = "zone"\nregion_value = 2.0\ndrop_off = 1'
    )
    (tmp_path / "job.toml").write_text(text)
    result = run_laminate(load_laminate_job(tmp_path / "job.toml"), workers=1)
    patch = result.drape("P2")
    assert result.converged
    np.testing.assert_array_equal(patch.cells, np.flatnonzero(zone == 2.0))
    # the seed is the region's node nearest the region's centroid (the mould's top is outside)
    region = mesh.points[patch.nodes]
    assert np.linalg.norm(region - patch.seed, axis=1).min() == 0.0
    nearest = region[np.argmin(np.linalg.norm(region - region.mean(axis=0), axis=1))]
    np.testing.assert_array_equal(patch.seed, nearest)
    assert (
        patch.kinematic is not None and np.isfinite(patch.kinematic_shear_angle[patch.cells]).all()
    )
    assert not result.pairs["0°", "90°"].checked
    assert np.isnan(result.pair_matrix("warp_compressed_fraction")[0, 1])
    data = meshio.read(tmp_path / "out" / "laminate.vtu").cell_data
    assert np.isnan(data["P2_warp"][0][zone == 1.0]).all()
    table = read_abaqus_orientations(tmp_path / "out" / "orientations.inp")["P2"]
    np.testing.assert_array_equal(table.elements, np.flatnonzero(zone == 2.0) + 1)
    summary = json.loads((tmp_path / "out" / "laminate.json").read_text())
    assert summary["plies"][1]["drop_off"] == 1 and summary["plies"][1]["region"] == "zone"
    assert summary["pairs"]["warp_compressed_fraction"][0][1] is None


def test_the_table_can_hold_the_kinematic_directions(written, tmp_path):
    from dataclasses import replace

    from vares.io.orientations import write_abaqus_orientations

    result, _ = written
    options = result.laminate.options.replace(fe_directions="kinematic")
    kinematic = replace(result, laminate=replace(result.laminate, options=options))
    write_abaqus_orientations(tmp_path / "k.inp", orientation_tables(kinematic))
    for name, ply in read_abaqus_orientations(tmp_path / "k.inp").items():
        drape = result.drape(name)
        rows = ply.elements - 1
        assert len(rows) > 0.9 * result.mesh.num_cells
        np.testing.assert_allclose(ply.warp, drape.kinematic_warp[rows], rtol=0, atol=1e-9)
        np.testing.assert_allclose(ply.fill, drape.kinematic_fill[rows], rtol=0, atol=1e-9)
    with pytest.raises(OptionsError, match="fe_directions"):
        options.replace(kinematic=False)
