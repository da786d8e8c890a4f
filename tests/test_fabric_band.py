"""The scatter of a fabric's compensation values carried into a structure's patterns (seam
lengths, dimensions, erected prestress), and the fabric's reports."""

import json
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from conftest import error_line, run

import vares
from vares.analysis.scatter import ScatterOptions, compensation_samples
from vares.app.fabric_band import fabric_band, prestress_figures
from vares.geometry.examples import STRUCTURE_EXAMPLES
from vares.materials import MaterialError
from vares.materials.biaxial_model import ECRModel, compensation_protocol, simulate
from vares.materials.compensation_law import strains_per_cycle
from vares.materials.fabric_file import ConstantScatter
from vares.materials.presets import file_fabric, load_presets
from vares.structures.matching import solve_structure
from vares.structures.panels import split_panels

SHIPPED = Path(__file__).parent.parent / "examples" / "biaxial"
SETTINGS = {"warp_direction": (1.0, 0.0, 0.0)}


@pytest.fixture(scope="module")
def strips():
    """Three strips of a hyperbolic paraboloid: two seams."""
    mesh, ids = STRUCTURE_EXAMPLES["hypar-strips"](strips=3, n=12)
    return split_panels(mesh, ids)


@pytest.fixture(scope="module")
def batch():
    return file_fabric(SHIPPED / "pes-batch-42.toml")


def scaled(preset, factor):
    """The fabric with its compensation values' scatter times ``factor``."""
    c = preset.compensation
    return replace(
        preset,
        compensation=replace(c, warp_std=factor * c.warp_std, fill_std=factor * c.fill_std),
    )


def seams(band):
    return [n for n in band.band.names if n.startswith("seam ")]


def test_zero_scatter_gives_zero_spread_exactly(strips, batch):
    band = fabric_band(
        strips, scaled(batch, 0.0), scatter=ScatterOptions(samples=3, sigmas=2.0), **SETTINGS
    )
    assert len(seams(band)) == 2
    for name in band.band.names:
        assert band.band.samples[name] == (band.band.nominal[name],) * 3, name
        assert band.band.spread(name) == 0.0


def test_seam_band_holds_the_nominal_and_grows_with_the_scatter(strips, batch):
    """The seams' nominal lengths lie within the reported ± 2 std of the samples' mean; twice
    the scatter of the compensation values (the same draws scaled) doubles the spread, to first
    order."""
    options = ScatterOptions(samples=6, sigmas=2.0, seed=3)
    one = fabric_band(strips, batch, scatter=options, erected=False, **SETTINGS)
    two = fabric_band(strips, scaled(batch, 2.0), scatter=options, erected=False, **SETTINGS)
    for name in seams(one):
        values = np.asarray(one.band.samples[name])
        assert one.band.spread(name) > 1e-5 * one.band.nominal[name]
        assert abs(values.mean() - one.band.nominal[name]) <= one.band.spread(name)
        assert two.band.spread(name) / one.band.spread(name) == pytest.approx(2.0, rel=0.05)
    # the samples are the fabric's: the same seed draws the same values, scaled about the mean
    c = batch.compensation
    drawn = np.asarray(compensation_samples(batch, 6, 3))
    cases = [np.array([[s["warp"], s["fill"]] for s in b.cases]) for b in (one, two)]
    assert np.array_equal(cases[0], drawn)
    assert np.allclose(cases[1] - [c.warp, c.fill], 2 * (drawn - [c.warp, c.fill]))


def test_erected_prestress_of_the_nominal_case_is_the_plain_erection(strips, batch):
    band = fabric_band(strips, batch, scatter=ScatterOptions(samples=2), **SETTINGS)
    structure = solve_structure(
        strips, batch.material("measured"), prestress=batch.compensation.prestress, **SETTINGS
    )
    plain = prestress_figures(vares.erect(structure))
    for name, value in plain.items():
        assert band.band.nominal[name] == pytest.approx(value, rel=1e-12), name
    # a sample compensated more (a softer fabric at the prestress) is erected with less warp
    # prestress from the nominal patterns
    warp = np.array([s["warp"] for s in band.cases])
    stress = np.asarray(band.band.samples["prestress warp_mean"])
    order = np.argsort(warp)
    assert stress[order[0]] > stress[order[-1]]


