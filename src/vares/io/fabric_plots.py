"""Figures of a fabric fit (matplotlib): the records and what was read from them.

- :func:`loops_figure`: warp and fill force against strain of a stiffness record, one colour
  per load ratio, with the fitted law on the chosen cycle's loading branches;
- :func:`residuals_figure`: the RMS strain residual per load ratio of each specimen, linear law
  and nonlinear response side by side;
- :func:`compensation_figure`: strains and forces of a compensation record against time, with
  the compensation values where they were read;
- :func:`ratios_plot`: measured against fitted force–strain, one panel per load ratio;
- :func:`cycles_plot`: the strains at the prestress after each load cycle of the compensation
  records, and the compensation values read after the last hold;
- :func:`band_plot`: a structure's pattern dimensions and seam lengths with their band under
  the scatter of the compensation values, and the erected prestress with its band;
- :func:`fabric_figures`: the records' figures of a fit, into a folder.

Every file is written atomically.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..analysis.scatter import Band
from ..materials.biaxial import BiaxialRecord, find_cycles
from ..materials.compensation_law import strains_per_cycle
from ..materials.fitting import CompensationValues, ElasticFit, FabricFit
from .files import write_with

__all__ = [
    "band_plot",
    "compensation_figure",
    "compensation_plot",
    "cycles_plot",
    "fabric_figures",
    "figure_paths",
    "loops_figure",
    "loops_plot",
    "ratios_plot",
    "residuals_figure",
    "residuals_plot",
]


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path: Path) -> Path:
    write_with(Path(path), lambda p: fig.savefig(p, dpi=110))
    return Path(path)


def _branch_cycles(record: BiaxialRecord, fit: ElasticFit):
    cycles = find_cycles(record)
    stages = sorted({c.stage for c in cycles})
    out = []
    for stage in stages:
        members = [c for c in cycles if c.stage == stage]
        chosen = members[-1] if fit.cycle == -1 else members[fit.cycle - 1]
        out.append((members, chosen))
    return out


def loops_figure(record: BiaxialRecord, fit: ElasticFit, path: str | Path) -> Path:
    """Force–strain loops of ``record`` with the law of ``fit`` (dashed) on its chosen cycle
    of each load ratio; written to ``path`` (PNG)."""
    return _written(loops_plot(record, fit), path)


def _written(fig, path: str | Path) -> Path:
    try:
        return _save(fig, Path(path))
    finally:
        _pyplot().close(fig)


def loops_plot(record: BiaxialRecord, fit: ElasticFit):
    """The figure of :func:`loops_figure` (a matplotlib figure, for the caller to close)."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), constrained_layout=True)
    stages = _branch_cycles(record, fit)
    colours = plt.cm.viridis(np.linspace(0, 0.9, max(len(stages), 2)))
    compliance = np.array(
        [[1 / fit.E_w, -fit.nu_fw / fit.E_f], [-fit.nu_wf / fit.E_w, 1 / fit.E_f]]
    )
    for k, (members, chosen) in enumerate(stages):
        span = slice(members[0].start, members[-1].end + 1)
        branch = slice(chosen.start, chosen.loaded + 1)
        force = record.force[branch]
        law = (force - force[0]) @ compliance.T + record.strain[chosen.start]
        for yarn, ax in enumerate(axes):
            ax.plot(
                100 * record.strain[span, yarn],
                record.force[span, yarn],
                color=colours[k],
                lw=0.8,
                label=members[0].label,
            )
            ax.plot(100 * law[:, yarn], force[:, yarn], "--", color="k", lw=0.8)
    for yarn, ax in enumerate(axes):
        name = ("warp", "fill")[yarn]
        ax.set_xlabel(f"{name} strain (%)")
        ax.set_ylabel(f"{name} force (kN/m)")
        ax.grid(alpha=0.3)
    axes[0].legend(title="warp:fill", fontsize=8)
    cycle = "last cycle" if fit.cycle == -1 else f"cycle {fit.cycle}"
    fig.suptitle(
        f"{record.name}: dashed, the fitted law on the {cycle} of each ratio (E1 {fit.E_w:.0f}, "
        f"E2 {fit.E_f:.0f} kN/m, ν12 {fit.nu_wf:.3f}; residual {fit.rms:.1e})",
        fontsize=9,
    )
    return fig


def residuals_figure(
    fits: list[ElasticFit] | tuple[ElasticFit, ...],
    path: str | Path,
    noise: float | None = None,
) -> Path:
    """RMS strain residual (warp and fill together) per load ratio of each fit, linear law and
    nonlinear response; ``noise``: a strain level drawn as a line (e.g. the gauge's)."""
    return _written(residuals_plot(fits, noise), path)


