"""Fibre directions per element for a laminate's FE model: an Abaqus orientation table and a CSV.

**Abaqus** (an include file for the model's input deck): per ply one

    *DISTRIBUTION TABLE, NAME=<ply>_TABLE
    COORD3D, COORD3D
    *DISTRIBUTION, NAME=<ply>_DIST, LOCATION=ELEMENT, TABLE=<ply>_TABLE
    , ax, ay, az, bx, by, bz          (the default: the ply's warp and fill at its seed)
    <element>, ax, ay, az, bx, by, bz (one line per element of the ply)
    *ORIENTATION, NAME=<ply>_ORI, DEFINITION=COORDINATES
    <ply>_DIST
    3, 0.

where ``a`` is the draped warp (the local 1-direction) and ``b`` the draped fill (in the local 1–2
plane), unit vectors from the origin. A comment line ``** vares ply <ORIENTATION>: <name>`` before
each block names the ply. Element labels are the mould's cells in global order, from 1. Numbers are
written with 17 significant digits, so they read back exactly.

**CSV**: ``element, ply, warp_x, warp_y, warp_z, fill_x, fill_y, fill_z, shear_angle`` (degrees),
one row per element of each ply.
"""

from __future__ import annotations

import csv
import io
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .files import write_text

__all__ = [
    "PlyOrientations",
    "abaqus_name",
    "read_abaqus_orientations",
    "read_orientation_csv",
    "write_abaqus_orientations",
    "write_orientation_csv",
]

CSV_COLUMNS = (
    "element",
    "ply",
    "warp_x",
    "warp_y",
    "warp_z",
    "fill_x",
    "fill_y",
    "fill_z",
    "shear_angle",
)


@dataclass(frozen=True)
class PlyOrientations:
    """One ply's directions: ``elements`` ``(k,)`` (labels from 1), ``warp`` and ``fill``
    ``(k, 3)`` (unit vectors), ``shear_angle`` ``(k,)`` (degrees; NaN if not known), and the
    ``default_warp``, ``default_fill`` ``(3,)`` for elements not listed."""

    name: str
    elements: np.ndarray
    warp: np.ndarray
    fill: np.ndarray
    shear_angle: np.ndarray
    default_warp: np.ndarray
    default_fill: np.ndarray


def abaqus_name(name: str, taken: Sequence[str] = ()) -> str:
    """An Abaqus label for ``name`` (letters, digits and underscores, starting with a letter, at
    most 60 characters, upper case), made unique among ``taken`` (labels are case-insensitive)."""
    label = re.sub(r"[^A-Za-z0-9_]", "_", name).upper()[:60]
    if not label or not label[0].isalpha():
        label = "PLY_" + label
    unique, count = label, 1
    upper = {t.upper() for t in taken}
    while unique in upper:
        count += 1
        unique = f"{label}_{count}"
    return unique


def _numbers(values) -> str:
    return ", ".join(f"{float(v):.17g}" for v in values)


def write_abaqus_orientations(path: Path, plies: Sequence[PlyOrientations]) -> list[str]:
    """Write the orientation table of ``plies`` (module docs); the orientations' names, in the
    order of ``plies``."""
    lines = ["** Fibre orientations per element, one *ORIENTATION per ply (written by vares)"]
    names: list[str] = []
    for ply in plies:
        label = abaqus_name(ply.name, names)
        names.append(label)
        table, dist, ori = f"{label}_TABLE", f"{label}_DIST", f"{label}_ORI"
        lines += [
            f"** vares ply {ori}: {ply.name}",
            f"*DISTRIBUTION TABLE, NAME={table}",
            "COORD3D, COORD3D",
            f"*DISTRIBUTION, NAME={dist}, LOCATION=ELEMENT, TABLE={table}",
            ", " + _numbers([*ply.default_warp, *ply.default_fill]),
        ]
        for element, warp, fill in zip(ply.elements, ply.warp, ply.fill, strict=True):
            lines.append(f"{int(element)}, " + _numbers([*warp, *fill]))
        lines += [f"*ORIENTATION, NAME={ori}, DEFINITION=COORDINATES", dist, "3, 0."]
    write_text(path, "\n".join(lines) + "\n")
    return [f"{n}_ORI" for n in names]


