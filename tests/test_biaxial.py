"""Biaxial test records: reading, the fit of the constants, compensation values, fabric files."""

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from conftest import error_line, run

import vares
from vares.analysis import compensation_report
from vares.analysis.checks import pattern_warnings
from vares.geometry.examples import grid_cells
from vares.io.biaxial import BiaxialFileError, read_biaxial, write_biaxial
from vares.materials import MaterialError, OrthotropicStVenantKirchhoff, fabric
from vares.materials.biaxial import find_cycles
from vares.materials.biaxial_model import (
    ECRModel,
    compensation_protocol,
    msaj_protocol,
    simulate,
    specimen_batch,
)
from vares.materials.fitting import (
    NotInRecord,
    compensating_law,
    compensation_values,
    fit_elastic,
    fit_fabric,
    law_compensation,
)

LINEAR = ECRModel(E_w=600.0, E_f=450.0, nu_wf=0.35, strain_noise=5e-5)
TRUE = {"E_w": 600.0, "E_f": 450.0, "nu_wf": 0.35, "nu_fw": 0.35 * 450.0 / 600.0}


# ---- the fit -------------------------------------------------------------------------------
def test_fit_recovers_the_linear_constants_within_the_reported_uncertainty():
    """Noise only: every constant within 3 standard errors, and the standard errors are
    honest: over 12 records the RMS of (fit − true)/error is near 1."""
    z = []
    for seed in range(12):
        fit = fit_elastic(simulate(LINEAR, msaj_protocol(), seed=seed))
        for name in ("E_w", "E_f", "nu_wf", "nu_fw"):
            error = fit.standard_errors[name]
            assert abs(getattr(fit, name) - TRUE[name]) < 3 * error, (seed, name)
            z.append((getattr(fit, name) - TRUE[name]) / error)
        assert fit.standard_errors["E_w"] < 0.002 * TRUE["E_w"]  # the errors are small too
        assert [r.label for r in fit.residuals] == ["1:1", "2:1", "1:2", "1:0", "0:1"]
        for r in fit.residuals:  # the residual is the noise, on every ratio
            assert 0.7 * 5e-5 < r.rms_warp < 1.3 * 5e-5
            assert 0.7 * 5e-5 < r.rms_fill < 1.3 * 5e-5
        assert not fit.linear_is_poor
    assert 0.5 < np.sqrt(np.mean(np.square(z))) < 1.6


def test_fit_without_reciprocity_finds_both_poisson_ratios():
    fit = fit_elastic(simulate(LINEAR, msaj_protocol(), seed=4), reciprocal=False)
    assert not fit.reciprocal
    for name in ("E_w", "E_f", "nu_wf", "nu_fw"):
        assert abs(getattr(fit, name) - TRUE[name]) < 3 * fit.standard_errors[name], name


def test_fit_of_the_nonlinear_hysteretic_model_within_the_stated_tolerance():
    """The ECR model with stiffening yarns, creep and ratchet: the linear fit is a secant over
    the tested range (flagged as poor: the nonlinear response fits much better), and the
    nonlinear response's linear part recovers the model's constants to 2 % and its quadratic
    terms to 20 %."""
    model = ECRModel.pes_pvc()
    fit = fit_elastic(simulate(model, msaj_protocol(), seed=0))
    assert fit.linear_is_poor
    assert fit.E_w > 1.2 * model.E_w  # a secant of a stiffening yarn
    nl = fit.nonlinear
    assert nl["rms"] < 0.25 * fit.rms
    assert nl["E_w"] == pytest.approx(model.E_w, rel=0.02)
    assert nl["E_f"] == pytest.approx(model.E_f, rel=0.02)
    assert nl["nu_wf"] == pytest.approx(model.nu_wf, rel=0.02)
    assert nl["k_w"] == pytest.approx(model.k_w, rel=0.2)
    assert nl["k_f"] == pytest.approx(model.k_f, rel=0.2)
    # the nonlinear backbone alone (no creep, no ratchet) is recovered within its errors
    backbone = fit_elastic(simulate(ECRModel(k_w=-2e-5, k_f=-3e-5), msaj_protocol(), seed=1))
    for key, true in (("k_w", -2e-5), ("k_f", -3e-5)):
        assert abs(backbone.nonlinear[key] - true) < 3 * backbone.nonlinear[f"{key}_error"]


