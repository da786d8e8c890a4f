"""No folded start, no folded pattern called converged, nothing lost and nothing mixed."""

import json

import numpy as np
import pytest
from conftest import error_line, run

import vares
from vares.geometry.examples import hypar, ruffled_fan
from vares.geometry.flatten import inverted_cells, lscm, tutte, untangle
from vares.geometry.injectivity import pattern_area_misfit, pattern_overlap
from vares.io.meshes import write_surface

NEO_HOOKE = vares.materials.NeoHooke(1000.0, 0.3)


def test_tutte_is_one_to_one_where_the_conformal_map_folds():
    mesh = hypar(size=2.0, rise=2.5, n=20)  # the steep saddle z = 2.5 x y
    assert inverted_cells(mesh, lscm(mesh)).size == 2
    start = tutte(mesh)
    assert inverted_cells(mesh, start).size == 0 and pattern_overlap(mesh, start) is None
    assert vares.geometry.signed_area(mesh, start) == pytest.approx(mesh.area)
    with pytest.warns(UserWarning, match="the conformal map folds 2 cell.*Tutte's embedding"):
        result = vares.solve(mesh, NEO_HOOKE)
    assert result.converged and result.initial_guess == "tutte"
    assert result.strategy == ["globalised newton"]


def test_a_few_folded_cells_are_mended_where_they_are():
    mesh = hypar(n=12)
    start = mesh.points[:, :2].copy()
    node = 6 * 13 + 6  # an inner node pushed across two of its neighbours: its cells fold
    start[node] += [1.3, 0.9]
    folded = inverted_cells(mesh, start)
    assert folded.size >= 2
    mended = untangle(mesh, start)
    assert mended is not None and inverted_cells(mesh, mended).size == 0
    moved = np.flatnonzero(np.any(mended != start, axis=1))
    assert node in moved
    # only the neighbourhood moved: every moved node within a few cells of the folded node
    assert np.abs(mesh.points[moved, :2] - mesh.points[node, :2]).max() <= 5 * 10.0 / 12
    flat = mesh.points[:, :2].copy()
    np.testing.assert_array_equal(untangle(mesh, flat), flat)  # nothing folded: unchanged
    # a start one gives is never changed behind one's back: it is refused
    given = vares.solve(mesh, NEO_HOOKE, initial_guess=start)
    assert not given.converged and "the initial guess inverts" in given.reason


def test_a_fold_held_by_the_boundary_is_not_mended():
    mesh = hypar(n=8)
    start = mesh.points[:, :2].copy()
    start[0] += [3.0, 3.0]  # a corner node thrown inside: its cell folds, and it is held
    assert inverted_cells(mesh, start).size
    assert untangle(mesh, start) is None


def test_tutte_on_a_surface_with_a_hole():
    x, y = np.meshgrid(np.linspace(-1, 1, 9), np.linspace(-1, 1, 9))
    points = np.column_stack([x.ravel(), y.ravel(), 0.3 * x.ravel() * y.ravel()])
    quads = [
        [j * 9 + i, j * 9 + i + 1, (j + 1) * 9 + i + 1, (j + 1) * 9 + i]
        for j in range(8)
        for i in range(8)
        if not (3 <= i <= 4 and 3 <= j <= 4)  # a 2 × 2 hole in the middle
    ]
    mesh = vares.SurfaceMesh(points, {"quad": np.array(quads)}, drop_unused_nodes=True)
    assert len(mesh.boundary_loops()) == 2
    start = tutte(mesh)
    assert inverted_cells(mesh, start).size == 0 and pattern_overlap(mesh, start) is None
    result = vares.solve(mesh, NEO_HOOKE, initial_guess="tutte")
    assert result.converged and result.initial_guess == "tutte"


def test_a_minimum_that_laps_over_itself_is_left_for_one_from_tutte():
    mesh = hypar(size=2.0, rise=2.5, n=10)
    from_lscm = vares.solve(mesh, NEO_HOOKE, initial_guess="lscm")
    assert not from_lscm.converged and from_lscm.overlap is not None
    assert "outline crosses itself" in from_lscm.reason
    result = vares.solve(mesh, NEO_HOOKE)
    assert result.converged and result.initial_guess == "tutte"
    assert "restart from Tutte's embedding" in result.strategy
    assert result.energy < 0.5 * from_lscm.energy