def test_a_band_needs_measured_compensation_values(strips, batch):
    with pytest.raises(MaterialError, match="no measured compensation values"):
        fabric_band(strips, replace(batch, compensation=None), prestress=(2.0, 1.5), **SETTINGS)
    with pytest.raises(MaterialError, match="has no scatter of its constants"):
        constants = ScatterOptions(sampled="constants")
        fabric_band(strips, replace(batch, scatter=None), scatter=constants, **SETTINGS)


def test_band_of_the_fitted_constants(strips, batch):
    """Sampling E1, E2, nu12: the nominal case is the fitted law's pattern and its plain
    erection; zero scatter gives zero spread exactly; the file's scatter (read with the
    fabric, and taken by default) gives a band."""
    scatter = batch.scatter
    assert (scatter.E1, scatter.E2, scatter.specimens) == pytest.approx(
        (14.9603, 15.4456, 2), rel=1e-5
    )
    options = ScatterOptions(sampled="constants", samples=3, seed=2)
    zero = fabric_band(
        strips, batch, constants=ConstantScatter(0.0, 0.0, 0.0), scatter=options, **SETTINGS
    )
    assert all(zero.band.spread(n) == 0.0 for n in zero.band.names)
    law = batch.material("law")
    structure = solve_structure(strips, law, prestress=(2.0, 1.5), **SETTINGS)
    plain = prestress_figures(vares.erect(structure))
    for name, value in plain.items():
        assert zero.band.nominal[name] == pytest.approx(value, rel=1e-12), name
    band = fabric_band(strips, batch, scatter=options, **SETTINGS)
    assert band.band.nominal == zero.band.nominal
    assert all(band.band.spread(n) > 0 for n in band.band.names)
    assert [set(s) for s in band.cases] == [{"E1", "E2", "nu12"}] * 3
    assert band.to_dict()["constants_std"]["E1"] == scatter.E1


def test_the_scatter_table_is_read_with_the_fabric(tmp_path):
    """A fabric file's [NAME.scatter] is read, and checked, once with its fabric."""
    path = tmp_path / "f.toml"
    head = '[f]\nE1 = 600.0\nE2 = 450.0\nG12 = 20.0\nnu12 = 0.3\nsource = "test"\n'
    path.write_text(head + "[f.scatter]\nE1 = 2.0\nnu12 = 0.01\nspecimens = 3\n", encoding="utf-8")
    assert file_fabric(path).scatter == ConstantScatter(2.0, 0.0, 0.01, 3)
    path.write_text(head + '[f.scatter]\nE1 = "x"\n', encoding="utf-8")
    with pytest.raises(
        MaterialError, match=r"f.toml: \[f.scatter\]: E1, E2 and nu12 must be numbers"
    ):
        file_fabric(path)
    path.write_text(head + "[f.scatter]\nE1 = -1.0\n", encoding="utf-8")
    with pytest.raises(MaterialError, match=r"\[f.scatter\]: E1, E2 and nu12 must be numbers ≥ 0"):
        load_presets(path)
    path.write_text(head + "[f.scatter]\nspecimens = 0\n", encoding="utf-8")
    with pytest.raises(MaterialError, match="specimens must be a positive integer"):
        file_fabric(path)
    path.write_text(head + "scatter = 1.0\n", encoding="utf-8")
    with pytest.raises(MaterialError, match="scatter must be a table"):
        file_fabric(path)
    path.write_text(head, encoding="utf-8")
    assert file_fabric(path).scatter is None


def test_strains_per_cycle():
    """A linear elastic record is at ``C σ`` at the prestress after every cycle; the ECR model's
    ratchet and creep make the strain there grow from cycle to cycle."""
    linear = ECRModel(E_w=600.0, E_f=450.0, nu_wf=0.35, strain_noise=0.0)
    record = simulate(linear, compensation_protocol(prestress=(2.0, 1.5), design=(8.0, 6.0)))
    points = strains_per_cycle(record, (2.0, 1.5))
    assert [k for k, *_ in points] == list(range(6))
    expected = linear.compliance @ [2.0, 1.5]
    for _, warp, fill in points:
        assert (warp, fill) == pytest.approx(tuple(expected), rel=1e-12)
    creeping = replace(ECRModel.pes_pvc(), strain_noise=0.0, force_noise=0.0)
    warps = [
        w for _, w, _ in strains_per_cycle(simulate(creeping, compensation_protocol()), (2, 1.5))
    ]
    assert len(warps) == 6 and np.all(np.diff(warps) > 0)


