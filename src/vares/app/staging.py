"""An output folder that holds one whole run: written beside it, then put in place at once.

A run writes its files into a hidden staging folder next to the output folder. When every file
is written, the staging folder takes the output folder's place (the previous run, if any, is
moved aside first and then deleted), so an output folder holds one whole run or the previous
one — never a mix, also when a run is interrupted. A manifest (``.vares-run.json``) lists the
files of the run and which command wrote them, so the next run knows which files it may
replace (``--force`` replaces a run of the same command only). The staging folder, and the
previous run while it is moved aside, name their process in ``.vares-staging.json``: the next
run into the same folder on the same machine removes those of a process that was killed, and
puts back a previous run left aside by a process killed in the middle of the swap. A staging
folder without that name (a finished run kept beside a folder that changed meanwhile) is never
removed.

Before any work :meth:`OutputFolder.check` refuses what would lose something: an output path
that is a file, the current folder or one containing it, a folder holding files vares did not
write (they would be lost), an existing run without ``force`` or of another command, an input
among the files to be written, a folder that cannot be written.
An input that a previous run wrote into the folder (a job file saved there) is carried over.
"""

from __future__ import annotations

import glob
import json
import os
import shutil
import socket
import tempfile
import time
from collections.abc import Iterable
from pathlib import Path

from .._version import __version__
from ..io.files import OutputExistsError, current_umask, write_text

__all__ = [
    "ABANDONED_AFTER_HOURS",
    "MANIFEST",
    "OutputFolder",
    "add_to_manifest",
    "listed",
    "process_start",
]

#: The file in an output folder that lists what the run wrote.
MANIFEST = ".vares-run.json"
#: The file in a staging folder naming the process that writes it (removed after the swap).
OWNER = ".vares-staging.json"
#: The files of an output folder that are not the run's own.
_BOOKKEEPING = (MANIFEST, OWNER)


