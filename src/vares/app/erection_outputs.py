"""The files of an erection, in the output directory's ``erect/``:

``erect.json``                  the key figures (converged, deviation, stresses against the
                                intended prestress, wrinkled and slack area) and the history
``erected.vtu``                 the erected surface with the displacement and normal deviation
                                per node, the membrane forces and states (and those on the design
                                shape, ``design_*``) per cell
``erected.obj``                 the erected surface
``deviation.png``, ``warp_stress.png``, ``fill_stress.png``, ``state.png``  drawn on it
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..io.files import atomic_path, write_json
from ..io.meshes import write_surface

if TYPE_CHECKING:
    from ..analysis.erection import ErectionResult
    from ..analysis.erection_optimum import OptimisedPatterns

__all__ = [
    "ERECTION_FILES",
    "erected_pictures",
    "erection_columns",
    "erection_comparison",
    "erection_figures",
    "erection_files",
    "write_erection",
]

#: The files of an erection, in the output directory's ``erect/``.
ERECTION_FILES = (
    "erect.json",
    "erected.vtu",
    "erected.obj",
    "deviation.png",
    "warp_stress.png",
    "fill_stress.png",
    "state.png",
)


def _number(value: float, digits: int = 4) -> str:
    return f"{value:.{digits}g}"


def erection_columns(
    result: ErectionResult, optimum: OptimisedPatterns | None = None
) -> dict[str, dict[str, object]]:
    """The figures an erection is judged by, per state: the patterns on the design shape and
    erected (with ``optimum``, the erection of optimised patterns: the VaReS patterns' on the
    design shape and erected, then the optimised patterns' on the design shape and erected).
    Each state: the stress statistics per yarn, the wrinkled and slack area fractions, the
    normal deviation from the design (``max``, ``rms``; zero on the design shape) and the area."""
    zero = {"max": 0.0, "rms": 0.0}

    def state(erection: ErectionResult, design: bool) -> dict[str, object]:
        return {
            **erection.statistics(design=design),
            "deviation": zero if design else erection.deviation(),
            "area": erection.surface_area if design else erection.erected_area,
        }

    if optimum is None:
        return {"design_shape": state(result, True), "erected": state(result, False)}
    return {
        "vares_design_shape": state(optimum.start, True),
        "vares_erected": state(optimum.start, False),
        "optimised_design_shape": state(result, True),
        "optimised_erected": state(result, False),
    }


def erection_figures(
    result: ErectionResult, units: str, optimum: OptimisedPatterns | None = None
) -> dict[str, object]:
    """What a run's ``summary.json`` or ``structure.json`` says of its erection (the whole of
    it is in ``erect/erect.json``): whether it converged, the units and
    :func:`erection_columns`."""
    return {
        "converged": result.converged,
        "regularised": result.regularised,
        "optimised": optimum is not None,
        "units": units,
        "file": "erect/erect.json",
        "states": erection_columns(result, optimum),
    }


_TITLES = {
    "design_shape": "on the design shape",
    "erected": "after erection",
    "vares_erected": "VaReS patterns, erected",
    "optimised_design_shape": "optimised, on the design shape",
    "optimised_erected": "optimised, erected",
}


def erection_comparison(
    result: ErectionResult, units: str, optimum: OptimisedPatterns | None = None
) -> tuple[list[str], list[tuple[str, ...]]]:
    """The figures an erection is judged by, column by column: on the design shape, after
    erection (with ``optimum``: the VaReS patterns' erection, then the optimised patterns'):
    ``(column titles, rows of (label, value per column))`` for the command line and reports."""
    states = erection_columns(result, optimum)
    order = (
        ("design_shape", "erected")
        if optimum is None
        else ("optimised_design_shape", "vares_erected", "optimised_erected")
    )
    columns = [states[k] for k in order]
    rows: list[tuple[str, ...]] = []
    for yarn in ("warp", "fill"):
        stats = [c["stress"][yarn] for c in columns]
        rows += [
            (f"{yarn}: intended", *(_number(s["intended"]) for s in stats)),
            (f"{yarn}: mean", *(_number(s["mean"]) for s in stats)),
            (f"{yarn}: min … max", *(f"{_number(s['min'])} … {_number(s['max'])}" for s in stats)),
            (f"{yarn}: RMS from intended", *(_number(s["rms_deviation"], 3) for s in stats)),
        ]
    for key, label in (("wrinkled", "wrinkled area (uniaxial tension)"), ("slack", "slack area")):
        rows.append((label, *(f"{100 * c[f'{key}_area_fraction']:.1f} %" for c in columns)))
    deviations = [c["deviation"] for c in columns]  # zero on the design shape
    rows.append(
        (
            f"normal deviation, max / RMS ({units})",
            *(f"{_number(d['max'], 3)} / {_number(d['rms'], 3)}" for d in deviations),
        )
    )
    rows.append((f"area ({units}²)", *(_number(c["area"], 6) for c in columns)))
    return [_TITLES[k] for k in order], rows


def erection_files(directory: Path, report: bool = False) -> list[Path]:
    """The files an erection writes into ``directory``."""
    return [directory / n for n in ERECTION_FILES + (("report.html",) if report else ())]


def erected_pictures(result: ErectionResult, units: str) -> dict[str, tuple[str, np.ndarray, str]]:
    """The pictures an erection writes, of the erected shape: field → (file, per-cell values,
    title); a report embeds them as written."""
    per_cell = np.concatenate(
        [result.normal_deviation[c].mean(axis=1) for c in result.mesh.cells.values()]
    )
    after = result.fields
    return {
        "normal_deviation": ("deviation.png", per_cell, f"normal deviation from design ({units})"),
        "warp_stress": ("warp_stress.png", after["warp_stress"], "warp force, erected"),
        "fill_stress": ("fill_stress.png", after["fill_stress"], "fill force, erected"),
        "state": ("state.png", after["state"], "taut (0) / wrinkled (1) / slack (2), erected"),
    }


def _erect_json(result: ErectionResult, units: str, optimum) -> dict[str, object]:
    out = result.to_dict(units=units)
    if optimum is not None:
        out["optimisation"] = optimum.to_dict()
    return out


def write_erection(
    result: ErectionResult, directory: Path, units: str, optimum: OptimisedPatterns | None = None
) -> list[Path]:
    """The files of an erection (:data:`ERECTION_FILES`) in ``directory``; returns their paths.
    With ``optimum`` (the erection is that of optimised patterns), ``erect.json`` holds the
    optimisation and the starting patterns' erected figures under ``optimisation``."""
    from ..io.plot import DPI, plot_surface_fields

    files = []
    fields = dict(result.fields) | {f"design_{k}": v for k, v in result.design_fields.items()}
    points = {
        "displacement": result.displacement,
        "normal_deviation": result.normal_deviation,
        "held": result.held.astype(float),
    }
    writers = {
        "erect.json": lambda p: write_json(p, _erect_json(result, units, optimum)),
        "erected.vtu": lambda p: write_surface(
            p, result.mesh, result.erected_points, fields, points, units=units
        ),
        "erected.obj": lambda p: write_surface(p, result.mesh, result.erected_points),
    }
    for name, writer in writers.items():
        writer(directory / name)
        files.append(directory / name)
    scale = result.material.stiffness_scale * result.thickness
    drawings = erected_pictures(result, units)
    pictures = plot_surface_fields(  # on one figure
        result.erected_mesh,
        {field: values for field, (_, values, _) in drawings.items()},
        titles={field: title for field, (_, _, title) in drawings.items()},
        stress_unit="force/length",
        stress_scale=scale,
    )
    for field, fig in pictures:
        path = directory / drawings[field][0]
        with atomic_path(path) as temporary:
            fig.savefig(temporary, dpi=DPI)
        files.append(path)
    return files