def residuals_plot(fits: list[ElasticFit] | tuple[ElasticFit, ...], noise: float | None = None):
    """The figure of :func:`residuals_figure`."""
    plt = _pyplot()
    labels = [r.label for r in fits[0].residuals]
    x = np.arange(len(labels))
    fig, ax = plt.subplots(figsize=(7, 3.4), constrained_layout=True)
    width = 0.8 / (2 * len(fits))
    for i, fit in enumerate(fits):
        for j, (rows, kind) in enumerate(
            ((fit.residuals, "linear"), (fit.nonlinear_residuals, "nonlinear"))
        ):
            if not rows:
                continue
            rms = [1e4 * np.hypot(r.rms_warp, r.rms_fill) / np.sqrt(2) for r in rows]
            offset = -0.4 + width * (2 * i + j + 0.5)
            ax.bar(x + offset, rms, width=width, label=f"{fit.name}, {kind}")
    if noise is not None:
        ax.axhline(1e4 * noise, color="k", lw=0.8, ls=":", label="strain noise")
    ax.set_xticks(x, labels)
    ax.set_xlabel("load ratio warp:fill")
    ax.set_ylabel("RMS strain residual (10⁻⁴)")
    ax.legend(fontsize=7)
    ax.set_title("residual of the fit per load ratio", fontsize=9)
    return fig


def compensation_figure(
    record: BiaxialRecord, values: CompensationValues, path: str | Path
) -> Path:
    """Strains (and forces, grey) of a compensation record against time, the compensation
    values marked where they were read."""
    return _written(compensation_plot(record, values), path)