def _keyword(line: str) -> tuple[str, dict[str, str]]:
    parts = [p.strip() for p in line[1:].split(",")]
    parameters = {}
    for part in parts[1:]:
        key, _, value = part.partition("=")
        parameters[key.strip().upper()] = value.strip()
    return parts[0].upper(), parameters


def read_abaqus_orientations(path: Path) -> dict[str, PlyOrientations]:
    """Read an orientation table written by :func:`write_abaqus_orientations` (or any input file
    of ``*DISTRIBUTION`` / ``*ORIENTATION, DEFINITION=COORDINATES`` blocks of the same form):
    ply name (from the ``** vares ply`` comment, else the orientation's name) → its directions
    (``shear_angle`` NaN: the table has none)."""
    text = Path(path).read_text(encoding="utf-8").splitlines()
    ply_names: dict[str, str] = {}
    distributions: dict[str, list[list[str]]] = {}
    orientations: dict[str, str] = {}
    current: str | None = None
    block: list[list[str]] | None = None
    pending_orientation: str | None = None
    for raw in text:
        line = raw.strip()
        if not line:
            continue
        if line.startswith("**"):
            match = re.match(r"\*\* vares ply (\S+): (.*)$", line)
            if match:
                ply_names[match.group(1).upper()] = match.group(2)
            continue
        if line.startswith("*"):
            keyword, parameters = _keyword(line)
            block, pending_orientation = None, None
            if keyword == "DISTRIBUTION":
                current = parameters["NAME"].upper()
                block = distributions.setdefault(current, [])
            elif keyword == "ORIENTATION":
                if parameters.get("DEFINITION", "COORDINATES").upper() != "COORDINATES":
                    raise ValueError(
                        f"{path}: orientation {parameters.get('NAME')} is not "
                        "DEFINITION=COORDINATES"
                    )
                pending_orientation = parameters["NAME"].upper()
            continue
        if block is not None:
            block.append([p.strip() for p in line.split(",")])
        elif pending_orientation is not None:
            orientations[pending_orientation] = line.split(",")[0].strip().upper()
            pending_orientation = None
    out: dict[str, PlyOrientations] = {}
    for ori, dist in orientations.items():
        if dist not in distributions:
            raise ValueError(f"{path}: orientation {ori} names no distribution {dist}")
        rows = distributions[dist]
        if not rows or rows[0][0] != "":
            raise ValueError(f"{path}: distribution {dist} has no default line first")
        default = np.array([float(v) for v in rows[0][1:7]])
        elements = np.array([int(r[0]) for r in rows[1:]], dtype=np.int64)
        values = np.array([[float(v) for v in r[1:7]] for r in rows[1:]]).reshape(-1, 6)
        name = ply_names.get(ori, ori)
        out[name] = PlyOrientations(
            name,
            elements,
            values[:, :3],
            values[:, 3:],
            np.full(len(elements), np.nan),
            default[:3],
            default[3:],
        )
    return out


def write_orientation_csv(path: Path, plies: Sequence[PlyOrientations]) -> None:
    """Write the directions of ``plies`` as CSV (module docs)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for ply in plies:
        for element, warp, fill, shear in zip(
            ply.elements, ply.warp, ply.fill, ply.shear_angle, strict=True
        ):
            writer.writerow(
                [int(element), ply.name, *(f"{float(v):.17g}" for v in (*warp, *fill, shear))]
            )
    write_text(path, buffer.getvalue())


def read_orientation_csv(path: Path) -> dict[str, PlyOrientations]:
    """Read a CSV written by :func:`write_orientation_csv`: ply name → its directions (the
    defaults NaN: a CSV has none)."""
    rows: dict[str, list[list[str]]] = {}
    with open(path, encoding="utf-8", newline="") as handle:
        reader = csv.reader(handle)
        header = next(reader)
        if tuple(header) != CSV_COLUMNS:
            raise ValueError(f"{path}: the columns must be {', '.join(CSV_COLUMNS)}")
        for row in reader:
            rows.setdefault(row[1], []).append(row)
    out = {}
    for name, lines in rows.items():
        values = np.array([[float(v) for v in r[2:]] for r in lines])
        out[name] = PlyOrientations(
            name,
            np.array([int(r[0]) for r in lines], dtype=np.int64),
            values[:, 0:3],
            values[:, 3:6],
            values[:, 6],
            np.full(3, np.nan),
            np.full(3, np.nan),
        )
    return out
