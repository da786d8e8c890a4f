"""``vares drape``: the kinematic drape of a woven ply on a mould, and its producibility."""

from pathlib import Path
from typing import Annotated, Any

import typer

from ...analysis.drape_options import DrapeOptions
from .common import console, guarded
from .flags import build, flags, option_parameter, with_flags
from .pattern import RUN_FLAGS

__all__ = ["drape"]

OUTPUT_FLAGS = [
    option_parameter(
        "output",
        Path("drape-out"),
        Path,
        "--output",
        "-o",
        help="Output directory.",
        panel="Output",
    ),
]


@with_flags(flags(DrapeOptions), OUTPUT_FLAGS, RUN_FLAGS[1:])
def drape(
    surface: Annotated[Path, typer.Argument(help="The mould's surface mesh.")],
    **values: Any,
) -> None:
    """Drape a woven ply kinematically (pin-jointed net) and check its producibility.

    Writes drape.json (the producibility and the net) and drape.vtu (the mould with the shear
    angle, the producibility class, the yarn directions and the flat pattern per node) into the
    output directory.
    """

    def body() -> None:
        from ...analysis.drape import drape_ply  # when the command runs
        from ...analysis.producibility import CLASSES
        from ...io.files import write_json
        from ...io.meshes import read_mesh, write_surface
        from ..staging import OutputFolder

        options = build(DrapeOptions, values)
        mesh = read_mesh(surface)
        output = values["output"]
        paths = [output / "drape.json", output / "drape.vtu"]
        folder = OutputFolder(
            output, paths, force=values["force"], inputs=[surface], command="drape"
        )
        folder.check()
        ply = drape_ply(mesh, options)
        check, result = ply.producibility, ply.drape
        data = {"surface": str(surface), **ply.summary()}
        data["producibility_codes"] = {name: code for code, name in enumerate(CLASSES)}
        fields = {
            "shear_angle": result.shear_angle,
            "producibility": ply.fields()["producibility"],
            "warp": result.warp,
            "fill": result.fill,
        }
        point_data = {"flat_u": result.material_coordinates[:, 0]}
        point_data["flat_v"] = result.material_coordinates[:, 1]
        folder.start()
        try:
            write_surface(folder.staged(paths[1]), mesh, None, fields, point_data)
            write_json(folder.staged(paths[0]), data)
            folder.commit()
        finally:
            folder.discard()
        if not values["quiet"]:
            _show(check, options.warn_fraction, result.net.valid.sum(), ply.spacing)
            for path in paths:
                console.print(f"  wrote {path}")

    guarded(body)


def _show(check, warn_fraction: float, nodes: int, spacing: float) -> None:
    from rich.table import Table

    locking = check.locking_angle
    table = Table(
        "class",
        "shear",
        "area fraction",
        title=f"producibility (locking {locking:g}°, warn from {warn_fraction * locking:g}°)",
    )
    bands = {
        "ok": f"< {check.warn_angle:g}°",
        "warn": f"{check.warn_angle:g}–{locking:g}°",
        "limit": f"≥ {locking:g}°",
    }
    for name, band in bands.items():
        table.add_row(name, band, f"{100 * check.fractions[name]:.2f} %")
    console.print(table)
    console.print(
        f"net of {nodes} nodes at spacing {spacing:g}; largest shear {check.max_shear:.2f}°; "
        f"{100 * check.covered:.1f} % of the area draped"
    )
