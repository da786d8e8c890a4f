"""One options model: the Python API, job files and the command line take the same options, with
the same defaults and bounds, and mean the same by them."""

import inspect
import json

import meshio
import numpy as np
import pytest
import typer
from conftest import run

import vares
from vares.app.cli import app
from vares.app.job import SECTIONS, JobError, load_job
from vares.app.runner import run_job
from vares.geometry.examples import hypar
from vares.options import OptionsError
from vares.solver import SolveOptions
from vares.structures import StructureOptions

#: A run with every solver option away from its default but the orientation (an anisotropic
#: law, so that the fibre options matter; the orientation is held to keep the run short).
SETTINGS = {
    "warp_angle": 15.0,
    "fill_angle": 105.0,
    "orientation": "held",
    "strategy": "damping",
    "steps": 4,
    "initial_guess": "projection",
    "plane": "xy",
    "tolerance": 1e-9,
    "max_iterations": 40,
    "damping": 0.5,
    "linear_solver": "scipy-superlu",
}
LAW = {"E1": 800.0, "E2": 640.0, "G12": 40.0, "nu12": 0.4}


def _command_parameters(name: str) -> set[str]:
    command = typer.main.get_command(app).commands[name]
    return {p.name for p in command.params}


def test_the_same_run_from_the_api_a_job_file_and_the_command_line(tmp_path):
    surface = hypar(size=4.0, rise=0.15, n=8)
    path = tmp_path / "roof.ply"
    meshio.write(path, meshio.Mesh(surface.points, [("triangle", surface.cells["triangle"])]))
    mesh = vares.read_mesh(path)
    fabric = vares.materials.OrthotropicStVenantKirchhoff(**LAW)
    api = vares.solve(mesh, fabric, 0.8, **SETTINGS)
    assert api.converged
    assert api.options == SolveOptions(**SETTINGS)
    defaults = SolveOptions()
    for name, value in SETTINGS.items():  # every setting but the orientation is no default
        assert getattr(api.options, name) == value, name
        assert value != getattr(defaults, name) or name == "orientation", name

    job_file = tmp_path / "job.toml"
    fibres = {k: SETTINGS[k] for k in ("warp_angle", "fill_angle", "orientation")}
    solver = {k: v for k, v in SETTINGS.items() if k not in fibres}
    lines = ['[input]\nmesh = "roof.ply"\n', '[material]\nlaw = "orthotropic"\nthickness = 0.8']
    lines += [f"{k} = {v}" for k, v in LAW.items()]
    lines += ["[fibres]"] + [f"{k} = {json.dumps(v)}" for k, v in fibres.items()]
    lines += ["[solver]"] + [f"{k} = {json.dumps(v)}" for k, v in solver.items()]
    lines += ['[output]\ndirectory = "job-out"']
    job_file.write_text("\n".join(lines) + "\n")
    from_job = run_job(load_job(job_file))
    assert from_job.result.options == api.options

    saved = tmp_path / "saved.toml"
    flags = [f"--{k.replace('_', '-')}={v}" for k, v in SETTINGS.items()]
    flags += [f"--{k}={v}" for k, v in LAW.items()]
    result = run(
        "pattern",
        path,
        "-o",
        tmp_path / "cli-out",
        "--material",
        "orthotropic",
        "--thickness",
        0.8,
        *flags,
        "--save-job",
        saved,
        "-q",
    )
    assert result.exit_code == 0, result.stderr
    assert load_job(saved).solve == api.options
    for folder in ("cli-out", "job-out"):
        summary = json.loads((tmp_path / folder / "summary.json").read_text())
        assert summary["options"] == api.options.to_dict()
        assert summary["energy"] == api.energy
        pattern = meshio.read(tmp_path / folder / "pattern.obj").points[:, :2]
        np.testing.assert_allclose(pattern, api.material_coordinates, rtol=0, atol=1e-12)


def test_every_option_is_reachable_from_all_three_with_one_default():
    solve = inspect.signature(vares.solve).parameters
    structure = inspect.signature(vares.solve_structure).parameters
    for cls, commands in (
        (SolveOptions, ("pattern", "example", "panels")),
        (StructureOptions, ("panels",)),
    ):
        for name, spec in cls.specs().items():
            assert spec.section in SECTIONS, name  # a job file can hold it
            for command in commands:  # a flag of each command that runs such a job
                assert name in _command_parameters(command), (name, command)
            default = cls.defaults()[name]
            assert structure[name].default == default, name
            if cls is SolveOptions:
                assert solve[name].default == default, name
    help_text = run("pattern", "--help").stdout
    assert "[default: 1e-10]" in help_text and "[default: 50]" in help_text


