"""``vares evaluate``: any pattern, any ply — the ply-stack check."""

from pathlib import Path
from typing import Annotated, Any

import typer

from ...solver.options import SolveOptions
from ..sections import MaterialOptions
from .common import console, field_table, guarded
from .flags import InputError, build, flags, option_parameter, with_flags
from .pattern import RUN_FLAGS

__all__ = ["evaluate"]

EVALUATE_FLAGS = [
    option_parameter(
        "output",
        Path("evaluation-out"),
        Path,
        "--output",
        "-o",
        help="Output directory.",
        panel="Output",
    ),
    option_parameter(
        "compression_threshold",
        0.0,
        float,
        "--compression-threshold",
        help="Yarn stresses below minus this count as compressed.",
        panel="Output",
    ),
]
_FIBRE_FLAGS = [p for p in flags(SolveOptions) if p.name in ("warp_angle", "fill_angle")]


@with_flags(flags(MaterialOptions), _FIBRE_FLAGS, EVALUATE_FLAGS, RUN_FLAGS[1:])
def evaluate(
    surface: Annotated[Path, typer.Argument(help="The 3D surface mesh.")],
    pattern_file: Annotated[
        Path, typer.Argument(metavar="PATTERN", help="Its pattern (e.g. pattern.obj).")
    ],
    **values: Any,
) -> None:
    """Evaluate a given pattern with a material and yarn directions (ply-stack check).

    Reports where the yarns go into compression (where a ply cut from this pattern wrinkles)
    and writes evaluation.json and evaluation.vtu into the output directory.
    """

    def body() -> None:
        from ...analysis.evaluate import evaluate as evaluate_pattern  # when the command runs
        from ...analysis.statistics import field_statistics
        from ...io.files import write_json
        from ...io.meshes import read_mesh, read_pattern, write_surface
        from ..staging import OutputFolder

        material_options = build(MaterialOptions, values)
        fibres = build(SolveOptions, values)
        material = material_options.build(Path.cwd())
        mesh = read_mesh(surface)
        coordinates = read_pattern(pattern_file, mesh)
        output = values["output"]
        paths = [output / "evaluation.json", output / "evaluation.vtu"]
        folder = OutputFolder(
            output,
            paths,
            force=values["force"],
            inputs=[surface, pattern_file],
            command="evaluate",
        )
        folder.check()
        result = evaluate_pattern(
            mesh,
            coordinates,
            material,
            material_options.thickness,
            warp_angle=fibres.warp_angle,
            fill_angle=fibres.fill_angle,
            compression_threshold=values["compression_threshold"],
        )
        if result.inverted_cells.size:
            raise InputError(f"the pattern inverts {result.inverted_cells.size} cell(s)")
        data = {
            "surface": str(surface),
            "pattern": str(pattern_file),
            "material": {"law": type(material).__name__, **material.parameters},
            "warp": result.fibres.warp,
            "fill": result.fibres.fill,
            "energy": result.energy,
            "compression_threshold": values["compression_threshold"],
            "compressed_cells": result.compressed_cells,
            "compressed_area_fraction": result.compressed_area_fraction,
            "fields": field_statistics(result.fields),
        }
        folder.start()
        try:  # the two files as one set, as every run writes its files
            write_surface(folder.staged(paths[1]), mesh, coordinates, result.fields)
            write_json(folder.staged(paths[0]), data)
            folder.commit()
        finally:
            folder.discard()
        if not values["quiet"]:
            console.print(field_table(result.fields))
            console.print(
                f"yarns in compression in {result.compressed_cells.size} of {mesh.num_cells} "
                f"cells ({100 * result.compressed_area_fraction:.1f} % of the area)"
            )
            for path in paths:
                console.print(f"  wrote {path}")

    guarded(body)