def test_a_pattern_that_overlaps_itself_is_not_converged_nor_cut(tmp_path):
    mesh = ruffled_fan()  # developable, but 1.6 turns of surface around its apex
    result = vares.solve(mesh, NEO_HOOKE)
    assert not result.converged and result.overlap is not None
    assert abs(result.energy) < 1e-9  # the energy is minimal: the pattern is the development
    assert len(result.overlap.crossings) > 0 and result.overlap.inverted.size == 0
    source = tmp_path / "fan.obj"
    write_surface(source, mesh)
    out = tmp_path / "out"
    cli = run("pattern", source, "-o", out, "-q")
    assert cli.exit_code == 1
    assert "the pattern overlaps itself: its outline crosses itself" in error_line(cli)
    assert "cut it there (split it into panels) or add a dart" in error_line(cli)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["converged"] is False and "overlaps itself" in summary["reason"]
    assert (out / "pattern.svg").exists() and not (out / "pattern.dxf").exists()
    cli = run("pattern", source, "-o", out, "-q", "--force", "--allow-overlap")
    assert cli.exit_code == 1 and (out / "pattern.dxf").exists()


def _sphere_less_one_triangle(n: int = 200) -> vares.SurfaceMesh:
    """A unit sphere of ``n`` nodes (a Fibonacci lattice, its convex hull) with one triangle
    taken out: a surface open at one small hole."""
    from scipy.spatial import ConvexHull

    k = np.arange(n) + 0.5
    z = 1 - 2 * k / n
    phi = np.pi * (1 + 5**0.5) * k
    points = np.column_stack([np.sqrt(1 - z**2) * np.cos(phi), np.sqrt(1 - z**2) * np.sin(phi), z])
    triangles = ConvexHull(points).simplices
    a, b, c = (points[triangles[:, i]] for i in range(3))
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), a + b + c) < 0
    triangles[inward] = triangles[inward][:, ::-1]
    return vares.SurfaceMesh(points, {"triangle": triangles[1:]})


def test_a_pattern_far_smaller_than_its_surface_is_not_converged_nor_cut(tmp_path):
    mesh = _sphere_less_one_triangle()
    with pytest.warns(UserWarning, match="conformal map folds"):
        result = vares.solve(mesh, NEO_HOOKE)
    assert not result.converged and result.overlap is None and result.uncuttable
    misfit = result.area_misfit
    assert misfit.ratio == pytest.approx(result.pattern_area / result.surface_area, rel=1e-12)
    assert misfit.ratio < 0.1  # a small cloth stretched over the whole sphere
    assert misfit.stretch_max == pytest.approx(result.fields["det_F"].max(), rel=1e-9)
    assert "the pattern's area is" in result.reason and "cut it into panels" in result.reason
    source = tmp_path / "ball.obj"
    write_surface(source, mesh)
    out = tmp_path / "out"
    cli = run("pattern", source, "-o", out, "-q")
    assert cli.exit_code == 1
    line = error_line(cli)
    assert f"the pattern's area is {100 * misfit.ratio:.3g} % of the surface's" in line
    assert "(is it nearly closed?)" in line
    summary = json.loads((out / "summary.json").read_text())
    assert summary["converged"] is False and "the pattern's area is" in summary["reason"]
    assert (out / "pattern.svg").exists() and not (out / "pattern.dxf").exists()
    cli = run("pattern", source, "-o", out, "-q", "--force", "--allow-overlap")
    assert cli.exit_code == 1 and (out / "pattern.dxf").exists()


@pytest.mark.parametrize(
    ("ratio", "refused"), [(0.6, True), (0.7, False), (1.4, False), (1.6, True)]
)
def test_the_area_a_pattern_may_have_is_within_a_factor_of_one_and_a_half(ratio, refused):
    mesh = hypar(n=6, rise=0.0)  # a flat square: its pattern scaled by √ratio has ratio × its area
    misfit = pattern_area_misfit(mesh, mesh.points[:, :2] * np.sqrt(ratio))
    assert (misfit is not None) == refused
    if refused:
        assert misfit.ratio == pytest.approx(ratio, rel=1e-12)
        assert misfit.stretch_min == pytest.approx(1 / ratio, rel=1e-12)
        assert misfit.stretch_max == pytest.approx(1 / ratio, rel=1e-12)
        assert ("stretched to" in misfit.describe()) == (ratio < 1)
        assert f"{100 * ratio:.3g} % of the surface's" in misfit.describe()


