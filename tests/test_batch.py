"""Batches of jobs: local worker processes and a Dask cluster give the same patterns."""

import json

import meshio
import numpy as np
import pytest
from conftest import run

from vares.app.batch import is_complete, run_batch
from vares.app.job import JobError, load_job


def write_jobs(folder, count=8):
    paths = []
    for k in range(count):
        path = folder / f"job{k}.toml"
        path.write_text(
            f'[input]\nexample = "hypar"\n\n[material]\nlaw = "st-venant-kirchhoff"\n'
            f"E = 1000.0\nnu = {0.1 + 0.04 * k}\n\n[fibres]\nwarp_angle = {10.0 * k}\n\n"
            f'[output]\ndirectory = "out{k}"\n'
        )
        paths.append(path)
    return paths


def patterns(folder, count):
    return [meshio.read(folder / f"out{k}" / "pattern.obj").points for k in range(count)]


def test_local_batch_reports_failures_and_skips_complete_jobs(tmp_path):
    paths = write_jobs(tmp_path, 3)
    bad = tmp_path / "bad.toml"
    bad.write_text('[input]\nmesh = "missing.obj"\n')
    seen = []
    statuses = run_batch([*paths, bad], workers=2, callback=seen.append)
    assert [s.status for s in statuses] == ["done", "done", "done", "failed"]
    assert "no such file" in statuses[3].message
    assert len(seen) == 4
    assert all(is_complete(load_job(p)) for p in paths)
    again = run_batch(paths, workers=2)
    assert [s.status for s in again] == ["skipped"] * 3
    # a changed job is not complete any more; its earlier results are replaced only with force
    before = (tmp_path / "out0" / "summary.json").read_text()
    paths[0].write_text(paths[0].read_text().replace("nu = 0.1", "nu = 0.2"))
    assert not is_complete(load_job(paths[0]))
    statuses = run_batch(paths, workers=1)
    assert [s.status for s in statuses] == ["failed", "skipped", "skipped"]
    assert "output exists" in statuses[0].message
    assert (tmp_path / "out0" / "summary.json").read_text() == before
    assert [s.status for s in run_batch(paths[:1], workers=1, force=True)] == ["done"]
    assert is_complete(load_job(paths[0]))


def test_jobs_sharing_an_output_folder_are_refused_before_any_work(tmp_path):
    paths = write_jobs(tmp_path, 2)
    paths[1].write_text(paths[1].read_text().replace('"out1"', '"out0"'))
    with pytest.raises(JobError, match="write into the same folder"):
        run_batch(paths, workers=1)
    assert not (tmp_path / "out0").exists()


def test_batch_command(tmp_path):
    paths = write_jobs(tmp_path, 2)
    result = run("batch", *paths, "--workers", 1)
    assert result.exit_code == 0, result.stderr
    assert "2 done" in result.stderr
    summary = json.loads((tmp_path / "out1" / "summary.json").read_text())
    assert summary["converged"] and summary["job_digest"]
    result = run("batch", paths[0], tmp_path / "nope.toml")
    assert result.exit_code == 2 and "no such file" in result.stderr


@pytest.mark.parametrize("command", ["batch", "fabric band"])
def test_parallel_options_are_checked_alike(tmp_path, command):
    """``vares batch`` and ``vares fabric band`` take the same --workers/--scheduler: no worker
    count below 1 (a batch used every core for 0) and not both (the scheduler won silently)."""
    from pathlib import Path

    fabric = Path(__file__).parents[1] / "examples" / "biaxial" / "pes-batch-42.toml"
    args = (
        ("batch", *write_jobs(tmp_path, 1))
        if command == "batch"
        else ("fabric", "band", "--example", "hypar", "--fabric", fabric, "-o", tmp_path / "out0")
    )
    zero = run(*args, "--workers", 0)
    assert zero.exit_code == 2 and "--workers must be > 0; got 0" in zero.stderr
    both = run(*args, "--workers", 2, "--scheduler", "tcp://127.0.0.1:1")
    assert both.exit_code == 2 and "give --workers or --scheduler, not both" in both.stderr
    assert not (tmp_path / "out0").exists()  # refused before any work


def test_dask_cluster_gives_the_same_patterns_as_local_workers(tmp_path):
    distributed = pytest.importorskip("distributed")
    local, remote = tmp_path / "local", tmp_path / "dask"
    local.mkdir()
    remote.mkdir()
    count = 8
    assert all(s.status == "done" for s in run_batch(write_jobs(local, count), workers=2))
    with distributed.LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
    ) as cluster:
        statuses = run_batch(write_jobs(remote, count), scheduler=cluster.scheduler_address)
    assert [s.status for s in statuses] == ["done"] * count
    for a, b in zip(patterns(local, count), patterns(remote, count), strict=True):
        np.testing.assert_array_equal(a, b)
    assert not np.allclose(patterns(local, count)[0], patterns(local, count)[1])