def test_batch_mean_recovers_the_batch_constants_within_its_standard_error():
    records, models = specimen_batch(LINEAR, msaj_protocol(cycles=2), specimens=6, scatter=0.03)
    fitted = fit_fabric(records, name="batch", G12=30.0, G12_source="given")
    summary = fitted.constants
    assert summary.specimens == 6
    for name, attribute in (("E_w", "E_w"), ("E_f", "E_f"), ("nu_wf", "nu_wf")):
        true_specimens = np.array([getattr(m, attribute) for m in models])
        # each specimen's own constants, and the batch's mean within 3 standard errors
        np.testing.assert_allclose(summary.values[name], true_specimens, rtol=0.004)
        assert abs(summary.mean[name] - getattr(LINEAR, attribute)) < 3 * summary.standard_error(
            name
        )
        assert summary.std[name] == pytest.approx(np.std(true_specimens, ddof=1), rel=0.1)


def test_cycles_found_from_the_force_signal_match_the_stage_column():
    record = simulate(ECRModel.pes_pvc(), msaj_protocol(), seed=2)
    with_column = find_cycles(record)
    without = find_cycles(replace(record, stage=None))
    assert [(c.stage, c.number, c.label) for c in with_column] == [
        (c.stage, c.number, c.label) for c in without
    ]
    assert len(without) == 15 and {c.number for c in without} == {1, 2, 3}
    assert [c.label for c in without[::3]] == ["1:1", "2:1", "1:2", "1:0", "0:1"]


def test_a_record_with_one_load_ratio_cannot_give_constants():
    record = simulate(LINEAR, compensation_protocol(), seed=0)
    with pytest.raises(NotInRecord, match="at least two load ratios"):
        fit_elastic(record)


# ---- compensation values -------------------------------------------------------------------
def test_compensation_values_of_a_linear_elastic_record_are_the_closed_form():
    """Without creep, ratchet or noise the strains at the prestress are ``C σ``."""
    model = replace(LINEAR, strain_noise=0.0)
    record = simulate(model, compensation_protocol(prestress=(2.0, 1.5), design=(8.0, 6.0)))
    values = compensation_values(record, (2.0, 1.5))
    expected = model.compliance @ [2.0, 1.5]
    assert values.warp == pytest.approx(2.0 / 600.0 - 0.35 * 1.5 / 600.0, rel=1e-12)
    assert (values.warp, values.fill) == pytest.approx(tuple(expected), rel=1e-12)
    assert values.time == record.time[-1] and values.samples == 11
    # with noise: within the noise of the mean of the samples read
    noisy = compensation_values(simulate(LINEAR, compensation_protocol(), seed=5), (2.0, 1.5))
    bound = 4 * 5e-5 / np.sqrt(noisy.samples)
    assert abs(noisy.warp - expected[0]) < bound and abs(noisy.fill - expected[1]) < bound


def test_creep_and_ratchet_raise_the_compensation_above_the_elastic_strain():
    model = ECRModel.pes_pvc(strain_noise=0.0, force_noise=0.0)
    values = compensation_values(simulate(model, compensation_protocol()), (2.0, 1.5))
    elastic = model.elastic_strain(np.array([2.0, 1.5]))
    assert values.warp > 2 * elastic[0] and values.fill > 2 * elastic[1]


def test_compensation_needs_a_hold_at_the_prestress():
    record = simulate(LINEAR, msaj_protocol(), seed=0)
    with pytest.raises(NotInRecord, match=r"no hold at the prestress 2/1\.5 kN/m"):
        compensation_values(record, (2.0, 1.5))


