"""The fabric's scatter in a patterning run: ``--scatter`` on ``vares pattern``, ``panels`` and
``cut`` (and ``[scatter]`` in job files) writes the band of the run's own patterns."""

import json
import re
from pathlib import Path

import meshio
import numpy as np
import pytest
from conftest import error_line, run

from vares.analysis.scatter import ScatterOptions
from vares.app.job import load_job
from vares.geometry.examples import EXAMPLES, STRUCTURE_EXAMPLES, saddle
from vares.structures.panels import split_panels

SHIPPED = Path(__file__).parent.parent / "examples" / "biaxial" / "pes-batch-42.toml"
DIMENSIONS = ("warp_length", "fill_length", "boundary_length", "area")
PRESTRESS = [f"prestress {y}_{k}" for y in ("warp", "fill") for k in ("mean", "min", "max")]


def write_obj(path, mesh):
    meshio.write(path, meshio.Mesh(mesh.points, [("triangle", mesh.cells["triangle"])]))
    return path


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A small sail, three hypar strips as three files, a small saddle; the shipped fabric file
    with its compensation values' scatter set to 0, one of one specimen, and one with the
    scatter of its constants set to 0."""
    root = tmp_path_factory.mktemp("band")
    text = SHIPPED.read_text(encoding="utf-8")
    zero = re.sub(r"^(warp_std|fill_std) = .*$", r"\1 = 0.0", text, flags=re.M)
    assert zero != text
    one = zero.replace("fill_std = 0.0\nspecimens = 2", "fill_std = 0.0\nspecimens = 1")
    assert one != zero
    (root / "zero.toml").write_text(zero, encoding="utf-8")
    (root / "one.toml").write_text(one, encoding="utf-8")
    head, table = text.split("[pes-batch-42.scatter]")
    table = re.sub(r"^(E1|E2|nu12) = .*$", r"\1 = 0.0", table, count=3, flags=re.M)
    (root / "zero-constants.toml").write_text(
        head + "[pes-batch-42.scatter]" + table, encoding="utf-8"
    )
    mesh, ids = STRUCTURE_EXAMPLES["hypar-strips"](strips=3, n=12)
    strips = [write_obj(root / f"{p.name}.obj", p.mesh) for p in split_panels(mesh, ids)]
    return {
        "root": root,
        "sail": write_obj(root / "sail.obj", EXAMPLES["sail"](n=10)),
        "strips": strips,
        "saddle": write_obj(root / "saddle.obj", saddle(size=8.0, height=1.6, n=12)),
    }


def own_dimensions(directory: Path) -> dict[str, float]:
    """The dimensions of the pattern a run wrote (pattern.obj), along the fibres its summary
    names: extents along warp and fill, boundary length, area."""
    pattern = meshio.read(directory / "pattern.obj")
    x, cells = pattern.points[:, :2], pattern.cells_dict["triangle"]
    fibres = json.loads((directory / "summary.json").read_text())["fibres"]
    warp, fill = np.asarray(fibres["warp"]), np.asarray(fibres["fill"])
    edges = np.sort(np.concatenate([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]]), axis=1)
    unique, count = np.unique(edges, axis=0, return_counts=True)
    boundary = unique[count == 1]
    a, b = x[cells[:, 1]] - x[cells[:, 0]], x[cells[:, 2]] - x[cells[:, 0]]
    return {
        "warp_length": float(np.ptp(x @ warp)),
        "fill_length": float(np.ptp(x @ fill)),
        "boundary_length": float(
            np.linalg.norm(x[boundary[:, 1]] - x[boundary[:, 0]], axis=1).sum()
        ),
        "area": float(0.5 * np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]).sum()),
    }


def pattern_args(files, fabric, out, *extra):
    return (
        "pattern", files["sail"], "--fabric", fabric, "--prestress", "2,1.5",
        "--warp-direction", "1,1,0", "-o", out, "-q", *extra,
    )  # fmt: skip


def test_a_pattern_run_writes_the_band_of_its_own_pattern(files, tmp_path):
    out = tmp_path / "sail"
    args = pattern_args(files, SHIPPED, out, "--scatter", "--scatter-samples", 3, "--report")
    result = run(*args)
    assert result.exit_code == 0, result.stderr
    band = json.loads((out / "summary.json").read_text())["scatter"]
    assert band["fabric_file"] == str(SHIPPED.resolve()) and band["converged"]
    assert band["scatter"] == {"sampled": "compensation", "samples": 3, "sigmas": 2.0, "seed": 0}
    assert len(band["samples"]) == 3 and band["where"] == "in this process"
    figures, own = band["figures"], own_dimensions(out)
    for name in DIMENSIONS:  # the band's nominal case is the pattern the run wrote
        assert figures[name]["nominal"] == pytest.approx(own[name], abs=1e-9), name
    assert band["nominal_difference"] <= 1e-9
    for name in [*DIMENSIONS, *PRESTRESS]:
        d = figures[name]
        assert d["spread"] > 0 and d["min"] < d["max"], name
        assert d["spread"] == pytest.approx(2.0 * d["std"], rel=1e-12)
    report = (out / "report.html").read_text()
    assert "Fabric scatter: the band of the patterns" in report
    assert "pattern dimensions with their band" in report and "id='band'" in report.replace(
        '"', "'"
    )
    # the job file the run wrote reads back with its [scatter] table, and reruns to the same band
    job = load_job(out / "job.toml")
    assert job.scatter == ScatterOptions(samples=3)
    assert "[scatter]" in (out / "job.toml").read_text()
    again = run("run", out / "job.toml", "-o", tmp_path / "again", "-q")
    assert again.exit_code == 0, again.stderr
    rerun = json.loads((tmp_path / "again" / "summary.json").read_text())["scatter"]
    assert rerun["figures"] == figures and rerun["samples"] == band["samples"]


@pytest.mark.parametrize(
    ("name", "sampled", "what", "extra"),
    [
        ("zero.toml", "compensation", "compensation values (warp_std and fill_std", ()),
        (
            "zero-constants.toml",
            "constants",
            "constants (E1, E2 and nu12",
            ("--compensate-by", "law"),
        ),
    ],
)
def test_zero_scatter_is_refused_by_a_run_as_by_fabric_band(
    files, tmp_path, name, sampled, what, extra
):
    """Standard deviations written as 0 (of two specimens) give no band: every sample would be
    the nominal pattern. A patterning run and 'vares fabric band' refuse the file alike, with
    one message, before any solve."""
    path, out = files["root"] / name, tmp_path / "run"
    args = pattern_args(files, path, out, "--scatter", "--scatter-sampled", sampled, *extra)
    refused = run(*args)
    assert refused.exit_code == 2, refused.stderr
    band = run("fabric", "band", files["sail"], "--fabric", path, "--sampled", sampled, "-o",
               tmp_path / "band")  # fmt: skip
    assert band.exit_code == 2, band.stderr
    message = error_line(band).removeprefix("vares: error: ")
    assert message.startswith(f"fabric 'pes-batch-42' has no scatter of its {what} are 0")
    assert "its band would be the nominal pattern alone" in message
    assert error_line(refused).endswith(f"{path}: {message}")
    assert not out.exists() and not (tmp_path / "band").exists()


def test_the_fitted_constants_sampled_in_a_run_compensated_by_the_law(files, tmp_path):
    out = tmp_path / "law"
    extra = ("--compensate-by", "law", "--scatter", "--scatter-sampled", "constants")
    result = run(*pattern_args(files, SHIPPED, out, *extra, "--scatter-samples", 2))
    assert result.exit_code == 0, result.stderr
    band = json.loads((out / "summary.json").read_text())["scatter"]
    own = own_dimensions(out)
    assert set(band["samples"][0]) == {"E1", "E2", "nu12"}
    for name in DIMENSIONS:
        assert band["figures"][name]["nominal"] == pytest.approx(own[name], abs=1e-9), name
        assert band["figures"][name]["spread"] > 0


def test_a_structure_run_writes_the_band_of_every_seam(files, tmp_path):
    out = tmp_path / "strips"
    result = run(
        "panels", *files["strips"], "--fabric", SHIPPED, "--prestress", "2,1.5",
        "--warp-direction", "1,0,0", "--scatter", "--scatter-samples", 3, "-o", out, "-q",
        "--report",
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr
    data = json.loads((out / "structure.json").read_text())
    band = data["scatter"]
    seams = {f"seam {s['first']}|{s['second']}": s["length_first_after"] for s in data["seams"]}
    assert len(seams) == 2
    for name, length in seams.items():
        d = band["figures"][name]
        assert d["nominal"] == pytest.approx(length, abs=1e-9)
        assert d["spread"] > 0
    for panel in data["panels"]:
        own = own_dimensions(out / panel["directory"])
        for name in DIMENSIONS:
            nominal = band["figures"][f"{panel['name']} {name}"]["nominal"]
            assert nominal == pytest.approx(own[name], abs=1e-9)
    assert band["nominal_difference"] <= 1e-9
    # the band is the structure's: in its report and structure.json, not in the panels'
    assert all(name in (out / "report.html").read_text() for name in seams)
    for panel in data["panels"]:
        directory = out / panel["directory"]
        assert "scatter" not in json.loads((directory / "summary.json").read_text())
        assert "Fabric scatter" not in (directory / "report.html").read_text()


def test_a_cut_run_takes_its_strips_as_panels(files, tmp_path):
    out = tmp_path / "cut"
    result = run(
        "cut", files["saddle"], "--roll-width", 3.0, "--fabric", SHIPPED, "--prestress", "2,1.5",
        "--nest-time", 0.2, "--scatter", "--scatter-samples", 2, "-o", out, "-q",
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr
    data = json.loads((out / "structure.json").read_text())
    band = data["scatter"]
    assert band["panels"] == [p["name"] for p in data["panels"]] and len(band["panels"]) >= 2
    # each strip solved again with the warp it was cut with: the same patterns
    assert band["nominal_difference"] <= 1e-9
    seams = [n for n in band["figures"] if n.startswith("seam ")]
    assert len(seams) == len(data["seams"]) >= 1
    assert all(band["figures"][n]["spread"] > 0 for n in seams)


def test_scatter_without_a_fabric_file_with_scatter_is_refused(files, tmp_path):
    preset = run(*pattern_args(files, "pes-pvc-type-2", tmp_path / "a", "--scatter"))
    assert preset.exit_code == 2
    assert "needs a fabric file with scatter" in error_line(preset)
    single = files["root"] / "one.toml"
    one = run(*pattern_args(files, single, tmp_path / "b", "--scatter"))
    assert one.exit_code == 2
    line = error_line(one)
    assert str(single) in line and "one specimen" in line
    flag = run(*pattern_args(files, SHIPPED, tmp_path / "c", "--scatter-samples", 4))
    assert flag.exit_code == 2 and "add --scatter" in error_line(flag)
    zero = run(*pattern_args(files, SHIPPED, tmp_path / "d", "--scatter", "--scatter-samples", 0))
    assert zero.exit_code == 2 and "--scatter-samples must be ≥ 1" in error_line(zero)
    law = run(*pattern_args(files, SHIPPED, tmp_path / "e", "--scatter", "--compensate-by", "law"))
    assert law.exit_code == 2 and "--scatter-sampled constants" in error_line(law)
    bare = run("pattern", files["sail"], "--fabric", SHIPPED, "--scatter", "-o", tmp_path / "f")
    assert bare.exit_code == 2 and "uniform prestress" in error_line(bare)
    assert not any((tmp_path / d).exists() for d in "abcdef")
