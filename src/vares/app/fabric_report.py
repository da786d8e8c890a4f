"""The HTML reports of a fabric: its fit to the biaxial test records (``vares fabric fit
--report``) and the band of a structure's patterns under its scatter (``vares fabric band -o``).

The fit's report shows, per stiffness record, the measured against the fitted force–strain
response per load ratio and the loops of all cycles; the residual per load ratio; per
compensation record its strains against time and the compensation per cycle; and the tables of
the constants and compensation values. The band's report shows the sampled compensation values,
every figure's band and the pattern dimensions with their band (docs/fabrics.md).
"""

from __future__ import annotations

import html

from ..io.fabric_plots import (
    band_plot,
    compensation_plot,
    cycles_plot,
    loops_plot,
    ratios_plot,
    residuals_plot,
)
from ..materials.biaxial import BiaxialRecord
from ..materials.fitting import FabricFit
from .fabric_band import FabricBand
from .html_parts import figure, number, page, report_drawing, table

__all__ = ["band_report", "band_section", "compensation_rows", "constant_rows", "fit_report"]


def _record(records: list[BiaxialRecord], name: str, source: str) -> BiaxialRecord | None:
    return next((r for r in records if (r.name, r.source) == (name, source)), None)


def constant_rows(fitted: FabricFit) -> list[tuple[str, ...]]:
    """The constants table: per specimen its name, E1, E2, nu12, nu21 (± standard error of the
    fit) and rms residual; last the mean ± std over the specimens (no residual)."""
    rows = [
        (
            f.name,
            f"{f.E_w:.1f} ± {f.standard_errors['E_w']:.1f}",
            f"{f.E_f:.1f} ± {f.standard_errors['E_f']:.1f}",
            f"{f.nu_wf:.3f} ± {f.standard_errors['nu_wf']:.3f}",
            f"{f.nu_fw:.3f} ± {f.standard_errors['nu_fw']:.3f}",
            f"{f.rms:.2e}",
        )
        for f in fitted.fits
    ]
    m, s = fitted.constants.mean, fitted.constants.std
    rows.append(
        (
            "mean ± std",
            f"{m['E_w']:.1f} ± {s['E_w']:.1f}",
            f"{m['E_f']:.1f} ± {s['E_f']:.1f}",
            f"{m['nu_wf']:.3f} ± {s['nu_wf']:.3f}",
            f"{m['nu_fw']:.3f} ± {s['nu_fw']:.3f}",
            "",
        )
    )
    return rows


def compensation_rows(fitted: FabricFit) -> list[tuple[str, str, str]]:
    """The compensation table (warp, fill in %): per specimen, the mean ± std and, when a law was
    fitted, its value; empty without compensation records."""
    if fitted.compensation is None:
        return []
    rows = [
        (c.name, f"{100 * c.warp:.3f} %", f"{100 * c.fill:.3f} %") for c in fitted.compensations
    ]
    cm, cs = fitted.compensation.mean, fitted.compensation.std
    rows.append(
        (
            "mean ± std",
            f"{100 * cm['warp']:.3f} ± {100 * cs['warp']:.3f} %",
            f"{100 * cm['fill']:.3f} ± {100 * cs['fill']:.3f} %",
        )
    )
    law = fitted.law_compensation()
    if law is not None:
        rows.append(("fitted law", f"{100 * law[0]:.3f} %", f"{100 * law[1]:.3f} %"))
    return rows