def test_a_pattern_compensated_by_the_measured_values():
    """The law through the measured values gives a flat panel exactly those strains: its
    VaReS pattern under the prestress is shorter by them (1 − 1/(1 + ε))."""
    warp, fill, prestress = 0.0081, 0.0066, (2.0, 1.5)
    law = compensating_law(warp, fill, prestress, nu12=0.35, G12=30.0)
    assert law.nu12 == 0.35 and law.G12 == 30.0
    assert law_compensation(law, prestress) == pytest.approx((warp, fill), rel=1e-12)
    x, y = np.meshgrid(np.linspace(0, 3.0, 7), np.linspace(0, 2.0, 5))
    mesh = vares.SurfaceMesh(
        np.column_stack([x.ravel(), y.ravel(), 0 * x.ravel()]), grid_cells(7, 5, "quad")
    )
    result = vares.solve(mesh, law, prestress=prestress, warp_direction=(1, 0, 0))
    report = compensation_report(result)
    assert report.warp.compensation_mean == pytest.approx(100 * warp / (1 + warp), rel=1e-7)
    assert report.fill.compensation_mean == pytest.approx(100 * fill / (1 + fill), rel=1e-7)
    # and the erection says so: erected, the pattern is stretched by exactly 1 + ε onto the
    # design (an affine map from the pattern to the erected panel, the shape not moved)
    erected = vares.erect(result)
    assert erected.converged and erected.deviation()["max"] < 1e-12
    pattern = np.column_stack([result.material_coordinates, np.ones(mesh.num_points)])
    stretch, *_ = np.linalg.lstsq(pattern, erected.erected_points[:, :2], rcond=None)
    np.testing.assert_allclose(stretch[:2].T, np.diag([1 + warp, 1 + fill]), atol=1e-12)
    # the fitted law of the same fabric predicts its own compensation, also exactly
    fitted = OrthotropicStVenantKirchhoff(600.0, 450.0, 30.0, 0.35)
    predicted = law_compensation(fitted, prestress)
    report = compensation_report(
        vares.solve(mesh, fitted, prestress=prestress, warp_direction=(1, 0, 0))
    )
    assert report.warp.compensation_mean == pytest.approx(
        100 * predicted[0] / (1 + predicted[0]), rel=1e-7
    )
    with pytest.raises(MaterialError, match="positive strains"):
        compensating_law(-0.001, fill, prestress, 0.35, 30.0)
    # the law holds the measured values at their prestress only: elsewhere a pattern is warned
    assert not any("measured at" in w for w in pattern_warnings(result, None))
    other = vares.solve(mesh, law, prestress=(3.0, 2.0), warp_direction=(1, 0, 0))
    (note,) = [w for w in pattern_warnings(other, None) if "measured at" in w]
    assert "measured at the prestress 2/1.5; this pattern's is 3/2" in note


# ---- reading files -------------------------------------------------------------------------
DE_LAB = (
    "\ufeffProbe;PES-42-A\r\n"
    "Datum;30.11.2026\r\n"
    "\r\n"
    "Zeit [s];Stufe;Kraft Kette [N/5cm];Kraft Schuss [N/5cm];"
    "Dehnung Kette [%];Dehnung Schuss [%]\r\n"
    "0,0;1;0,00;0,00;0,0000;0,0000\r\n"
    "12,5;1;100,0;50,0;1,5000;0,8000\r\n"
    "25,0;1;200,0;100,0;3,0000;1,6000\r\n"
    "37,5;2;150,5;75,25;2,2500;1,2000\r\n"
)


