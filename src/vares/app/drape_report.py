"""The report's section on a ply draped kinematically beside the pattern (``--drape``): where it
was laid, its producibility, its shear against the pattern's and the net's shear on the surface."""

from __future__ import annotations

import numpy as np

from .html_parts import REPORT_DPI, figure, number, table
from .outcome import PanelOutcome

__all__ = ["drape_section"]


def drape_section(panel: PanelOutcome) -> list[str]:
    """The HTML parts of the section (none without a drape)."""
    ply = panel.drape
    if ply is None:
        return []
    check, units = ply.producibility, panel.units
    locking, source = ply.options.locking
    rows = [
        ("seed", " ".join(number(v, 6) for v in ply.seed)),
        ("warp at the seed", " ".join(number(v, 4) for v in ply.warp)),
        ("yarn spacing", f"{number(ply.spacing)} {units}"),
        ("net nodes", int(ply.drape.net.valid.sum())),
        ("fabric kind", ply.options.fabric_kind),
        ("locking angle", f"{number(locking, 4)}° ({source})"),
        ("warning from", f"{number(check.warn_angle, 4)}°"),
        ("largest shear of the net", f"{number(check.max_shear, 4)}°"),
        ("area with a shear value", f"{100 * check.covered:.1f} %"),
    ]
    rows += [(f"area {name}", f"{100 * value:.2f} %") for name, value in check.fractions.items()]
    parts = [
        "<h2>Kinematic drape and producibility</h2>",
        table(rows, ident="drape"),
    ]
    result = panel.result
    if result.converged:
        against = ply.comparison(result.fields["shear_angle"], panel.mesh.cell_areas())
        if "correlation" in against:
            compared = [
                ("cells compared", against["cells"]),
                (
                    "mean |difference| (area-weighted)",
                    f"{number(against['mean_abs_difference'], 4)}°",
                ),
                ("largest |difference|", f"{number(against['max_abs_difference'], 4)}°"),
                ("largest shear of the pattern", f"{number(against['max_shear'], 4)}°"),
                ("correlation", number(against["correlation"], 4)),
            ]
            parts += [
                "<h3>The pattern's shear against the net's</h3>",
                table(compared, ident="drape-against-pattern"),
            ]
    from ..io.plot import plot_surface_fields  # when a report is written

    shear = np.where(np.isfinite(ply.drape.shear_angle), ply.drape.shear_angle, 0.0)
    titles = {"shear_angle": "shear angle of the kinematic net [°] (0 where it does not reach)"}
    for _, drawing in plot_surface_fields(
        panel.mesh, {"shear_angle": shear}, titles=titles, dpi=REPORT_DPI
    ):
        parts.append(figure(drawing, titles["shear_angle"], "figure-drape-shear", close=False))
    return parts