def test_fabric_band_command_writes_summary_and_report(tmp_path):
    out = tmp_path / "band"
    args = (
        "fabric", "band", "--example", "hypar-strips", "--fabric", SHIPPED / "pes-batch-42.toml",
        "--warp-direction", "1,0,0", "--samples", "2", "-o", out,
    )  # fmt: skip
    result = run(*args)
    assert result.exit_code == 0, result.stderr
    summary = json.loads((out / "summary.json").read_text())
    names = list(summary["figures"])
    assert sum(n.startswith("seam ") for n in names) == 5  # six strips
    assert "prestress warp_mean" in names and len(summary["samples"]) == 2
    report = (out / "report.html").read_text()
    assert "pattern dimensions with their band" in report and "seam " in report
    again = run(*args)
    assert again.exit_code == 2 and "output exists" in error_line(again)
    bad = run(*args[:-2], "--samples", "0")
    assert bad.exit_code == 2 and "--samples" in error_line(bad)


def test_fabric_band_command_leaves_a_runs_folder_alone(tmp_path):
    """A run's folder keeps its own summary.json and report.html: the band, even with --force,
    is refused there (``vares erect`` and the report read the run's summary.json)."""
    out = tmp_path / "run"
    made = run("example", "hypar", "-o", out, "--report", "-q")
    assert made.exit_code == 0, made.stderr
    before = {n: (out / n).read_bytes() for n in ("summary.json", "report.html")}
    args = ("fabric", "band", "--example", "hypar", "--fabric", SHIPPED / "pes-batch-42.toml")
    refused = run(*args, "--samples", "2", "-o", out, "--force")
    assert refused.exit_code == 2 and "folder of a run" in error_line(refused)
    assert {n: (out / n).read_bytes() for n in before} == before


def test_fabric_band_command_writes_both_files_or_neither(tmp_path, monkeypatch):
    """A report that cannot be made leaves the folder's earlier summary.json as it was (the
    band's files are made before either is written)."""
    out = tmp_path / "band"
    args = ("fabric", "band", "--example", "hypar", "--fabric", SHIPPED / "pes-batch-42.toml")
    args += ("--samples", "2", "--no-erect", "-o", out, "--force")
    assert run(*args).exit_code == 0
    before = (out / "summary.json").read_bytes()

    def broken(*_):
        raise RuntimeError("no report")

    monkeypatch.setattr("vares.app.fabric_report.band_report", broken)
    failed = run(*args, "--seed", "1")
    assert failed.exit_code != 0 and "no report" in failed.stderr
    assert (out / "summary.json").read_bytes() == before


def test_fabric_fit_report_names_each_load_ratio(tmp_path):
    paths = sorted(SHIPPED.glob("pes-42-*"))
    report = tmp_path / "fit.html"
    result = run(
        "fabric", "fit", *paths, "--prestress", "2,1.5", "-o", tmp_path / "x.toml",
        "--report", report,
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr
    text = report.read_text()
    for specimen in ("PES-42-A", "PES-42-B"):
        caption = re.search(rf"{specimen}: measured and fitted per load ratio \(([^)]*)\)", text)
        assert caption is not None
        assert caption.group(1).split(", ") == ["1:1", "2:1", "1:2", "1:0", "0:1"]
    assert text.count("<img") == 8 and "compensation per cycle" in text
    wrong = run("fabric", "fit", *paths, "-o", tmp_path / "y.toml", "--report", tmp_path / "r.pdf")
    assert wrong.exit_code == 2 and "--report must end in .html" in error_line(wrong)


def test_samples_on_a_dask_scheduler_are_those_solved_here(strips, batch):
    distributed = pytest.importorskip("dask.distributed")
    options = ScatterOptions(samples=2, seed=1)
    here = fabric_band(strips, batch, scatter=options, erected=False, **SETTINGS)
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        there = fabric_band(
            strips,
            batch,
            scatter=options,
            erected=False,
            scheduler=cluster.scheduler_address,
            **SETTINGS,
        )
    assert there.band.samples == here.band.samples
