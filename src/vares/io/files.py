"""Writing files safely: atomically, and never over an existing file unless allowed.

A file is first written under a temporary name in its target folder and then renamed, so a
failure never leaves a half-written file behind, and an existing file is only replaced when the
caller allows it.
"""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Callable, Iterable
from contextlib import contextmanager
from pathlib import Path

import numpy as np

__all__ = [
    "OutputExistsError",
    "atomic_path",
    "check_writable",
    "current_umask",
    "write_bytes",
    "write_json",
    "write_text",
    "write_with",
]


class OutputExistsError(FileExistsError):
    """An output file exists and overwriting was not allowed."""


def check_writable(paths: Iterable[Path], overwrite: bool) -> None:
    """Raise :class:`OutputExistsError` naming the paths that exist, unless ``overwrite``."""
    existing = [str(p) for p in paths if p.exists()]
    if existing and not overwrite:
        raise OutputExistsError(f"output exists: {', '.join(existing)} (use --force to overwrite)")


@contextmanager
def atomic_path(path: Path):
    """Yield a temporary path beside ``path`` (same suffix); rename it to ``path`` on success."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(
        dir=path.parent, prefix=f".{path.stem}-", suffix=path.suffix
    )
    os.close(handle)
    os.chmod(temporary, 0o666 & ~current_umask())
    try:
        yield Path(temporary)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


def current_umask() -> int:
    """The process's file mode creation mask (read without changing it for good)."""
    current = os.umask(0)
    os.umask(current)
    return current


def write_with(path: Path, writer: Callable[[Path], None]) -> None:
    with atomic_path(path) as temporary:
        writer(temporary)


def write_text(path: Path, text: str) -> None:
    """Write ``text`` (UTF-8) atomically."""
    write_with(Path(path), lambda p: p.write_text(text, encoding="utf-8"))


def write_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` atomically."""
    write_with(Path(path), lambda p: p.write_bytes(data))


def write_json(path: Path, data: dict) -> None:
    """Write ``data`` as indented JSON (numpy scalars and arrays converted)."""

    def default(value):
        if isinstance(value, np.ndarray):
            return value.tolist()
        if isinstance(value, np.generic):
            return value.item()
        raise TypeError(f"cannot write {type(value).__name__} to JSON")

    write_text(path, json.dumps(data, indent=2, default=default, allow_nan=True) + "\n")