def test_reader_semicolons_decimal_commas_bom_n_per_5cm_and_percent(tmp_path):
    path = tmp_path / "pes-42-a.csv"
    path.write_bytes(DE_LAB.encode("utf-8"))
    record = read_biaxial(path)
    assert record.name == "PES-42-A" and record.metadata["datum"] == "30.11.2026"
    np.testing.assert_allclose(record.time, [0.0, 12.5, 25.0, 37.5])
    # 100 N per 5 cm = 2 kN/m; 1.5 % = 0.015
    np.testing.assert_allclose(record.force, [[0, 0], [2.0, 1.0], [4.0, 2.0], [3.01, 1.505]])
    np.testing.assert_allclose(
        record.strain, [[0, 0], [0.015, 0.008], [0.03, 0.016], [0.0225, 0.012]]
    )
    np.testing.assert_array_equal(record.stage, [1, 1, 1, 2])
    # integers first, decimal commas later: still decimal commas
    path.write_text(DE_LAB.replace("0,0;1;0,00;0,00;0,0000;0,0000", "0;1;0;0;0;0"), "utf-8")
    np.testing.assert_allclose(read_biaxial(path).force[1:, 0], [2.0, 4.0, 3.01])


def test_reader_tabs_units_line_and_permille(tmp_path):
    path = tmp_path / "b.tsv"
    path.write_text(
        "# specimen: B\n"
        "time\twarp load\tfill load\twarp strain\tfill strain\n"
        "min\tN/mm\tkN/m\t‰\tmm/mm\n"
        "0.5\t1.0\t2.0\t3.0\t0.004\n"
        "1.0\t2.0\t3.0\t4.0\t0.005\n"
        "1.5\t3.0\t4.0\t5.0\t0.006\n",
        encoding="cp1252",
    )
    record = read_biaxial(path)
    assert record.name == "B" and record.stage is None
    np.testing.assert_allclose(record.time, [30.0, 60.0, 90.0])
    np.testing.assert_allclose(record.force[:, 0], [1.0, 2.0, 3.0])
    np.testing.assert_allclose(record.strain[:, 0], [0.003, 0.004, 0.005])


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("12,5;1;100,0", "12,5;1;abc"), "line 6, column 3 (warp force): 'abc' is not a number"),
        (
            ("25,0;1;200,0;100,0;3,0000;1,6000", "25,0;1;200,0;100,0"),
            "line 7: 4 fields, the header (line 4) has 6",
        ),
        (
            ("[N/5cm];Kraft Schuss", "[kg];Kraft Schuss"),
            "line 4, column 3 (warp force): unknown unit 'kg'",
        ),
        (("Dehnung Schuss [%]", "Temperatur [C]"), "line 4: the header names no fill strain"),
        (
            ("Zeit [s];Stufe;Kraft Kette", "Probe;Stufe;Gewicht"),
            "the header names no time "
            "and no warp force column (it has: fill force, warp strain, fill strain)",
        ),
        (("37,5;2", "20,0;2"), "line 8, column 1 (time): time does not increase"),
    ],
)
def test_a_malformed_file_gives_one_clear_error(tmp_path, change, message):
    path = tmp_path / "bad.csv"
    path.write_text(DE_LAB.replace(*change), encoding="utf-8")
    with pytest.raises(BiaxialFileError) as caught:
        read_biaxial(path)
    text = str(caught.value)
    assert "\n" not in text and text.startswith(str(path)) and message in text


@pytest.mark.parametrize("layout", ["de-lab", "tsv"])
def test_written_layouts_read_back(tmp_path, layout):
    record = simulate(ECRModel.pes_pvc(), msaj_protocol(cycles=2), sample_interval=2.0, seed=3)
    path = write_biaxial(record, tmp_path / f"r.{'csv' if layout == 'de-lab' else 'tsv'}", layout)
    back = read_biaxial(path)
    np.testing.assert_allclose(
        back.force, record.force, atol=0.0101 if layout == "de-lab" else 1e-4
    )
    np.testing.assert_allclose(back.strain, record.strain, atol=1e-6)
    assert (back.stage is not None) == (layout == "de-lab")
    assert fit_elastic(back).E_w == pytest.approx(fit_elastic(record).E_w, rel=1e-3)


