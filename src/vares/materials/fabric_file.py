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

Only ``E1, E2, G12, nu12, source`` and the compensation table's ``prestress``, ``warp`` and
``fill`` are read into the preset; the rest documents the fit.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from .base import MaterialError

__all__ = [
    "COMPENSATE_BY",
    "MeasuredCompensation",
    "fabric_toml",
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