def test_an_initial_pattern_file_from_the_command_line_and_a_job(tmp_path):
    mesh = hypar(n=8)
    source = tmp_path / "roof.obj"
    write_surface(source, mesh)
    assert run("pattern", source, "-o", tmp_path / "first", "-q").exit_code == 0
    again = run(
        "pattern",
        source,
        "-o",
        tmp_path / "again",
        "--initial-pattern",
        tmp_path / "first" / "pattern.obj",
        "-q",
        "--save-job",
        tmp_path / "again.toml",
    )
    assert again.exit_code == 0, again.stderr
    summary = json.loads((tmp_path / "again" / "summary.json").read_text())
    assert summary["iterations"] <= 1  # it starts at the optimum
    assert 'initial_pattern = "first/pattern.obj"' in (tmp_path / "again.toml").read_text()
    other = hypar(n=6)
    write_surface(tmp_path / "other.obj", other)
    bad = run(
        "pattern", source, "-o", tmp_path / "bad", "--initial-pattern", tmp_path / "other.obj"
    )
    assert bad.exit_code == 2 and "does not have the nodes and faces" in error_line(bad)


def test_an_interrupted_forced_rerun_leaves_the_previous_run_whole(tmp_path, monkeypatch):
    out = tmp_path / "out"
    assert run("example", "hypar", "-o", out, "-q").exit_code == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    from vares.app import outputs

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(outputs, "write_dxf", interrupted)
    result = run("example", "hypar", "-o", out, "-q", "--force", "--E", "2000")
    assert result.exit_code == 130 and "interrupted" in error_line(result)
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no staging left behind