class OutputFolder:
    """The output folder ``directory`` of a run that will write ``planned`` (paths inside it)
    and reads ``inputs``; see the module docs. A folder inside another run's (``erect/``) has
    no manifest of its own (``manifest=False``): the files that run lists in it are ``known``.
    ``command`` names what writes the folder (``"job"``, ``"evaluate"``): a run of another
    command is never replaced."""

    def __init__(
        self,
        directory: Path,
        planned: Iterable[Path],
        *,
        force: bool,
        inputs: Iterable[Path],
        manifest: bool = True,
        known: Iterable[Path] = (),
        command: str = "job",
    ) -> None:
        self.directory = Path(directory).resolve()
        self.planned = [Path(p).resolve() for p in planned]
        self.force = force
        self.inputs = {Path(p).resolve() for p in inputs}
        self.manifest = manifest
        self.known = {Path(p).resolve() for p in known}
        self.command = command
        self.staging: Path | None = None

    # ------------------------------------------------------------------ before the work
    def check(self) -> None:
        """Refuse (with a one-line error) anything that would lose a file or fail late."""
        for path in self.planned:
            if path in self.inputs:
                raise OutputExistsError(
                    f"the output {path} is an input of the run: choose another output folder"
                )
        for path in self.inputs:  # a job file there is carried over; anything else is replaced
            if self.directory in path.parents and path.suffix.lower() != ".toml":
                raise OutputExistsError(
                    f"the input {path} lies in the output folder, which the run replaces: "
                    "move it out or choose another output folder"
                )
        if self.directory.exists() and not self.directory.is_dir():
            raise OutputExistsError(f"the output folder {self.directory} is a file")
        here = Path.cwd().resolve()
        if self.directory == here or self.directory in here.parents:
            raise OutputExistsError(
                f"the output folder {self.directory} is the current folder or holds it, which "
                "the run would replace: choose a folder of its own"
            )
        _remove_abandoned(self.directory)  # a killed run's leftovers, inside and beside it
        existing = self._existing()
        other = _command(self.directory)
        if existing and other not in (None, self.command):
            raise OutputExistsError(
                f"the output folder {self.directory} holds a {other} run, which a {self.command} "
                "run does not replace: choose another folder"
            )
        self._refuse_foreign(existing)
        if existing and not self.force:
            shown = ", ".join(str(self.directory / p) for p in sorted(existing)[:3])
            raise OutputExistsError(
                f"output exists: {shown}{', …' if len(existing) > 3 else ''} (use --force to "
                "replace the previous run)"
            )
        self._writable()

    def _refuse_foreign(self, existing: set[Path], kept: str = "") -> None:
        """Refuse a folder holding files that no run of vares wrote there (they would be
        lost); ``kept`` says where the finished run waits, when it comes to that at the end."""
        ours = {p.relative_to(self.directory) for p in listed(self.directory)}
        ours |= {p.relative_to(self.directory) for p in [*self.planned, *self.known]}
        foreign = sorted(str(p) for p in existing - ours)
        if foreign:
            shown = ", ".join(foreign[:4]) + (", …" if len(foreign) > 4 else "")
            raise OutputExistsError(
                f"the output folder {self.directory} holds files vares did not write ({shown}); "
                f"they would be lost: choose a new or empty folder{kept}"
            )

    def _existing(self) -> set[Path]:
        if not self.directory.is_dir():
            return set()
        return {
            p.relative_to(self.directory)
            for p in self.directory.rglob("*")
            if p.is_file() and p.name not in _BOOKKEEPING
        }

    def _writable(self) -> None:
        parent = self.directory.parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
            probe = tempfile.mkdtemp(prefix=f".{self.directory.name}.probe-", dir=parent)
            os.rmdir(probe)
        except OSError as exc:
            raise OSError(
                exc.errno, f"cannot write into {parent}: {exc.strerror}", str(parent)
            ) from None

    # ------------------------------------------------------------------ the work
    def start(self) -> Path:
        """Create the staging folder (removing those of killed runs); the run writes into it."""
        _remove_abandoned(self.directory)
        self.staging = _owned_folder(f".{self.directory.name}.vares-", self.directory.parent)
        planned = set(self.planned)
        for path in self.inputs:  # inputs a previous run wrote here stay with the new run
            if self.directory in path.parents and path not in planned:
                target = self.staged(path)
                target.parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(path, target)
        return self.staging

    def staged(self, path: Path) -> Path:
        """Where ``path`` (inside the output folder) is written during the run."""
        return self.staging / Path(path).resolve().relative_to(self.directory)

    def commit(self) -> None:
        """Put the staged run in place of the output folder (module docs)."""
        files = sorted(
            str(p.relative_to(self.staging))
            for p in self.staging.rglob("*")
            if p.is_file() and p.name != OWNER
        )
        if self.manifest:
            manifest = {"vares_version": __version__, "command": self.command, "files": files}
            text = json.dumps(manifest, indent=2) + "\n"
            (self.staging / MANIFEST).write_text(text, encoding="utf-8")
        if self.directory.exists():  # files that appeared during the run are not lost either
            try:
                self._refuse_foreign(self._existing(), f"; this run is kept in {self.staging}")
            except OutputExistsError:
                (self.staging / OWNER).unlink()  # kept: no later run removes it
                self.staging = None
                raise
            shutil.copymode(self.directory, self.staging)
        else:
            os.chmod(self.staging, 0o777 & ~current_umask())
        previous, moved = None, False
        if self.directory.exists():  # aside, named: a run killed here gets it put back
            previous = _owned_folder(f".{self.directory.name}.old-", self.directory.parent)
        try:
            if previous is not None:
                os.replace(self.directory, previous / "run")
                moved = True
            os.replace(self.staging, self.directory)
        except BaseException:
            if moved:
                os.replace(previous / "run", self.directory)
            if previous is not None:
                shutil.rmtree(previous, ignore_errors=True)
            raise
        self.staging = None
        (self.directory / OWNER).unlink(missing_ok=True)
        if previous is not None:
            shutil.rmtree(previous, ignore_errors=True)

    def discard(self) -> None:
        """Remove the staging folder of a run that did not finish."""
        if self.staging is not None:
            shutil.rmtree(self.staging, ignore_errors=True)
            self.staging = None


def _owned_folder(prefix: str, parent: Path) -> Path:
    """A new hidden folder in ``parent`` that names this process (:data:`OWNER`): its id, its
    machine and, where the system tells, when it started (a process id is reused)."""
    folder = Path(tempfile.mkdtemp(prefix=prefix, dir=parent))
    owner = {"pid": os.getpid(), "host": socket.gethostname()}
    started = process_start(os.getpid())
    if started is not None:
        owner["started"] = started
    (folder / OWNER).write_text(json.dumps(owner), encoding="utf-8")
    return folder


#: A staging folder whose process cannot be asked whether it still runs (another machine's,
#: or one that did not say when it started while its id is in use) is taken for abandoned
#: after this many hours.
ABANDONED_AFTER_HOURS = 48.0


