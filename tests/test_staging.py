"""Output folders: staging folders of runs that ended are removed by the next run, live ones
are not, also where a process id has been reused or the process cannot be asked."""

import json
import os
import socket
import subprocess
import sys
import time

import pytest

from vares.app.staging import ABANDONED_AFTER_HOURS, OWNER, OutputFolder, process_start

pytestmark = pytest.mark.skipif(os.name != "posix", reason="processes are asked on POSIX only")


def _staging(tmp_path, name: str, owner: dict, age_hours: float = 0.0):
    folder = tmp_path / f".out.vares-{name}"
    folder.mkdir()
    (folder / "pattern.dxf").write_text("half written")
    (folder / OWNER).write_text(json.dumps(owner))
    if age_hours:
        then = time.time() - age_hours * 3600.0
        os.utime(folder / OWNER, (then, then))
    return folder


def test_a_staging_folder_names_when_its_process_started(tmp_path):
    started = process_start(os.getpid())
    if started is None:
        pytest.skip("this system does not say when a process started")
    assert process_start(os.getpid()) == started
    child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(30)"])
    try:
        assert process_start(child.pid) not in (None, started)
    finally:
        child.kill()
        child.wait()
    assert process_start(child.pid) is None  # ended
    folder = OutputFolder(tmp_path / "out", [tmp_path / "out" / "a.txt"], force=False, inputs=[])
    staging = folder.start()
    owner = json.loads((staging / OWNER).read_text())
    assert owner == {"pid": os.getpid(), "host": socket.gethostname(), "started": started}
    folder.discard()


def test_stale_staging_folders_go_and_live_ones_stay(tmp_path):
    """A run killed long ago whose process id now names another live process, another
    machine's run older than the limit, and a run that never said when it started, older than
    the limit: removed by the next run. A live run (its id and start time match), another
    machine's recent run and a recent run without a start time: kept."""
    host = socket.gethostname()
    child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"])
    try:
        live = process_start(child.pid)
        if live is None:
            pytest.skip("this system does not say when a process started")
        old = ABANDONED_AFTER_HOURS + 1.0
        _staging(tmp_path, "reused", {"pid": child.pid, "host": host, "started": "0:1"})
        _staging(tmp_path, "live", {"pid": child.pid, "host": host, "started": live}, old)
        _staging(tmp_path, "elsewhere-old", {"pid": 1, "host": f"not-{host}"}, old)
        _staging(tmp_path, "elsewhere", {"pid": 1, "host": f"not-{host}"}, 1.0)
        _staging(tmp_path, "unknown-start-old", {"pid": child.pid, "host": host}, old)
        _staging(tmp_path, "unknown-start", {"pid": child.pid, "host": host}, 1.0)
        out = OutputFolder(tmp_path / "out", [tmp_path / "out" / "a.txt"], force=False, inputs=[])
        out.check()  # the next run into the folder, before its work
        left = sorted(p.name for p in tmp_path.iterdir())
    finally:
        child.kill()
        child.wait()
    assert left == [".out.vares-elsewhere", ".out.vares-live", ".out.vares-unknown-start"]