def test_nothing_in_an_output_folder_is_lost(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    mesh = hypar(n=6)
    write_surface(out / "roof.obj", mesh)  # the input lies in the output folder
    result = run("pattern", out / "roof.obj", "-o", out, "-q", "--force")
    assert result.exit_code == 2
    assert "roof.obj lies in the output folder, which the run replaces" in error_line(result)
    assert sorted(p.name for p in out.iterdir()) == ["roof.obj"]
    (out / "notes.txt").write_text("mine")
    write_surface(tmp_path / "x.obj", mesh)
    result = run("pattern", tmp_path / "x.obj", "-o", out, "-q", "--force")
    assert result.exit_code == 2
    assert "holds files vares did not write (notes.txt, roof.obj)" in error_line(result)
    (tmp_path / "file").write_text("not a folder")
    result = run("pattern", out / "roof.obj", "-o", tmp_path / "file", "-q")
    assert result.exit_code == 2 and "is a file" in error_line(result)
    result = run("pattern", out / "roof.obj", "-o", tmp_path / "x", "--save-job", out / "roof.obj")
    assert result.exit_code == 2 and "ends in .toml" in error_line(result)
    # a job saved into its output folder goes with the run, and the run can be repeated
    job = tmp_path / "run" / "job.toml"
    result = run("pattern", out / "roof.obj", "-o", tmp_path / "run", "--save-job", job, "-q")
    assert result.exit_code == 0, result.stderr
    manifest = json.loads((tmp_path / "run" / ".vares-run.json").read_text())
    assert "job.toml" in manifest["files"] and "pattern.dxf" in manifest["files"]
    result = run("run", job, "-q")
    assert result.exit_code == 2 and "use --force to replace the previous run" in error_line(result)
    result = run("run", job, "-q", "--force")
    assert result.exit_code == 0, result.stderr
    assert job.exists() and (tmp_path / "run" / "pattern.dxf").exists()
    # another run's job file is not overwritten, even with --force
    saved = job.read_text()
    other = run("pattern", out / "roof.obj", "-o", tmp_path / "y", "--save-job", job, "-f")
    assert other.exit_code == 2 and "belongs to another run's folder" in error_line(other)
    assert job.read_text() == saved and not (tmp_path / "y").exists()


def test_a_scans_flipped_slivers_are_mended_in_its_projection():
    from vares.geometry.examples import scan_like

    mesh = scan_like(20_000)  # 2 mm noise on jittered points: a few slivers flip
    with pytest.warns(UserWarning, match=r"the projection folds \d+ cell\(s\), mended"):
        mended = vares.solve(mesh, NEO_HOOKE)
    assert mended.converged and mended.initial_guess == "projection"
    from_tutte = vares.solve(mesh, NEO_HOOKE, initial_guess="tutte")
    assert from_tutte.converged
    assert mended.energy == pytest.approx(from_tutte.energy, rel=1e-9)  # the same optimum
    assert mended.iterations < from_tutte.iterations


def test_a_file_that_appears_during_a_run_is_not_lost(tmp_path, monkeypatch):
    """The folder is checked again just before the run takes its place: a file put there
    meanwhile stays, the previous run too, and the new run waits beside them."""
    out = tmp_path / "out"
    assert run("example", "hypar", "-o", out, "-q").exit_code == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    from vares.app import staging

    start = staging.OutputFolder.start

    def meanwhile(self):
        staged = start(self)
        (out / "notes.txt").write_text("written during the run")
        return staged

    monkeypatch.setattr(staging.OutputFolder, "start", meanwhile)
    result = run("example", "hypar", "-o", out, "-q", "--force", "--E", "2000")
    assert result.exit_code == 2 and "(notes.txt)" in error_line(result)
    assert "this run is kept in" in error_line(result)
    after = {p.name: p.read_bytes() for p in out.iterdir()}
    assert after.pop("notes.txt") == b"written during the run" and after == before
    kept = [p for p in tmp_path.iterdir() if p.name.startswith(".out.vares-")]
    assert len(kept) == 1 and (kept[0] / "pattern.dxf").is_file()


def test_an_erection_rerun_lists_only_its_own_files(tmp_path):
    out = tmp_path / "out"
    assert run("example", "hypar", "-o", out, "-q").exit_code == 0
    assert run("erect", out, "-q", "--report").exit_code == 0
    assert (out / "erect" / "report.html").is_file()
    assert run("erect", out, "-q", "-f").exit_code == 0  # without the report this time
    listed = json.loads((out / ".vares-run.json").read_text())["files"]
    assert "erect/erect.json" in listed and "erect/report.html" not in listed
    assert not (out / "erect" / "report.html").exists()
    (out / "erect" / "report.html").write_text("the user's own page")
    result = run("erect", out, "-q", "-f")
    assert result.exit_code == 2 and "(report.html)" in error_line(result)
    assert (out / "erect" / "report.html").read_text() == "the user's own page"


def test_batch_jobs_whose_folders_nest_are_refused(tmp_path):
    for name, folder in (("a", "X"), ("b", "X/b")):
        (tmp_path / f"{name}.toml").write_text(
            f'[input]\nexample = "hypar"\n[output]\ndirectory = "{folder}"\n'
        )
    result = run("batch", tmp_path / "a.toml", tmp_path / "b.toml")
    assert result.exit_code == 2 and "one into the other's" in error_line(result)
    assert not (tmp_path / "X").exists()


def test_pseudo_time_reports_an_overlapping_pattern_without_restarting(monkeypatch):
    """Pseudo-time starts from the projection; a pattern it ends with that overlaps itself is
    reported as such (Tutte's embedding, which has no plane, is no restart for it)."""
    from vares.geometry.injectivity import Overlap
    from vares.solver import api

    mesh = hypar(n=6)
    crossing = Overlap(np.zeros(0, int), np.array([[0.0, 0.0]]), np.array([0]))
    monkeypatch.setattr(api, "pattern_overlap", lambda mesh, x: crossing)
    result = vares.solve(mesh, NEO_HOOKE, strategy="pseudo-time")
    assert not result.converged and result.overlap is crossing
    assert result.initial_guess == "projection"


def test_a_killed_runs_staging_folder_is_removed_by_the_next_run(tmp_path):
    """A run killed mid-way leaves its hidden staging folder; the next run into the same
    folder removes it when its process has ended, and leaves a live run's and a kept one."""
    import os
    import subprocess
    import sys

    from vares.app.staging import OWNER

    ended = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                           capture_output=True, text=True, check=True)  # fmt: skip
    host = __import__("socket").gethostname()
    folders = {}
    for name, pid in (("killed", int(ended.stdout)), ("running", os.getppid())):
        folder = tmp_path / f".out.vares-{name}"
        folder.mkdir()
        (folder / "pattern.dxf").write_text("half written")
        (folder / OWNER).write_text(json.dumps({"pid": pid, "host": host}))
        folders[name] = folder
    kept = tmp_path / ".out.vares-kept"  # a finished run kept beside: names no process
    kept.mkdir()
    (kept / "pattern.dxf").write_text("finished")
    other = tmp_path / ".other.vares-killed"  # another output folder's
    other.mkdir()
    (other / OWNER).write_text(json.dumps({"pid": int(ended.stdout), "host": host}))
    assert run("example", "hypar", "-o", tmp_path / "out", "-q").exit_code == 0
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == [".other.vares-killed", ".out.vares-kept", ".out.vares-running", "out"]
    assert not (tmp_path / "out" / OWNER).exists()
    manifest = json.loads((tmp_path / "out" / ".vares-run.json").read_text())
    assert OWNER not in manifest["files"]


def _ended_pid() -> int:
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)  # fmt: skip
    return int(done.stdout)


