"""The command line: ``vares pattern``, ``example``, ``run``, ``evaluate``, ``fabrics``,
``panels``, ``cut``, ``batch``. A thin layer over the job runner: every command builds a job and
runs it; every error becomes one line ``vares: error: …`` and an exit status, never a
traceback."""

from .main import main

__all__ = ["app", "main"]


def __getattr__(name: str) -> object:
    if name == "app":  # the whole command line, built when first asked for
        from .main import app

        return app
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