def fit_report(fitted: FabricFit, records: list[BiaxialRecord]) -> str:
    """The fit's report (one HTML page, figures embedded)."""
    single = [
        f"the {what} come from one specimen: their scatter is unknown (written as 0)"
        for what, summary in (
            ("constants", fitted.constants),
            ("compensation values", fitted.compensation),
        )
        if summary is not None and summary.specimens == 1
    ]
    poor = [f.name for f in fitted.fits if f.linear_is_poor]
    if poor:
        single.append(
            f"the linear law fits {', '.join(poor)} poorly (the nonlinear response leaves less "
            "than two thirds of its residual): the constants are secant values over the range"
        )
    parts = page(fitted.name, f"Fabric fit: {fitted.name}", "fitted", single)
    parts.append("<h2>Elastic constants (MSAJ/M-02)</h2>")
    parts.append(
        table(
            constant_rows(fitted),
            ["specimen", "E1 (kN/m)", "E2 (kN/m)", "nu12", "nu21", "rms residual"],
            "constants",
        )
    )
    parts.append(
        f"<p>G12 = {fitted.G12:g} kN/m {html.escape(fitted.G12_source)} (not measured by "
        "biaxial tests).</p>"
    )
    residuals = [
        (f.name, r.label, f"{r.rms_warp:.2e}", f"{r.rms_fill:.2e}", r.samples)
        for f in fitted.fits
        for r in f.residuals
    ]
    parts.append(table(residuals, ["specimen", "load ratio", "rms warp", "rms fill", "samples"]))
    with report_drawing():
        for f in fitted.fits:
            record = _record(records, f.name, f.source)
            if record is None:
                continue
            labels = ", ".join(r.label for r in f.residuals)
            parts.append(
                figure(
                    ratios_plot(record, f),
                    f"{f.name}: measured and fitted per load ratio ({labels})",
                    f"ratios-{f.name}",
                )
            )
            parts.append(figure(loops_plot(record, f), f"{f.name}: all cycles", f"loops-{f.name}"))
        parts.append(figure(residuals_plot(fitted.fits), "residual per load ratio", "residuals"))
        if fitted.compensation is not None and fitted.prestress is not None:
            p = fitted.prestress
            parts.append(f"<h2>Compensation values (EN 17117-2) at {p[0]:g}/{p[1]:g} kN/m</h2>")
            parts.append(
                table(compensation_rows(fitted), ["specimen", "warp", "fill"], "compensation")
            )
            pairs = [
                (record, c)
                for c in fitted.compensations
                if (record := _record(records, c.name, c.source)) is not None
            ]
            if pairs:
                parts.append(figure(cycles_plot(pairs), "compensation per cycle", "cycles"))
            for record, c in pairs:
                parts.append(
                    figure(
                        compensation_plot(record, c),
                        f"{c.name}: strains against time",
                        f"compensation-{c.name}",
                    )
                )
    parts.append("</body></html>")
    return "\n".join(parts)


def band_report(band: FabricBand, units: str = "m") -> str:
    """The band's report (one HTML page, the figure embedded)."""
    parts = page(band.fabric.name, f"Pattern band: {band.fabric.name}", "converged", [])
    with report_drawing():
        parts += band_section(band, units)
    parts.append("</body></html>")
    return "\n".join(parts)


def band_section(band: FabricBand, units: str = "m", level: int = 2) -> list[str]:
    """The band as parts of an HTML page: the fabric and its samples, every figure's band, the
    figure of the pattern dimensions with their band (drawn: call it inside
    :func:`~vares.app.html_parts.report_drawing`). ``level``: of the section headings."""
    scatter = band.options
    h = f"h{level}"
    parts = [f"<{h}>Fabric and samples</{h}>"]
    parts.append(f"<p>{html.escape(band.fabric.name)} ({html.escape(band.fabric.source)}): ")
    c, s = band.fabric.compensation, band.constants
    if scatter.sampled == "constants" and s is not None:
        f = band.fabric
        parts.append(
            f"fitted constants E1 {f.E1:.1f} ± {s.E1:.1f}, E2 {f.E2:.1f} ± {s.E2:.1f} kN/m, "
            f"nu12 {f.nu12:.3f} ± {s.nu12:.3f} ({s.specimens or '?'} specimens); G12 "
            f"{f.G12:g} kN/m. "
        )
    elif c is not None:
        parts.append(
            f"compensation values at {c.prestress[0]:g}/{c.prestress[1]:g} kN/m warp "
            f"{100 * c.warp:.3f} ± {100 * c.warp_std:.3f} %, fill {100 * c.fill:.3f} ± "
            f"{100 * c.fill_std:.3f} % ({c.specimens or '?'} specimens). "
        )
    parts.append(
        f"{scatter.samples} samples (seed {scatter.seed}) of {html.escape(band.sampled)}; the "
        f"band is the nominal value ± {scatter.sigmas:g} sample standard deviations. "
        "Prestress: the nominal patterns erected with the fabric of each sample (prestress "
        f"{band.prestress[0]:g}/{band.prestress[1]:g}).</p>"
    )
    rows = [
        (
            name,
            number(d["nominal"], 7),
            f"± {number(d['spread'], 3)}",
            f"{number(d['min'], 7)} … {number(d['max'], 7)}",
        )
        for name, d in band.band.to_dict().items()
    ]
    parts.append(f"<{h}>Band</{h}>")
    parts.append(
        table(
            rows,
            ["figure", "nominal", f"± {scatter.sigmas:g} std", "samples min … max"],
            "band",
        )
    )
    parts.append(
        figure(band_plot(band.band, units), "pattern dimensions with their band", "band-plot")
    )
    seconds = band.seconds
    parts.append(
        f"<p>Nominal case {seconds.get('nominal', 0):.2f} s; {scatter.samples} samples "
        f"{seconds.get('samples', 0):.2f} s.</p>"
    )
    return parts