def test_a_run_killed_in_the_middle_of_the_swap_gets_the_previous_run_back(tmp_path):
    """Killed between moving the previous run aside and putting the new one in place, a run
    leaves no output folder: the next run into it puts the previous run back first."""
    import subprocess
    import sys

    out = tmp_path / "out"
    assert run("example", "hypar", "-o", out, "-q").exit_code == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    killed = (
        "import os, sys\n"
        "from vares.app import staging\n"
        "replace = os.replace\n"
        "def dying(a, b):\n"
        f"    if str(b) == {str(out)!r}:  # the new run into place: the old one is aside\n"
        "        os._exit(9)  # killed: no clean-up runs\n"
        "    replace(a, b)\n"
        "staging.os.replace = dying\n"
        "from vares.app.cli.main import app\n"
        f"app(['example', 'hypar', '-o', {str(out)!r}, '-q', '--force', '--E', '2000'])\n"
    )
    done = subprocess.run([sys.executable, "-c", killed], capture_output=True, text=True)
    assert done.returncode == 9, done.stderr
    assert not out.exists() and any(p.name.startswith(".out.old-") for p in tmp_path.iterdir())
    result = run("example", "hypar", "-o", out, "-q")  # no --force: the old run is back
    assert result.exit_code == 2 and "output exists" in error_line(result)
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    # the killed run's staging folder (it named its process) is gone as well
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_an_interrupt_in_the_middle_of_the_swap_puts_the_previous_run_back(tmp_path, monkeypatch):
    out = tmp_path / "out"
    assert run("example", "hypar", "-o", out, "-q").exit_code == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    from vares.app import staging

    replace = staging.os.replace

    def interrupted(a, b):
        if str(b) == str(out) and not str(a).endswith("run"):  # the old run is aside
            raise KeyboardInterrupt
        replace(a, b)

    monkeypatch.setattr(staging.os, "replace", interrupted)
    result = run("example", "hypar", "-o", out, "-q", "--force", "--E", "2000")
    monkeypatch.undo()
    assert result.exit_code == 130
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_a_killed_erections_staging_folder_does_not_block_the_runs_rerun(tmp_path):
    from vares.app.staging import OWNER

    out = tmp_path / "out"
    assert run("example", "hypar", "-o", out, "-q").exit_code == 0
    leftover = out / ".erect.vares-killed"
    leftover.mkdir()
    (leftover / "erect.json").write_text("half written")
    owner = {"pid": _ended_pid(), "host": __import__("socket").gethostname()}
    (leftover / OWNER).write_text(json.dumps(owner))
    result = run("example", "hypar", "-o", out, "-q", "--force")
    assert result.exit_code == 0, result.stderr
    assert not leftover.exists()


def test_an_erection_killed_before_its_commit_leaves_its_old_files_known(tmp_path, monkeypatch):
    """The run's manifest lists the old and the new erect/ files until the new ones are in
    place: a rerun after a kill there does not take the old report for a stranger's file."""
    out = tmp_path / "out"
    assert run("example", "hypar", "-o", out, "-q").exit_code == 0
    assert run("erect", out, "-q", "--report").exit_code == 0
    from vares.app import staging

    def killed(self):
        raise KeyboardInterrupt

    monkeypatch.setattr(staging.OutputFolder, "commit", killed)
    assert run("erect", out, "-q", "-f").exit_code == 130  # without the report
    monkeypatch.undo()
    listed = json.loads((out / ".vares-run.json").read_text())["files"]
    assert "erect/report.html" in listed and "erect/erect.json" in listed
    assert (out / "erect" / "report.html").is_file()  # the previous erection, whole
    result = run("erect", out, "-q", "-f")
    assert result.exit_code == 0, result.stderr
    listed = json.loads((out / ".vares-run.json").read_text())["files"]
    assert "erect/report.html" not in listed and not (out / "erect" / "report.html").exists()


def test_a_run_of_another_command_or_the_current_folder_is_never_replaced(tmp_path, monkeypatch):
    out = tmp_path / "out"
    assert run("example", "hypar", "-o", out, "-q").exit_code == 0
    before = sorted(p.name for p in out.iterdir())
    result = run("evaluate", out / "surface.obj", out / "pattern.obj", "-o", out, "--force")
    assert result.exit_code == 2  # its inputs lie there too; copied out, the run is refused
    surface, pattern = tmp_path / "s.obj", tmp_path / "p.obj"
    surface.write_bytes((out / "surface.obj").read_bytes())
    pattern.write_bytes((out / "pattern.obj").read_bytes())
    result = run("evaluate", surface, pattern, "-o", out, "--force", "-q")
    assert result.exit_code == 2 and "holds a job run" in error_line(result)
    assert sorted(p.name for p in out.iterdir()) == before
    monkeypatch.chdir(out)
    result = run("example", "hypar", "-o", ".", "-q", "--force")
    assert result.exit_code == 2 and "the current folder" in error_line(result)
    assert sorted(p.name for p in out.iterdir()) == before
