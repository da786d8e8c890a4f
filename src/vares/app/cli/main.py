"""The ``vares`` command: one module per subcommand, wired together here."""

from __future__ import annotations

import typer

from .batch import batch
from .blank import drape_blank
from .cut import cut
from .drape import drape
from .erect import erect
from .evaluate import evaluate
from .fabric import fabric_app
from .fabrics import fabrics
from .laminate import laminate
from .panels import panels
from .pattern import example, pattern
from .run import run

__all__ = ["app", "main"]

app = typer.Typer(
    help="Cutting patterns of doubly curved membranes by the Variation of Reference Strategy.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
for command in (pattern, example, run, evaluate, fabrics, panels, cut, erect, batch, drape):
    app.command()(command)
app.command()(laminate)
app.command("drape-blank")(drape_blank)
app.add_typer(fabric_app, name="fabric")


def _print_version(value: bool) -> None:
    if value:
        from ..._version import __version__

        typer.echo(f"vares {__version__}")
        raise typer.Exit()


@app.callback()
def _options(
    version: bool = typer.Option(
        False, "--version", callback=_print_version, is_eager=True, help="Print the version."
    ),
) -> None:
    """Cutting patterns of doubly curved membranes by the Variation of Reference Strategy."""


def main() -> None:
    """Entry point of the ``vares`` script.

    It leaves as soon as its work is done: once the exit handlers have run (pools shut down,
    temporary folders removed, streams flushed), the process ends without tearing down every
    module's objects one by one, which took 0.2–0.4 s after a solve (numba's type system leaves
    some 10⁵ objects), a fifth of a small job (docs/benchmarks.md)."""
    import atexit
    import os
    import sys

    _keep_freed_memory()
    try:
        app()
        code = 0
    except SystemExit as exit_:
        code = exit_.code
    if code is None:
        code = 0
    elif not isinstance(code, int):
        print(code, file=sys.stderr)
        code = 1
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe or stream
            pass
    os._exit(code)


def _keep_freed_memory() -> None:
    """Let glibc keep the memory a Newton iteration frees for the next one's arrays of the same
    size, instead of handing it back to the system and faulting it in afresh (a fresh process's
    100k-triangle solve took 1.16 s instead of 0.95 s: docs/benchmarks.md). The command owns its
    process, so it may; a program that calls ``vares.solve`` can set ``MALLOC_MMAP_THRESHOLD_``
    and ``MALLOC_TRIM_THRESHOLD_`` in its environment to the same effect."""
    import ctypes
    import platform

    if platform.libc_ver()[0] != "glibc":
        return
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return
    m_trim_threshold, m_mmap_threshold = -1, -3
    mallopt(m_mmap_threshold, 32 * 2**20)  # glibc's largest: arrays below it come from the heap
    mallopt(m_trim_threshold, 2**31 - 1)  # and the heap is not trimmed
