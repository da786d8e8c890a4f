"""The command line: ``vares pattern``, ``example``, ``run``, ``evaluate``, ``fabrics``,
``panels``, ``cut``, ``batch``. A thin layer over the job runner: every command builds a job and
runs it; every error becomes one line ``vares: error: …`` and an exit status, never a
traceback."""

from .main import app, main

__all__ = ["app", "main"]
