"""``vares drape``: the kinematic drape of a woven ply on a mould, and its producibility."""

from enum import StrEnum
from pathlib import Path
from typing import Annotated, Any

import typer

from .common import console, guarded
from .flags import InputError, option_parameter, with_flags
from .pattern import RUN_FLAGS

__all__ = ["drape"]

#: The fabric kinds of ``vares.materials.forming`` (named here so that the command line does
#: not import the engine; a test checks that the two lists agree).
FABRIC_KIND_NAMES = ("woven-plain", "woven-twill", "woven-satin", "ncf-biaxial")
FabricKindName = StrEnum("FabricKindName", {name: name for name in FABRIC_KIND_NAMES})

DRAPE_FLAGS = [
    option_parameter(
        "seed",
        None,
        tuple[float, float, float] | None,
        "--seed",
        help="Seed point X Y Z on the mould (default: the node nearest the nodes' centroid).",
        panel="Drape",
    ),
    option_parameter(
        "warp",
        (1.0, 0.0, 0.0),
        tuple[float, float, float],
        "--warp",
        help="Warp direction X Y Z at the seed (projected onto the mould).",
        panel="Drape",
    ),
    option_parameter(
        "spacing",
        None,
        float | None,
        "--spacing",
        help="Yarn spacing of the net, mesh length units (default: half the mean edge).",
        panel="Drape",
    ),
    option_parameter(
        "fabric_kind",
        FabricKindName("woven-twill"),
        FabricKindName,
        "--fabric-kind",
        help="Fabric kind: its typical locking angle (docs/composites.md).",
        panel="Producibility",
    ),
    option_parameter(
        "locking_angle",
        None,
        float | None,
        "--locking-angle",
        help="Locking angle in degrees (instead of the fabric kind's).",
        panel="Producibility",
    ),
    option_parameter(
        "warn_fraction",
        0.8,
        float,
        "--warn-fraction",
        help="Warn from this fraction of the locking angle on.",
        panel="Producibility",
    ),
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


@with_flags(DRAPE_FLAGS, RUN_FLAGS[1:])
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
        import numpy as np  # when the command runs

        from ...analysis.producibility import CLASSES, producibility
        from ...geometry.drape import kinematic_drape
        from ...io.files import write_json
        from ...io.meshes import read_mesh, write_surface
        from ...materials.forming import FABRIC_KINDS
        from ..staging import OutputFolder

        mesh = read_mesh(surface)
        kind = FABRIC_KINDS[str(values["fabric_kind"])]
        locking = values["locking_angle"]
        locking = kind.locking_angle if locking is None else locking
        spacing = values["spacing"]
        if spacing is None:
            edges = mesh.edges()
            spacing = 0.5 * float(
                np.linalg.norm(mesh.points[edges[:, 0]] - mesh.points[edges[:, 1]], axis=1).mean()
            )
        if not spacing > 0:
            raise InputError(f"--spacing must be positive; got {spacing}")
        seed = values["seed"]
        if seed is None:
            centre = mesh.points.mean(axis=0)
            seed = mesh.points[np.argmin(np.linalg.norm(mesh.points - centre, axis=1))]
        seed = np.asarray(seed, dtype=float)
        output = values["output"]
        paths = [output / "drape.json", output / "drape.vtu"]
        folder = OutputFolder(
            output, paths, force=values["force"], inputs=[surface], command="drape"
        )
        folder.check()
        result = kinematic_drape(mesh, seed, np.asarray(values["warp"]), spacing)
        check = producibility(
            result.shear_angle, mesh.cell_areas(), locking, values["warn_fraction"]
        )
        net = result.net
        data = {
            "surface": str(surface),
            "seed": seed,
            "warp_direction": values["warp"],
            "spacing": spacing,
            "fabric_kind": kind.name,
            "locking_angle_source": "given" if values["locking_angle"] is not None else kind.source,
            "net_nodes": int(net.valid.sum()),
            "nodes_interpolated_fraction": float(result.node_in_net.mean()),
            "nodes_without_pattern": int(np.isnan(result.material_coordinates[:, 0]).sum()),
            "producibility": check.summary(),
        }
        codes = np.zeros(len(check.classes))
        for code, name in enumerate(CLASSES):
            codes[check.classes == name] = code
        data["producibility_codes"] = {name: code for code, name in enumerate(CLASSES)}
        fields = {
            "shear_angle": result.shear_angle,
            "producibility": codes,
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
            _show(check, locking, values["warn_fraction"], net.valid.sum(), spacing)
            for path in paths:
                console.print(f"  wrote {path}")

    guarded(body)


def _show(check, locking: float, warn_fraction: float, nodes: int, spacing: float) -> None:
    from rich.table import Table

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
