"""The ``vares`` command: one module per subcommand, wired together here."""

from __future__ import annotations

import typer

from .batch import batch
from .cut import cut
from .erect import erect
from .evaluate import evaluate
from .fabrics import fabrics
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
for command in (pattern, example, run, evaluate, fabrics, panels, cut, erect, batch):
    app.command()(command)


def main() -> None:
    """Entry point of the ``vares`` script."""
    app()
