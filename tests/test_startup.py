"""A small `vares pattern` job imports what its work needs and no more (docs/benchmarks.md,
"Around the solve"): each output imports its writer when it writes, the erection, structures,
the fabric's band and the plots only for a job that asks for them."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import meshio
import pytest

from vares.geometry.examples import four_point_sail

#: Runs the command line in a fresh process as the ``vares`` script does, and writes the modules
#: it had imported (its exit handlers run before it ends) one a line to the file argv[1].
RUN = """\
import atexit, sys
listing, *arguments = sys.argv[1:]
sys.argv = ["vares", *arguments]
atexit.register(lambda: open(listing, "w").write("\\n".join(sorted(sys.modules))))
from vares.app.cli import main
main()
"""

#: Modules a plain pattern job does without.
NOT_FOR_A_PATTERN = {
    "vares.analysis.erection",
    "vares.structures.matching",
    "vares.structures.cutting",
    "vares.app.fabric_band",
    "vares.parallel",
    "numba",
    "matplotlib",
    "scipy.spatial",
}


@pytest.fixture(scope="module")
def sail(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("sail") / "sail.obj"
    mesh = four_point_sail(n=16)  # 512 triangles: below the compiled kernels' size
    meshio.write(path, meshio.Mesh(mesh.points, list(mesh.cells.items())))
    return path


def _modules_of_a_run(tmp_path: Path, *arguments: str) -> set[str]:
    listing = tmp_path / "modules.txt"
    done = subprocess.run(
        [sys.executable, "-c", RUN, str(listing), *arguments],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    return set(listing.read_text().split())


def test_a_small_pattern_job_imports_only_what_it_uses(sail: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    loaded = _modules_of_a_run(tmp_path, "pattern", str(sail), "-o", str(out), "-q")
    assert (out / "pattern.dxf").is_file() and (out / "pattern.png").is_file()
    # what the run's outputs and checks use is there: the listing is of a run that worked
    assert {"ezdxf", "PIL.Image", "meshio", "shapely", "vares.io.dxf"} <= loaded
    assert not NOT_FOR_A_PATTERN & loaded, sorted(NOT_FOR_A_PATTERN & loaded)


def test_a_job_that_asks_for_them_imports_them(sail: Path, tmp_path: Path) -> None:
    """The guard above can fail: a job with an erection imports the erection analysis."""
    out = tmp_path / "out"
    loaded = _modules_of_a_run(tmp_path, "pattern", str(sail), "-o", str(out), "-q", "--erect")
    assert {"vares.analysis.erection", "vares.app.erection_outputs"} <= loaded
    assert (out / "erect").is_dir()


def test_the_command_line_of_a_pattern_job_imports_no_writer() -> None:
    """Building `vares pattern`'s command line (its options, help and checks) imports no
    output's library: those come with the files that need them."""
    code = (
        "import sys\n"
        "from vares.app.cli.main import build_app\n"
        "build_app('pattern')\n"
        "print(' '.join(sorted(sys.modules)))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    loaded = set(done.stdout.split())
    assert "vares.app.cli.pattern" in loaded
    writers = {"ezdxf", "PIL", "meshio", "shapely", "numba", "matplotlib", "vares.io.dxf"}
    assert not writers & loaded, sorted(writers & loaded)
    assert not NOT_FOR_A_PATTERN & loaded