# ---- fabric files and the command line -----------------------------------------------------
def _records(folder):
    model = ECRModel.pes_pvc()
    paths = []
    stiff, _ = specimen_batch(model, msaj_protocol(cycles=2, rate=1.0), specimens=2)
    for i, record in enumerate(stiff):
        paths.append(
            write_biaxial(
                replace(record, name=f"msaj-{i + 1}"), folder / f"msaj-{i + 1}.csv", "de-lab"
            )
        )
    held, _ = specimen_batch(model, compensation_protocol(cycles=2, last_hold=120), 2, seed=5)
    for i, record in enumerate(held):
        paths.append(
            write_biaxial(
                replace(record, name=f"comp-{i + 1}"), folder / f"comp-{i + 1}.tsv", "tsv"
            )
        )
    return paths


def test_fabric_fit_then_pattern_with_the_fabric_file(tmp_path):
    paths = _records(tmp_path)
    target, figures = tmp_path / "pes-batch-42.toml", tmp_path / "figures"
    fit = ("fabric", "fit", *paths, "--prestress", "2,1.5", "-o", target, "--plots", figures)
    result = run(*fit)
    assert result.exit_code == 0, result.stderr
    assert "compensation values at 2/1.5 kN/m" in result.stderr
    names = sorted(p.name for p in figures.iterdir())
    assert names == [
        "comp-1_compensation.png",
        "comp-2_compensation.png",
        "msaj-1_loops.png",
        "msaj-2_loops.png",
        "residuals.png",
    ]
    assert all((figures / n).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for n in names)
    result = run(*fit)  # nothing is overwritten without --force
    assert result.exit_code == 2 and "output exists" in error_line(result)
    preset = fabric(str(target))
    assert preset.name == "pes-batch-42" and preset.compensate_by == "measured"
    assert "not measured by biaxial tests" in preset.source and "msaj-1.csv" in preset.source
    measured = preset.compensation
    own = [compensation_values(read_biaxial(p), (2.0, 1.5)) for p in paths[2:]]
    assert measured.prestress == (2.0, 1.5)
    assert measured.warp == pytest.approx(np.mean([c.warp for c in own]), rel=1e-12)
    assert measured.fill_std == pytest.approx(np.std([c.fill for c in own], ddof=1), rel=1e-12)
    assert measured.warp > 0.004  # creep and permanent set: twice the elastic strain
    import tomllib

    data = tomllib.loads(target.read_text(encoding="utf-8"))["pes-batch-42"]
    assert data["scatter"]["specimens"] == 2 and data["scatter"]["E1"] > 0
    assert len(data["specimens"]) == 4 and data["fit"]["ratios"][0] == "1:1"
    # the file wherever a preset goes: a pattern compensated by the measured values …
    out = tmp_path / "sail"
    flags = ("--prestress", "2,1.5", "--warp-direction", "1,1,0", "-q")
    result = run("example", "sail", "-o", out, "--fabric", target, *flags, "--report")
    assert result.exit_code == 0, result.stderr
    report = (out / "report.html").read_text(encoding="utf-8")
    assert "measured compensation at 2 / 1.5" in report and "msaj-1.csv" in report
    assert measured.specimens == 2 and "% (mean ± std)" in report
    summary = json.loads((out / "summary.json").read_text())
    warp = summary["compensation"]["warp"]["compensation_mean"]
    assert warp == pytest.approx(100 * measured.warp / (1 + measured.warp), rel=0.02)
    job = (out / "job.toml").read_text()
    assert 'presets = "../pes-batch-42.toml"' in job
    # … or by the fitted law, much less (it knows neither creep nor permanent set)
    result = run(
        "example",
        "sail",
        "-o",
        tmp_path / "law",
        "--fabric",
        target,
        "--compensate-by",
        "law",
        *flags,
    )
    assert result.exit_code == 0, result.stderr
    law = json.loads((tmp_path / "law" / "summary.json").read_text())
    assert law["material"]["E1"] == pytest.approx(preset.E1)
    assert law["compensation"]["warp"]["compensation_mean"] < 0.5 * warp
    # a job file names it the same way
    (tmp_path / "job.toml").write_text(
        '[input]\nexample = "hypar"\n\n[material]\nfabric = "pes-batch-42.toml"\n'
        'compensate_by = "law"\n\n[output]\ndirectory = "hyp"\n',
        encoding="utf-8",
    )
    result = run("run", tmp_path / "job.toml", "-q")
    assert result.exit_code == 0, result.stderr
    hyp = json.loads((tmp_path / "hyp" / "summary.json").read_text())
    assert hyp["material"]["E1"] == pytest.approx(preset.E1)


