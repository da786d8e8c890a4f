"""``vares drape --example NAME``: the shipped moulds draped from their own seed, warp and spacing
(docs/composites.md, "The net")."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import error_line, run

from vares.analysis.drape import drape_ply
from vares.app.cli.drape import DRAPE_EXAMPLES
from vares.geometry.examples import double_dome, double_dome_height, irregular_cap, rib30


def test_the_hemisphere_example_is_the_hemisphere_draped_from_its_pole(tmp_path):
    out = tmp_path / "out"
    result = run("drape", "--example", "hemisphere", "-o", out)
    assert result.exit_code == 0, result.stderr
    data = json.loads((out / "drape.json").read_text())
    assert data["example"] == "hemisphere" and "surface" not in data
    assert data["seed"] == [0.0, 0.0, 100.0] and data["warp"] == [1.0, 0.0, 0.0]
    assert data["spacing"] == 2.0
    direct = drape_ply(
        irregular_cap(100.0, 90.0, 30, 0.3, 1), seed=(0, 0, 100), warp=(1, 0, 0), spacing=2.0
    )
    expected = direct.producibility.summary()
    for key in ("limit_fraction", "warn_fraction", "max_shear"):
        assert data["producibility"][key] == pytest.approx(expected[key], rel=1e-12)
    # the hemisphere's net shears beyond a twill's 50° only at the equator on the diagonals
    assert 50.0 < data["producibility"]["max_shear"] < 53.0


def test_an_example_takes_the_flags_over_its_own_settings(tmp_path):
    out = tmp_path / "out"
    flags = ("--seed", "1,0,99.995", "--warp", "0,1,0", "--spacing", 4, "--locking-angle", 30)
    result = run("drape", "--example", "hemisphere", *flags, "-o", out, "-q")
    assert result.exit_code == 0, result.stderr
    data = json.loads((out / "drape.json").read_text())
    assert data["seed"] == [1.0, 0.0, 99.995] and data["warp"] == [0.0, 1.0, 0.0]
    assert data["spacing"] == 4.0 and data["producibility"]["locking_angle"] == 30.0


def test_the_double_dome_and_rib_examples_use_their_seeds_and_warps(tmp_path):
    dome, rib = DRAPE_EXAMPLES["double-dome"], DRAPE_EXAMPLES["rib"]
    # the double dome from the saddle's centre, on both planes of symmetry
    centre = (0.0, 0.0, float(double_dome_height(np.zeros(1), np.zeros(1))[0]))
    assert dome.seed() == centre and dome.warp == (1.0, 0.0, 0.0) and dome.units == "mm"
    assert dome.make().num_cells == double_dome().num_cells
    # the rib in metres, the warp along it, the seed the node nearest the centroid
    assert rib.seed() is None and rib.warp == (0.0, 1.0, 0.0) and rib.units == "m"
    out = tmp_path / "rib"
    result = run("drape", "--example", "rib", "-o", out, "-q")
    assert result.exit_code == 0, result.stderr
    data = json.loads((out / "drape.json").read_text())
    mesh = rib30()
    direct = drape_ply(mesh, warp=(0, 1, 0), spacing=0.004)
    assert data["seed"] == pytest.approx(direct.seed.tolist())
    assert data["producibility"]["max_shear"] == pytest.approx(
        direct.producibility.max_shear, rel=1e-12
    )


def test_a_file_and_an_example_or_neither_are_refused(tmp_path):
    for args, message in [
        (("--example", "cube"), "--example must be one of hemisphere, double-dome, rib"),
        ((), "give a mould file or --example"),
        ((tmp_path / "mould.obj", "--example", "rib"), "give a mould file or --example"),
    ]:
        result = run("drape", *args, "-o", tmp_path / "out")
        assert result.exit_code == 2
        assert message in error_line(result)
        assert not (tmp_path / "out").exists()
