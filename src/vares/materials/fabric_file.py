"""Fabric files: a fabric's constants and compensation values from biaxial tests, as TOML.

A fabric file is a preset file (:mod:`vares.materials.presets`) whose entry also says how its
numbers were found. ``vares fabric fit`` writes one; it is usable wherever a preset is
(``--fabric pes-batch-42.toml``, ``fabric = "pes-batch-42.toml"`` in a job's ``[material]``,
``vares.materials.fabric("pes-batch-42.toml")``)::

    [pes-batch-42]
    description = "…"
    E1 = 612.4            # warp E·t, kN/m: mean over the specimens
    E2 = 471.0            # fill E·t, kN/m
    G12 = 32.0            # not measured by biaxial tests: from the preset or value named below
    nu12 = 0.352          # ν_wf
    source = "…"          # the files, the evaluation, the program
    compensate_by = "measured"      # or "law"

    [pes-batch-42.scatter]          # sample standard deviation over the specimens
    E1 = 8.1
    …
    [pes-batch-42.compensation]     # EN 17117-2: strains at the prestress (mm/mm)
    prestress = [2.0, 1.5]
    warp = 0.0081
    fill = 0.0066
    warp_std = 0.0003
    fill_std = 0.0002
    …
    [pes-batch-42.fit]              # how the constants were fitted, residuals
    …
    [[pes-batch-42.specimens]]      # one table per specimen
    …

Only ``E1, E2, G12, nu12, source``, the compensation table's ``prestress``, ``warp`` and
``fill`` (and their scatter) and the scatter table's ``E1, E2, nu12`` and ``specimens``
(:func:`read_scatter`: for the band of the constants, :mod:`vares.app.fabric_band`) are read
into the preset; the rest documents the fit.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .base import MaterialError

if TYPE_CHECKING:
    from .fitting import FabricFit

__all__ = [
    "COMPENSATE_BY",
    "ConstantScatter",
    "MeasuredCompensation",
    "fabric_toml",
    "fit_toml",
    "read_scatter",
    "read_test_tables",
    "toml_string",
]

#: How a pattern is compensated with a tested fabric.
COMPENSATE_BY = ("measured", "law")

#: The keys and tables a tested fabric's entry may hold beyond a preset's.
EXTRA_KEYS = {"compensate_by", "scatter", "compensation", "fit", "specimens"}


@dataclass(frozen=True)
class MeasuredCompensation:
    """Measured compensation values: warp and fill strains (mm/mm) at the ``prestress``
    (warp, fill; kN/m), their scatter over the specimens (0 if not given) and the number of
    specimens (None if not given)."""

    prestress: tuple[float, float]
    warp: float
    fill: float
    warp_std: float = 0.0
    fill_std: float = 0.0
    specimens: int | None = None


@dataclass(frozen=True)
class ConstantScatter:
    """The sample standard deviations of a fabric's fitted constants over its specimens:
    ``E1``, ``E2`` (kN/m) and ``nu12``, and the number of specimens (None if not given)."""

    E1: float
    E2: float
    nu12: float
    specimens: int | None = None


def read_scatter(entry: Mapping[str, Any], where: str) -> ConstantScatter | None:
    """The ``scatter`` table of a preset file's entry (``where``: ``"FILE: [name]"`` for
    messages), None when it has none; raises :class:`MaterialError` for values that are not
    non-negative numbers."""
    table = entry.get("scatter")
    if table is None:
        return None
    where = f"{where[:-1]}.scatter]"
    if not isinstance(table, dict):
        raise MaterialError(f"{where} must be a table")
    try:
        values = [float(table.get(k, 0.0)) for k in ("E1", "E2", "nu12")]
    except (TypeError, ValueError):
        raise MaterialError(f"{where}: E1, E2 and nu12 must be numbers") from None
    if not all(math.isfinite(v) and v >= 0 for v in values):
        raise MaterialError(f"{where}: E1, E2 and nu12 must be numbers ≥ 0")
    specimens = table.get("specimens")
    if specimens is not None and (
        isinstance(specimens, bool) or not isinstance(specimens, int) or specimens < 1
    ):
        raise MaterialError(f"{where}: specimens must be a positive integer")
    return ConstantScatter(values[0], values[1], values[2], specimens)


def read_test_tables(
    entry: Mapping[str, Any], where: str
) -> tuple[MeasuredCompensation | None, str | None]:
    """The measured compensation and the ``compensate_by`` choice of a preset file's entry
    (``where``: ``"FILE: [name]"`` for messages); raises :class:`MaterialError`."""
    choice = entry.get("compensate_by")
    if choice is not None and choice not in COMPENSATE_BY:
        raise MaterialError(f"{where}: compensate_by must be one of {', '.join(COMPENSATE_BY)}")
    table = entry.get("compensation")
    for key in ("scatter", "fit"):
        if key in entry and not isinstance(entry[key], dict):
            raise MaterialError(f"{where}: {key} must be a table")
    if table is None:
        if choice == "measured":
            raise MaterialError(f"{where}: compensate_by = 'measured' needs a compensation table")
        return None, choice
    if not isinstance(table, dict):
        raise MaterialError(f"{where}: compensation must be a table")
    missing = [k for k in ("prestress", "warp", "fill") if k not in table]
    if missing:
        raise MaterialError(f"{where}.compensation lacks {', '.join(missing)}")
    prestress = table["prestress"]
    try:
        pair = tuple(float(p) for p in prestress)
        values = [float(table[k]) for k in ("warp", "fill")]
        scatter = [float(table.get(k, 0.0)) for k in ("warp_std", "fill_std")]
    except (TypeError, ValueError):
        raise MaterialError(
            f"{where}.compensation: prestress must be two numbers and warp, fill numbers"
        ) from None
    if len(pair) != 2 or not all(p > 0 and math.isfinite(p) for p in pair):
        raise MaterialError(f"{where}.compensation: prestress must be two positive numbers")
    if not all(math.isfinite(v) for v in values + scatter):
        raise MaterialError(f"{where}.compensation: values must be finite")
    if any(v < 0 for v in scatter):
        raise MaterialError(f"{where}.compensation: warp_std and fill_std must not be negative")
    specimens = table.get("specimens")
    if specimens is not None and (
        isinstance(specimens, bool) or not isinstance(specimens, int) or specimens < 1
    ):
        raise MaterialError(f"{where}.compensation: specimens must be a positive integer")
    compensation = MeasuredCompensation(
        (pair[0], pair[1]), values[0], values[1], scatter[0], scatter[1], specimens
    )
    return compensation, choice


#: The escapes of a TOML basic string; other control characters are written as ``\uXXXX``.
_TOML_ESCAPES = {
    "\\": "\\\\",
    '"': '\\"',
    "\b": "\\b",
    "\t": "\\t",
    "\n": "\\n",
    "\f": "\\f",
    "\r": "\\r",
}


def toml_string(text: str) -> str:
    """``text`` as a TOML basic string: quoted, with every character TOML does not admit there
    (quote, backslash, control characters) escaped, so any name or path reads back as it was.
    Raises :class:`ValueError` for text that is not valid Unicode (a lone surrogate)."""
    out = []
    for character in text:
        code = ord(character)
        if character in _TOML_ESCAPES:
            out.append(_TOML_ESCAPES[character])
        elif code < 0x20 or code == 0x7F:
            out.append(f"\\u{code:04X}")
        elif 0xD800 <= code <= 0xDFFF:
            raise ValueError(f"cannot write {text!r} to TOML: it is not valid Unicode")
        else:
            out.append(character)
    return '"' + "".join(out) + '"'


def _value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        value = float(value)
        if not math.isfinite(value):
            return '"nan"'
        return repr(value)
    if isinstance(value, str):
        return toml_string(value)
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    raise TypeError(f"cannot write {type(value).__name__} to TOML")


def fabric_toml(
    name: str,
    head: Mapping[str, Any],
    tables: Mapping[str, Mapping[str, Any]],
    specimens: list[Mapping[str, Any]],
    comment: str = "",
) -> str:
    """TOML text of one fabric entry: ``head`` keys under ``[name]``, each of ``tables`` as
    ``[name.table]`` and ``specimens`` as ``[[name.specimens]]``; ``comment`` lines first."""
    if not name or any(c in name for c in ' ."[]#='):
        raise MaterialError(f"a fabric name needs letters, digits, - or _; got {name!r}")
    lines = [f"# {line}" if line else "#" for line in comment.splitlines()]
    lines += ["", f"[{name}]"]
    lines += [f"{k} = {_value(v)}" for k, v in head.items()]
    for table, values in tables.items():
        lines += ["", f"[{name}.{table}]"]
        lines += [f"{k} = {_value(v)}" for k, v in values.items()]
    for specimen in specimens:
        lines += ["", f"[[{name}.specimens]]"]
        lines += [f"{k} = {_value(v)}" for k, v in specimen.items()]
    return "\n".join(lines) + "\n"


def fit_toml(
    fitted: FabricFit, compensate_by: str | None = None, description: str | None = None
) -> str:
    """The fabric file of a fit (:class:`~vares.materials.fitting.FabricFit`): the mean
    constants, their scatter, the compensation values, how they were fitted and every specimen.

    ``compensate_by``: the pattern's default compensation (``"measured"`` when there are
    compensation values, else ``"law"``); ``description`` defaults to one naming the
    specimens and the evaluation."""
    from .._version import __version__

    choice = compensate_by or ("measured" if fitted.compensation is not None else "law")
    if choice == "measured" and fitted.compensation is None:
        raise MaterialError("no compensation records: a pattern can only use the law")
    mean, std = fitted.constants.mean, fitted.constants.std
    n = fitted.constants.specimens
    fit0 = fitted.fits[0]
    cycle = "last cycle" if fit0.cycle == -1 else f"cycle {fit0.cycle}"
    ratios = [r.label for r in fit0.residuals]
    text = description or (
        f"biaxial fit of {n} specimen(s), load ratios {' '.join(ratios)} ({cycle} of each)"
    )
    sources = sorted({r.source for r in (*fitted.fits, *fitted.compensations) if r.source})
    source = (
        f"vares {__version__} fabric fit of {', '.join(sources) or 'records'} "
        f"(MSAJ/M-02 least squares of the strain residual, "
        f"{'with' if fit0.reciprocal else 'without'} reciprocity"
        + (", EN 17117-2 compensation values" if fitted.compensation else "")
        + f"); G12 {fitted.G12:g} kN/m {fitted.G12_source} (not measured by biaxial tests)"
    )
    head = {
        "description": text,
        "E1": mean["E_w"],
        "E2": mean["E_f"],
        "G12": fitted.G12,
        "nu12": mean["nu_wf"],
        "source": source,
        "compensate_by": choice,
    }
    tables: dict[str, dict[str, object]] = {
        "scatter": {
            "specimens": n,
            "E1": std["E_w"],
            "E2": std["E_f"],
            "nu12": std["nu_wf"],
            "nu21": std["nu_fw"],
        }
    }
    if fitted.compensation is not None and fitted.prestress is not None:
        c = fitted.compensation
        law = fitted.law_compensation() or (math.nan, math.nan)
        tables["compensation"] = {
            "prestress": list(fitted.prestress),
            "warp": c.mean["warp"],
            "fill": c.mean["fill"],
            "warp_std": c.std["warp"],
            "fill_std": c.std["fill"],
            "specimens": c.specimens,
            "law_warp": law[0],
            "law_fill": law[1],
            "note": "strains (mm/mm) at the prestress after the cycles and holds, from the "
            "extensometers' zero; erected length = pattern length × (1 + strain)",
        }
    tables["fit"] = {
        "method": "MSAJ/M-02: least squares of the strain residual over the loading "
        "branches of all load ratios, one strain offset per ratio",
        "cycle": fit0.cycle,
        "reciprocal": fit0.reciprocal,
        "ratios": ratios,
        "nu21": mean["nu_fw"],
        "rms_residual": float(np.mean([f.rms for f in fitted.fits])),
        "nonlinear_rms_residual": float(
            np.mean([f.nonlinear.get("rms", math.nan) for f in fitted.fits])
        ),
        "linear_is_poor": any(f.linear_is_poor for f in fitted.fits),
        "G12_source": fitted.G12_source,
    }
    specimens: list[dict[str, object]] = []
    for f in fitted.fits:
        row: dict[str, object] = {
            "name": f.name,
            "file": f.source,
            "E1": f.E_w,
            "E2": f.E_f,
            "nu12": f.nu_wf,
            "nu21": f.nu_fw,
            "E1_error": f.standard_errors["E_w"],
            "E2_error": f.standard_errors["E_f"],
            "nu12_error": f.standard_errors["nu_wf"],
            "nu21_error": f.standard_errors["nu_fw"],
            "rms_residual": f.rms,
            "ratios": [r.label for r in f.residuals],
            "rms_warp": [r.rms_warp for r in f.residuals],
            "rms_fill": [r.rms_fill for r in f.residuals],
        }
        if f.nonlinear:
            row |= {
                "nonlinear_E1": f.nonlinear["E_w"],
                "nonlinear_E2": f.nonlinear["E_f"],
                "nonlinear_nu12": f.nonlinear["nu_wf"],
                "k_w": f.nonlinear["k_w"],
                "k_f": f.nonlinear["k_f"],
                "nonlinear_rms_residual": f.nonlinear["rms"],
            }
        specimens.append(row)
    for c in fitted.compensations:
        specimens.append(
            {
                "name": c.name,
                "file": c.source,
                "compensation_warp": c.warp,
                "compensation_fill": c.fill,
                "read_at": c.time,
            }
        )
    comment = (
        f"Fabric {fitted.name}: written by vares {__version__} (vares fabric fit).\n"
        "E1, E2 (E·t, kN/m) and nu12 are the means over the specimens; [scatter] their sample\n"
        "standard deviations. G12 is not measured by biaxial tests (see source)."
    )
    return fabric_toml(fitted.name, head, tables, specimens, comment)