def test_misspelt_or_misplaced_job_keys_are_refused_with_a_suggestion(tmp_path):
    cases = [
        (
            "[input]\nexample = 'hypar'\n[solver]\nmax_iteration = 10\n",
            "[solver] unknown key 'max_iteration' (did you mean 'max_iterations'?)",
        ),
        (
            "[input]\nexample = 'hypar'\n[solver]\nwarp_angle = 10.0\n",
            "[solver] unknown key 'warp_angle'; it belongs in [fibres]",
        ),
        (
            "[input]\nexample = 'hypar'\n[solvers]\ntolerance = 1e-8\n",
            "unknown table [solvers] (did you mean [solver]?)",
        ),
        (
            "[input]\nexample = 'hypar'\n[solver]\nstrategy = 'newtn'\n",
            "[solver] strategy must be one of auto, newton, pseudo-time, damping; got 'newtn' "
            "(did you mean 'newton'?)",
        ),
        (
            "[input]\nexample = 'hypar'\n[solver]\nmax_iterations = 0\n",
            "[solver] max_iterations must be ≥ 1; got 0",
        ),
    ]
    for text, message in cases:
        path = tmp_path / "job.toml"
        path.write_text(text)
        with pytest.raises(JobError) as caught:
            load_job(path)
        assert str(caught.value) == f"{path}: {message}"


def test_api_settings_are_checked_alike():
    mesh = hypar(n=4)
    material = vares.materials.NeoHooke(1000.0, 0.3)
    with pytest.raises(
        OptionsError, match=r"unknown option 'tolerence' \(did you mean 'tolerance'\?\)"
    ):
        vares.solve(mesh, material, tolerence=1e-8)
    with pytest.raises(OptionsError, match=r"tolerance must be > 0; got -1\.0"):
        vares.solve(mesh, material, tolerance=-1.0)
    with pytest.raises(OptionsError, match=r"steps must be an integer; got 2\.5"):
        vares.solve(mesh, material, steps=2.5)
    base = SolveOptions(tolerance=1e-8)
    result = vares.solve(mesh, material, options=base, max_iterations=30)
    assert result.options == SolveOptions(tolerance=1e-8, max_iterations=30)
    assert SolveOptions(warp_direction=[1, 0, 0]).warp_direction == (1.0, 0.0, 0.0)
    with pytest.raises(OptionsError, match="cannot also be free"):
        SolveOptions(warp_direction=(1, 0, 0), orientation="free")


def test_command_line_values_are_checked_by_the_same_declarations(tmp_path):
    result = run("example", "hypar", "-o", tmp_path, "--tolerance", -1)
    assert result.exit_code == 2
    assert "vares: error: --tolerance must be > 0; got -1.0" in result.stderr
    result = run("example", "hypar", "-o", tmp_path, "--damping", 0)
    assert result.exit_code == 2 and "--damping must be > 0" in result.stderr
    assert not any(tmp_path.iterdir())


def test_an_option_reused_in_another_table_keeps_its_declaration():
    """A laminate's and a ply's darts and locking angle are those of a single ply's drape
    (vares.options.reused): the same kind, choices and bounds, in their own tables, refused
    alike; a default of None makes the ply's "not given"."""
    from vares.analysis.dart_options import DartOptions
    from vares.analysis.drape_options import DrapeOptions
    from vares.structures.laminate_options import LaminateOptions, PlyOptions

    for cls, section in ((LaminateOptions, "laminate"), (PlyOptions, "ply")):
        for original, name in ((DartOptions, "darts"), (DrapeOptions, "locking_angle")):
            spec, source = cls.specs()[name], original.specs()[name]
            assert (spec.kind, spec.choices, spec.positive) == (
                source.kind,
                source.choices,
                source.positive,
            )
            assert spec.section == section and spec.help != source.help
    assert LaminateOptions.defaults()["darts"] == DartOptions.defaults()["darts"] == "none"
    assert PlyOptions.defaults()["darts"] is None and PlyOptions.specs()["darts"].optional
    assert PlyOptions.specs()["dart_lines"].help.startswith("Dart lines of the ply's own")
    for make in (
        lambda: DartOptions(darts="sometimes"),
        lambda: LaminateOptions(darts="sometimes"),
        lambda: PlyOptions(name="A", darts="sometimes"),
    ):
        with pytest.raises(OptionsError, match="darts must be one of none, auto; got 'sometimes'"):
            make()
    with pytest.raises(OptionsError, match="locking_angle must be > 0"):
        LaminateOptions(locking_angle=0.0)
    assert LaminateOptions(darts="AUTO").darts == "auto"
    assert LaminateOptions().to_dict(section="laminate")["darts"] == "none"