def test_fabric_fit_of_a_malformed_file_is_one_error_line(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text(DE_LAB.replace("12,5;1;100,0", "12,5;1;abc"), encoding="utf-8")
    result = run("fabric", "fit", path, "-o", tmp_path / "x.toml")
    assert result.exit_code == 2
    assert "line 6, column 3 (warp force)" in error_line(result)
    assert not (tmp_path / "x.toml").exists()


def test_fabric_file_errors(tmp_path):
    path = tmp_path / "f.toml"
    path.write_text(
        '[f]\nE1 = 800.0\nE2 = 600.0\nG12 = 30.0\nnu12 = 0.3\nsource = "test"\n'
        'compensate_by = "measured"\n',
        encoding="utf-8",
    )
    with pytest.raises(MaterialError, match="needs a compensation table"):
        fabric(str(path))
    path.write_text(
        '[f]\nE1 = 800.0\nE2 = 600.0\nG12 = 30.0\nnu12 = 0.3\nsource = "test"\n', encoding="utf-8"
    )
    with pytest.raises(MaterialError, match="no measured compensation values"):
        fabric(str(path)).material("measured")
    result = run("example", "hypar", "-o", tmp_path / "o", "--compensate-by", "law")
    assert result.exit_code == 2 and "needs a fabric" in error_line(result)


# ---- the scatter carried into a pattern -----------------------------------------------------
def test_pattern_band_of_a_flat_panel_is_the_closed_form(tmp_path):
    """A flat 3 × 2 panel, compensation 0.8 ± 0.02 % warp and 0.6 ± 0.03 % fill: the pattern's
    length is 3/(1 + ε_w) at the mean and at the band's ends, its width 2/(1 + ε_f)."""
    from vares.analysis.scatter import pattern_band

    path = tmp_path / "f.toml"
    path.write_text(
        '[f]\nE1 = 800.0\nE2 = 600.0\nG12 = 30.0\nnu12 = 0.3\nsource = "test"\n\n'
        "[f.compensation]\nprestress = [2.0, 1.5]\nwarp = 0.008\nfill = 0.006\n"
        "warp_std = 0.0002\nfill_std = 0.0003\n",
        encoding="utf-8",
    )
    x, y = np.meshgrid(np.linspace(0, 3.0, 7), np.linspace(0, 2.0, 5))
    mesh = vares.SurfaceMesh(
        np.column_stack([x.ravel(), y.ravel(), 0 * x.ravel()]), grid_cells(7, 5, "quad")
    )
    band = pattern_band(mesh, fabric(str(path)), warp_direction=(1, 0, 0))
    assert band.mean["warp_length"] == pytest.approx(3.0 / 1.008, rel=1e-8)
    assert band.low["warp_length"] == pytest.approx(3.0 / 1.0082, rel=1e-8)
    assert band.high["warp_length"] == pytest.approx(3.0 / 1.0078, rel=1e-8)
    assert band.low["fill_length"] == pytest.approx(2.0 / 1.0063, rel=1e-8)
    assert band.high["boundary_length"] == pytest.approx(2 * (3 / 1.0078 + 2 / 1.0057), rel=1e-8)
    corner = np.hypot(1.5 * (1 / 1.0078 - 1 / 1.008), 1.0 * (1 / 1.0057 - 1 / 1.006))
    assert band.node_deviation == pytest.approx(corner, rel=1e-5)


def test_fabric_band_command():
    shipped = Path(__file__).parent.parent / "examples" / "biaxial" / "pes-batch-42.toml"
    result = run("fabric", "band", "--example", "hypar", "--fabric", shipped, "--samples", "2")
    assert result.exit_code == 0, result.stderr
    assert "warp_length" in result.stderr and "prestress warp_mean" in result.stderr
    result = run("fabric", "band", "--fabric", shipped)
    assert result.exit_code == 2 and "mesh files or --example" in error_line(result)


def test_fabric_band_needs_the_scatter_of_the_compensation_values(tmp_path):
    """A fabric file of one compensation record has no scatter (std 0): its band would be the
    mean pattern over and over, presented as a band of zero width; it is refused instead."""
    shipped = Path(__file__).parent.parent / "examples" / "biaxial"
    single = tmp_path / "single.toml"
    result = run(
        "fabric", "fit", shipped / "pes-42-A_msaj.csv", shipped / "pes-42-C_compensation.csv",
        "--prestress", "2,1.5", "-o", single,
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr
    assert "come from one specimen: their scatter is unknown" in result.stderr
    refused = run("fabric", "band", "--example", "hypar", "--fabric", single)
    assert refused.exit_code == 2, refused.stderr
    assert "no scatter" in error_line(refused) and "one specimen" in error_line(refused)
    out = tmp_path / "hypar"
    flags = ("--prestress", "2,1.5", "--report", "-q")
    assert run("example", "hypar", "-o", out, "--fabric", single, *flags).exit_code == 0
    assert "% (one specimen: no scatter)" in (out / "report.html").read_text(encoding="utf-8")


def test_fabric_file_strings_read_back_as_they_were():
    """Quotes, backslashes, newlines and other control characters in a record's name or path
    are escaped: the fabric file stays TOML and reads back the same text."""
    import tomllib

    from vares.materials.fabric_file import fabric_toml

    odd = 'PES "42"\\A\nline two\ttab\x01\x7f\r'
    text = fabric_toml("f", {"source": odd}, {"fit": {"note": odd}}, [{"name": odd}])
    data = tomllib.loads(text)["f"]
    assert data["source"] == odd and data["fit"]["note"] == odd
    assert data["specimens"][0]["name"] == odd


def test_a_file_that_is_no_test_record_says_what_it_is(tmp_path):
    """A spreadsheet, a binary export or a fabric file among the records (a glob that caught
    too much) is named as what it is, not as a record without a header line."""
    shipped = Path(__file__).parent.parent / "examples" / "biaxial" / "pes-batch-42.toml"
    sheet = tmp_path / "pes-42-A.xlsx"
    sheet.write_bytes(b"PK\x03\x04" + bytes(range(256)) * 4)
    raw = tmp_path / "pes-42-A.dat"
    raw.write_bytes(b"\x00\x01\x02\x03" * 64)
    for path, message in [
        (sheet, "is a binary file"),
        (raw, "is a binary file"),
        (shipped, "is a TOML file"),
    ]:
        with pytest.raises(BiaxialFileError, match=message):
            read_biaxial(path)
    result = run("fabric", "fit", sheet, "-o", tmp_path / "f.toml")
    assert result.exit_code == 2 and "export the record as text (CSV or TSV)" in error_line(result)


def test_fabric_fit_says_what_a_flag_needs():
    record = Path(__file__).parent.parent / "examples" / "biaxial" / "pes-42-A_msaj.csv"
    out = Path("never-written.toml")
    result = run("fabric", "fit", record, "-o", out, "--compensate-by", "measured")
    assert result.exit_code == 2 and "--compensate-by measured needs --prestress" in error_line(
        result
    )
    result = run("fabric", "fit", record, "-o", out, "--cycle", "0")
    assert result.exit_code == 2 and "cycles count from 1; -1 is the last" in error_line(result)
    assert not out.exists()
