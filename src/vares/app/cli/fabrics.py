"""``vares fabrics``: the fabric presets and their sources."""

from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.table import Table

from ...materials import load_presets, presets
from .common import guarded

__all__ = ["fabrics"]


def fabrics(
    presets_file: Annotated[
        Path | None, typer.Option("--presets", help="TOML file with your own presets.")
    ] = None,
) -> None:
    """List the fabric presets (typical values: use your own biaxial test values to cut)."""

    def body() -> None:
        catalogue = presets() | (load_presets(presets_file) if presets_file else {})
        table = Table(
            "preset",
            "E1 (warp)",
            "E2 (fill)",
            "G12",
            "nu12",
            "description",
            title="fabric presets: stiffness E·t as force per length (thickness 1)",
        )
        for name, p in catalogue.items():
            table.add_row(
                name, f"{p.E1:g}", f"{p.E2:g}", f"{p.G12:g}", f"{p.nu12:g}", p.description
            )
        out = Console(highlight=False, soft_wrap=True)
        out.print(table)
        for name, p in catalogue.items():
            out.print(f"{name}: {p.source}")

    guarded(body)
