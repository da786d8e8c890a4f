"""``vares drape-blank``: a given blank (a rectangle off the roll, or an outline from a DXF)
draped forward onto a mould, with the mould as a frictionless contact surface."""

from pathlib import Path
from typing import Annotated, Any

import typer

from ..sections import MaterialOptions
from .common import console, guarded
from .flags import InputError, build, flags, option_parameter, with_flags
from .pattern import RUN_FLAGS

__all__ = ["drape_blank"]

PANEL = "Blank"
BLANK_FLAGS = [
    option_parameter("blank_length", None, float | None, "--blank-length",
                     help="Length of a rectangular blank along the warp (x).", panel=PANEL),
    option_parameter("blank_width", None, float | None, "--blank-width",
                     help="Width of a rectangular blank along the fill (y).", panel=PANEL),
    option_parameter("blank_dxf", None, Path | None, "--blank-dxf",
                     help="DXF file with the blank's outline (a closed polyline; warp along x).",
                     panel=PANEL),
    option_parameter("blank_layer", None, str | None, "--blank-layer",
                     help="The DXF layer of the outline (default: the largest closed polyline).",
                     panel=PANEL),
    option_parameter("spacing", None, float | None, "--spacing",
                     help="Mesh size of the blank (default: 1/50 of its larger side).",
                     panel=PANEL),
    option_parameter("seed", None, str | None, "--seed",
                     help="Seed point 'x,y,z' on the mould (default: the node nearest the "
                     "nodes' centroid); the blank's centre (or its outline's centroid) goes there.",
                     panel=PANEL),
    option_parameter("warp", "1,0,0", str, "--warp",
                     help="Warp direction 'x,y,z' at the seed, projected onto the mould.",
                     panel=PANEL),
    option_parameter("flange", None, float | None, "--flange",
                     help="How far the mould is extended beyond its edge for the excess "
                     "(default: the blank's largest distance from its seed).", panel=PANEL),
    option_parameter("output", Path("blank-out"), Path, "--output", "-o",
                     help="Output directory.", panel="Output"),
    option_parameter("units", "mm", str, "--units",
                     help="Units of the coordinates, for blank.dxf (mm, cm, m).", panel="Output"),
]  # fmt: skip


def _vector(text: str, flag: str) -> tuple[float, float, float]:
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 3:
        raise InputError(f"{flag} must be three numbers 'x,y,z'; got {text!r}")
    return values


@with_flags(BLANK_FLAGS, flags(MaterialOptions), RUN_FLAGS[1:])
def drape_blank(
    mould: Annotated[Path, typer.Argument(help="The mould's surface mesh.")],
    **values: Any,
) -> None:
    """Drape a given blank forward onto a mould (frictionless contact, pressed from the seed).

    Writes blank.json (convergence, net and excess areas, shear, compressed area), blank.vtu
    (the blank as it lies on the mould: shear angle, yarn strains, compressed state, on-part
    flag per cell; the flat coordinates per node) and blank.dxf (the flat blank: its outline
    on layer EXTENDED, the trim lines on NET, the warp on ROSETTE) into the output directory.
    """

    def body() -> None:
        import numpy as np

        from ...analysis.blank_drape import drape_blank as drape
        from ...geometry.blank import outline_blank, rectangle_blank
        from ...io.blank_files import read_blank_outline, write_blank_dxf
        from ...io.files import write_json
        from ...io.meshes import read_mesh, write_surface
        from ..staging import OutputFolder

        rectangle = values["blank_length"] is not None or values["blank_width"] is not None
        if rectangle == (values["blank_dxf"] is not None):
            raise InputError("give the blank as --blank-length and --blank-width, or --blank-dxf")
        if rectangle and (values["blank_length"] is None or values["blank_width"] is None):
            raise InputError("a rectangular blank needs both --blank-length and --blank-width")
        if values["units"] not in ("mm", "cm", "m"):
            raise InputError(f"--units must be mm, cm or m; got {values['units']!r}")
        options = build(MaterialOptions, values)
        material = options.build(Path.cwd())
        if not material.needs_fibres:
            raise InputError("a blank drape needs a fabric with yarns (--fabric, or --material "
                             "orthotropic or ncf)")  # fmt: skip
        warp = _vector(values["warp"], "--warp")
        mesh = read_mesh(mould)
        if values["seed"] is not None:
            seed = _vector(values["seed"], "--seed")
        else:
            points = mesh.points
            seed = points[np.argmin(np.linalg.norm(points - points.mean(axis=0), axis=1))]
        spacing = values["spacing"]
        if spacing is not None and not spacing > 0:
            raise InputError(f"--spacing must be > 0; got {spacing:g}")
        if rectangle:
            length, width = values["blank_length"], values["blank_width"]
            spacing = spacing or max(length, width) / 50.0
            blank = rectangle_blank(length, width, spacing)
        else:
            ring = read_blank_outline(values["blank_dxf"], values["blank_layer"])
            spacing = spacing or float(np.ptp(ring, axis=0).max()) / 50.0
            blank = outline_blank(ring, spacing)
        if values["flange"] is not None and values["flange"] < 0:
            raise InputError(f"--flange must not be negative; got {values['flange']}")
        output = values["output"]
        paths = [output / "blank.json", output / "blank.vtu", output / "blank.dxf"]
        inputs = [mould] + ([values["blank_dxf"]] if values["blank_dxf"] else [])
        folder = OutputFolder(
            output, paths, force=values["force"], inputs=inputs, command="drape-blank"
        )
        folder.check()
        result = drape(
            mesh, blank, material, options.thickness, seed=seed, warp_direction=warp,
            flange_width=values["flange"],
        )  # fmt: skip
        summary = {"mould": str(mould), "seed": [float(v) for v in seed], "warp": list(warp)}
        summary |= result.summary()
        fields = {
            "shear_angle": result.shear_angle,
            "warp_strain": result.warp_strain,
            "fill_strain": result.fill_strain,
            "compressed": result.state.astype(float),
            "on_part": result.on_part.astype(float),
            "warp": result.warp,
            "fill": result.fill,
        }
        flat = blank.coordinates
        point_data = {"flat_u": flat[:, 0], "flat_v": flat[:, 1], "outwardness": result.outwardness}
        folder.start()
        try:
            write_json(folder.staged(paths[0]), summary)
            write_surface(folder.staged(paths[1]), result.draped_mesh, None, fields, point_data)
            write_blank_dxf(
                folder.staged(paths[2]), blank, result.trim_lines, units=values["units"]
            )
            folder.commit()
        finally:
            folder.discard()
        if not values["quiet"]:
            state = "converged" if result.converged else f"NOT converged ({result.reason})"
            if result.facet_limited:
                state = (
                    f"converged as far as the mould's facets allow (unbalanced force "
                    f"{100 * summary['unbalanced_force']:.2g} % of the cells' forces)"
                )
            console.print(
                f"blank of {len(blank.coordinates)} nodes draped: {state} in "
                f"{result.iterations} iterations ({result.elapsed:.1f} s); net area "
                f"{result.net_area:.6g}, excess {result.excess_area:.6g}; largest shear on the "
                f"part {summary['max_shear_on_part']:.2f}°, compressed "
                f"{100 * summary['compressed_fraction_on_part']:.1f} % of the part"
            )
            for path in paths:
                console.print(f"  wrote {path}")
        if not result.converged:
            raise typer.Exit(1)

    guarded(body)
