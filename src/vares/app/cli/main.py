"""The ``vares`` command: one module per subcommand, wired together here.

A run imports only its own subcommand's module (:func:`main`): building every command's
options, and importing what they declare them from, took a tenth of a small job's time
(docs/benchmarks.md). ``app``, the whole command line, is built when first asked for.
"""

from __future__ import annotations

import importlib

import typer

__all__ = ["app", "build_app", "main"]

app: typer.Typer  # the whole command line (built by the module's __getattr__)

#: The subcommands in the order ``vares --help`` lists them: name → (module, function).
COMMANDS = {
    "pattern": (".pattern", "pattern"),
    "example": (".pattern", "example"),
    "run": (".run", "run"),
    "evaluate": (".evaluate", "evaluate"),
    "fabrics": (".fabrics", "fabrics"),
    "panels": (".panels", "panels"),
    "cut": (".cut", "cut"),
    "erect": (".erect", "erect"),
    "batch": (".batch", "batch"),
    "drape": (".drape", "drape"),
    "laminate": (".laminate", "laminate"),
    "drape-blank": (".blank", "drape_blank"),
}
#: Groups of subcommands: name → (module, Typer app).
GROUPS = {"fabric": (".fabric", "fabric_app")}


def _print_version(value: bool) -> None:
    if value:
        from ..._version import __version__

        typer.echo(f"vares {__version__}")
        raise typer.Exit()


def _options(
    version: bool = typer.Option(
        False, "--version", callback=_print_version, is_eager=True, help="Print the version."
    ),
) -> None:
    """Cutting patterns of doubly curved membranes by the Variation of Reference Strategy."""


def build_app(only: str | None = None) -> typer.Typer:
    """The command line, or the part of it that runs the subcommand ``only`` (the same
    command, options and messages)."""
    built = typer.Typer(
        help="Cutting patterns of doubly curved membranes by the Variation of Reference Strategy.",
        no_args_is_help=True,
        add_completion=False,
        pretty_exceptions_enable=False,
    )
    for name, (module, attribute) in COMMANDS.items():
        if only in (None, name):
            function = getattr(importlib.import_module(module, __package__), attribute)
            built.command(name)(function)
    for name, (module, attribute) in GROUPS.items():
        if only in (None, name):
            group = getattr(importlib.import_module(module, __package__), attribute)
            built.add_typer(group, name=name)
    built.callback()(_options)
    return built


def __getattr__(name: str) -> typer.Typer:
    if name == "app":
        value = build_app()
        globals()["app"] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


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
    first = sys.argv[1] if len(sys.argv) > 1 else None
    command = build_app(first) if first in COMMANDS or first in GROUPS else build_app()
    try:
        command()
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