def compensation_plot(record: BiaxialRecord, values: CompensationValues):
    """The figure of :func:`compensation_figure`."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 3.8), constrained_layout=True)
    minutes = record.time / 60
    ax.plot(minutes, 100 * record.strain[:, 0], lw=0.8, label="warp strain")
    ax.plot(minutes, 100 * record.strain[:, 1], lw=0.8, label="fill strain")
    ax.set_xlabel("time (min)")
    ax.set_ylabel("strain (%)")
    twin = ax.twinx()
    twin.plot(minutes, record.force[:, 0], color="0.6", lw=0.6)
    twin.plot(minutes, record.force[:, 1], color="0.8", lw=0.6)
    twin.set_ylabel("force (kN/m, grey)")
    ax.plot([values.time / 60] * 2, [100 * values.warp, 100 * values.fill], "ko")
    ax.annotate(
        f"compensation values\nwarp {100 * values.warp:.3f} %, fill {100 * values.fill:.3f} %",
        (values.time / 60, 100 * values.warp),
        xytext=(-170, 10),
        textcoords="offset points",
        fontsize=8,
    )
    ax.legend(loc="upper left", fontsize=8)
    ax.grid(alpha=0.3)
    p = values.prestress
    ax.set_title(f"{record.name}: compensation values at {p[0]:g}/{p[1]:g} kN/m", fontsize=9)
    return fig


def ratios_plot(record: BiaxialRecord, fit: ElasticFit):
    """One panel per load ratio: warp and fill force against strain on the loading branch of
    the fitted cycle (solid) and the fitted law from the branch's first sample (dashed)."""
    plt = _pyplot()
    stages = _branch_cycles(record, fit)
    fig, axes = plt.subplots(
        1, len(stages), figsize=(2.4 * len(stages), 2.8), sharey=True, constrained_layout=True
    )
    axes = np.atleast_1d(axes)
    compliance = np.array(
        [[1 / fit.E_w, -fit.nu_fw / fit.E_f], [-fit.nu_wf / fit.E_w, 1 / fit.E_f]]
    )
    for ax, (members, chosen) in zip(axes, stages, strict=True):
        branch = slice(chosen.start, chosen.loaded + 1)
        force = record.force[branch]
        law = (force - force[0]) @ compliance.T + record.strain[chosen.start]
        for yarn, colour in ((0, "C0"), (1, "C1")):
            name = ("warp", "fill")[yarn]
            ax.plot(100 * record.strain[branch, yarn], force[:, yarn], color=colour, label=name)
            ax.plot(100 * law[:, yarn], force[:, yarn], "--", color="k", lw=0.8)
        ax.set_title(f"{members[0].label}", fontsize=9)
        ax.set_xlabel("strain (%)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("force (kN/m)")
    axes[0].legend(fontsize=7)
    fig.suptitle(f"{record.name}: measured (solid) and fitted (dashed) per load ratio", fontsize=9)
    return fig


def cycles_plot(
    pairs: list[tuple[BiaxialRecord, CompensationValues]],
):
    """The warp and fill strains at the prestress before each load cycle and after the last
    (:func:`strains_per_cycle`) of each compensation record, and its compensation values after
    the last hold (filled markers)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 3.4), constrained_layout=True)
    for k, (record, values) in enumerate(pairs):
        points = strains_per_cycle(record, values.prestress)
        cycles = [p[0] for p in points]
        after = (max(cycles) + 1) if cycles else 1
        for yarn, marker in ((0, "o"), (1, "s")):
            name = ("warp", "fill")[yarn]
            colour = f"C{2 * k + yarn}"
            ax.plot(
                cycles,
                [100 * p[1 + yarn] for p in points],
                marker=marker,
                mfc="none",
                color=colour,
                label=f"{values.name} {name}",
            )
            ax.plot(after, 100 * (values.warp, values.fill)[yarn], marker, color=colour)
    ax.set_xlabel("load cycles done (last point: after the final hold)")
    ax.set_ylabel("strain at the prestress (%)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("compensation per cycle", fontsize=9)
    return fig


def band_plot(band: Band, units: str = "m"):
    """Left: every length of the band (pattern dimensions, seam lengths) as its samples' and
    band's deviation from the nominal value, in thousandths of ``units``; right: the erected
    prestress (``prestress …`` figures) with its band."""
    plt = _pyplot()
    lengths = [n for n in band.names if not n.startswith("prestress") and not n.endswith("area")]
    stresses = [n for n in band.names if n.startswith("prestress")]
    fig, axes = plt.subplots(
        1,
        2 if stresses else 1,
        figsize=(10, 0.8 + 0.22 * max(len(lengths), 6)),
        constrained_layout=True,
        squeeze=False,
    )
    ax = axes[0, 0]
    for row, name in enumerate(lengths):
        values = 1e3 * (np.asarray(band.samples[name]) - band.nominal[name])
        ax.plot(values, np.full(values.size, row), "|", color="C0", ms=6)
        spread = 1e3 * band.spread(name)
        ax.errorbar(0.0, row, xerr=spread, fmt="o", color="k", ms=3, capsize=3)
    ax.set_yticks(range(len(lengths)), lengths, fontsize=7)
    ax.invert_yaxis()
    ax.axvline(0.0, color="0.7", lw=0.8)
    ax.set_xlabel(f"deviation from the nominal pattern (10⁻³ {units})")
    ax.set_title(f"lengths: samples (|) and band (± {band.sigmas:g} std)", fontsize=9)
    ax.grid(alpha=0.3, axis="x")
    if stresses:
        ax = axes[0, 1]
        for row, name in enumerate(stresses):
            values = np.asarray(band.samples[name])
            ax.plot(values, np.full(values.size, row), "|", color="C1", ms=6)
            ax.errorbar(
                band.nominal[name], row, xerr=band.spread(name), fmt="o", color="k", ms=3, capsize=3
            )
        ax.set_yticks(
            range(len(stresses)), [n.removeprefix("prestress ") for n in stresses], fontsize=7
        )
        ax.invert_yaxis()
        ax.set_xlabel("erected membrane force (force per length)")
        ax.set_title("erected prestress of the nominal patterns", fontsize=9)
        ax.grid(alpha=0.3, axis="x")
    return fig


def figure_paths(
    fitted: FabricFit, records: list[BiaxialRecord], directory: str | Path
) -> list[tuple[str, object, BiaxialRecord | None, Path]]:
    """What :func:`fabric_figures` draws: ``(kind, fit or values, record, path)`` each, with
    ``SPECIMEN_loops.png`` per stiffness record, ``residuals.png`` and
    ``SPECIMEN_compensation.png`` per compensation record (a repeated name gets ``-2``, …)."""
    directory = Path(directory)
    by_key = {(r.name, r.source): r for r in records}
    planned: list[tuple[str, object, BiaxialRecord | None, Path]] = []

    def target(name: str, kind: str) -> Path:
        stem = "".join(c if c.isalnum() or c in "-_." else "_" for c in name) or "specimen"
        path, k = directory / f"{stem}_{kind}.png", 1
        while any(path == p for *_, p in planned):
            k += 1
            path = directory / f"{stem}-{k}_{kind}.png"
        return path

    for fit in fitted.fits:
        record = by_key.get((fit.name, fit.source))
        if record is not None:
            planned.append(("loops", fit, record, target(fit.name, "loops")))
    planned.append(("residuals", fitted.fits, None, directory / "residuals.png"))
    for values in fitted.compensations:
        record = by_key.get((values.name, values.source))
        if record is not None:
            planned.append(("compensation", values, record, target(values.name, "compensation")))
    return planned


def fabric_figures(
    fitted: FabricFit, records: list[BiaxialRecord], directory: str | Path
) -> list[Path]:
    """All figures of a fit into ``directory`` (made if missing; see :func:`figure_paths`)."""
    Path(directory).mkdir(parents=True, exist_ok=True)
    written = []
    for kind, item, record, path in figure_paths(fitted, records, directory):
        if kind == "loops":
            written.append(loops_figure(record, item, path))
        elif kind == "residuals":
            written.append(residuals_figure(item, path))
        else:
            written.append(compensation_figure(record, item, path))
    return written