def process_start(pid: int) -> str | None:
    """When process ``pid`` started, as a token that differs between two processes of the same
    id (Linux: the boot and the start time in clock ticks), or ``None`` where the system does
    not tell or the process does not exist."""
    try:
        boot = Path("/proc/sys/kernel/random/boot_id").read_text(encoding="ascii").strip()
        stat = Path(f"/proc/{pid}/stat").read_text(encoding="ascii")
    except (OSError, UnicodeDecodeError):
        return None
    fields = stat[stat.rfind(")") + 2 :].split()  # after the command name, which may hold ")"
    return f"{boot}:{fields[19]}" if len(fields) > 19 else None


def _abandoned(folder: Path, owner: dict, host: str) -> bool:
    """Whether the run that wrote ``folder`` (its :data:`OWNER` record ``owner``) has ended."""
    pid = int(owner["pid"])
    if owner["host"] == host:
        if pid == os.getpid() and owner.get("started") in (None, process_start(pid)):
            return False  # this very process
        if not _alive(pid):
            return True
        started, now = owner.get("started"), process_start(pid)
        if started is not None and now is not None:
            return started != now  # the id belongs to another process now
    try:  # its process cannot be asked: by its age
        age = time.time() - (folder / OWNER).stat().st_mtime
    except OSError:
        return False
    return age > ABANDONED_AFTER_HOURS * 3600.0


def _remove_abandoned(directory: Path) -> None:
    """Clean up after runs into ``directory`` (and into folders inside it, as ``erect/``) whose
    process has ended (killed: an interrupted run cleans up itself): remove their staging
    folders, and put back a previous run they had moved aside and not replaced (else remove
    it). A run has ended when its process, on this machine, is gone or its id now names a
    process that started at another time; a run of another machine's process, or one whose
    start is not known while its id is in use, when it is older than
    :data:`ABANDONED_AFTER_HOURS`. POSIX only: elsewhere a process cannot be asked whether it
    lives without a handle to it."""
    if os.name != "posix":
        return
    host = socket.gethostname()
    name = glob.escape(directory.name)
    staged = [*directory.parent.glob(f".{name}.vares-*")]
    aside = [*directory.parent.glob(f".{name}.old-*")]
    if directory.is_dir():
        staged += directory.glob(".*.vares-*")
        aside += directory.glob(".*.old-*")
    for folder in [*staged, *aside]:
        try:
            owner = json.loads((folder / OWNER).read_text(encoding="utf-8"))
            if not _abandoned(folder, owner, host):
                continue
        except (OSError, ValueError, KeyError, TypeError, AttributeError):
            continue  # no owner named: a finished run kept beside the folder, or not ours
        target = folder.parent / folder.name[1:].rsplit(".old-", 1)[0]
        if folder in aside and (folder / "run").is_dir() and not target.exists():
            os.replace(folder / "run", target)  # killed between the two renames of the swap
        shutil.rmtree(folder, ignore_errors=True)


def _command(directory: Path) -> str | None:
    """The command whose run the folder holds, by its manifest (``None``: no manifest)."""
    try:
        data = json.loads((Path(directory) / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data.get("command", "job") if isinstance(data, dict) else None


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True


def listed(directory: Path) -> list[Path]:
    """The files a run's manifest lists (paths inside ``directory``)."""
    try:
        data = json.loads((Path(directory) / MANIFEST).read_text(encoding="utf-8"))
        return [Path(directory) / p for p in data["files"]]
    except (OSError, ValueError, KeyError, TypeError):
        return []


def add_to_manifest(directory: Path, files: Iterable[Path], replacing: Path | None) -> None:
    """List files written into a run's folder afterwards (``vares erect``) in its manifest: in
    place of those it listed in the subfolder ``replacing`` (a rerun may write fewer), or
    beside them (``None``: before the files are put in place, so that a run killed then leaves
    both the old files and the new ones known)."""
    directory = Path(directory).resolve()
    path = directory / MANIFEST
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        data = {"vares_version": __version__, "files": []}
    listed = set(data.get("files", []))
    if replacing is not None:
        sub = Path(replacing).resolve().relative_to(directory)
        listed = {f for f in listed if sub not in Path(f).parents}
    listed |= {str(Path(f).resolve().relative_to(directory)) for f in files}
    data["files"] = sorted(listed)
    text = json.dumps(data, indent=2) + "\n"
    write_text(path, text)
