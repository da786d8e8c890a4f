"""Biaxial test records as test machines export them: CSV/TSV, one file per specimen or test.

:func:`read_biaxial` reads a file into a :class:`~vares.materials.biaxial.BiaxialRecord`
(time in s, forces per width in kN/m, strains in mm/mm). What it accepts:

- a preamble before the header (``key;value`` or ``key: value`` lines, ``#`` comments), kept as
  the record's metadata; the header is the first line naming a time, a warp force, a fill force,
  a warp strain and a fill strain column (English, German or French words: *time/Zeit/temps*,
  *warp/Kette/chaîne*, *fill/weft/Schuss/trame*, *force/load/Kraft/effort*,
  *strain/Dehnung/déformation/elongation*), and optionally a *stage/Stufe/step/étape* column;
- units in the header cell (``Kraft Kette [N/5cm]``, ``warp force (kN/m)``, ``strain / %``) or
  on a line of their own under it: forces in kN/m, N/mm, N/m, N/cm, N/5cm, N/50mm, daN/5cm,
  daN/cm, lbf/in; strains in mm/mm, m/m, -, %, ‰, mm/m, µm/m; time in s, ms, min, h;
- semicolons, tabs or commas between fields; decimal commas (with semicolons or tabs); a
  byte-order mark; UTF-8 or Windows-1252 text;
- load stages from a stage column, or (without one) found from the force signal.

A file that cannot be read raises :class:`BiaxialFileError`, one line naming the file, the line
and, where one is at fault, the column.

:func:`write_biaxial` writes a record in one of two layouts (:data:`LAYOUTS`): ``"de-lab"``
(preamble, semicolons, decimal commas, a BOM, N/5cm and %, a stage column) and ``"tsv"`` (``#``
preamble, tabs, kN/m and mm/mm, no stage column).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import NoReturn

import numpy as np

from ..materials.biaxial import BiaxialRecord, RecordError
from .files import write_text

__all__ = ["LAYOUTS", "BiaxialFileError", "read_biaxial", "write_biaxial"]


class BiaxialFileError(ValueError):
    """A biaxial test file that cannot be read (the message names file, line and column)."""


#: Factors to vares' units (kN/m, mm/mm, s), by unit as written (lower case, no spaces).
FORCE_UNITS = {
    "kn/m": 1.0,
    "n/mm": 1.0,
    "n/m": 1e-3,
    "n/cm": 0.1,
    "n/5cm": 0.02,
    "n/50mm": 0.02,
    "dan/5cm": 0.2,
    "dan/cm": 1.0,
    "lbf/in": 0.1751268,
}
STRAIN_UNITS = {
    "mm/mm": 1.0,
    "m/m": 1.0,
    "-": 1.0,
    "1": 1.0,
    "%": 0.01,
    "‰": 1e-3,
    "mm/m": 1e-3,
    "µm/m": 1e-6,
    "μm/m": 1e-6,
    "µε": 1e-6,
}
TIME_UNITS = {"s": 1.0, "sec": 1.0, "ms": 1e-3, "min": 60.0, "h": 3600.0}

_WORDS = {
    "time": ("time", "zeit", "temps", "tiempo", "tempo"),
    "stage": ("stage", "stufe", "step", "schritt", "phase", "étape", "etape", "segment"),
    "warp": ("warp", "kette", "kett", "chaîne", "chaine", "ordito", "urdimbre"),
    "fill": ("fill", "weft", "schuss", "trame", "trama"),
    "force": ("force", "load", "kraft", "last", "effort", "tension", "forza", "fuerza"),
    "strain": (
        "strain",
        "dehnung",
        "déformation",
        "deformation",
        "elongation",
        "extension",
        "allongement",
        "epsilon",
        "ε",
    ),
}
_COLUMNS = ("time", "warp force", "fill force", "warp strain", "fill strain")


def _fail(
    path: Path, line: int, message: str, column: int | None = None, name: str = ""
) -> NoReturn:
    where = f"{path}, line {line}"
    if column is not None:
        where += f", column {column}" + (f" ({name})" if name else "")
    raise BiaxialFileError(f"{where}: {message}")


def _split_unit(cell: str) -> tuple[str, str | None]:
    """``"Kraft Kette [N/5cm]"`` → ``("kraft kette", "n/5cm")``; no unit → None."""
    text = cell.strip().strip('"').strip()
    for pattern in (r"^(.*?)\[([^\]]*)\]\s*$", r"^(.*?)\(([^)]*)\)\s*$", r"^(.*?)\s/\s*(\S+)$"):
        match = re.match(pattern, text)
        if match:
            return match.group(1).strip().lower(), _unit(match.group(2))
    match = re.match(r"^(.*?)\s+in\s+(\S+)$", text, flags=re.IGNORECASE)
    if match:
        return match.group(1).strip().lower(), _unit(match.group(2))
    return text.lower(), None


def _unit(text: str) -> str:
    return text.strip().lower().replace(" ", "").replace("\u202f", "")


def _role(name: str) -> str | None:
    """The column a header name stands for (one of ``_COLUMNS`` or ``"stage"``), or None."""
    tokens = re.split(r"[\s_\-.,:/]+", name)

    def has(kind: str) -> bool:
        return any(t.startswith(w) for t in tokens for w in _WORDS[kind]) or any(
            w in name for w in _WORDS[kind] if len(w) > 4
        )

    direction = "warp" if has("warp") else "fill" if has("fill") else None
    if has("strain") and direction:
        return f"{direction} strain"
    if has("force") and direction:
        return f"{direction} force"
    if (has("time") or "t" in tokens) and not direction:
        return "time"
    if has("stage") and not direction:
        return "stage"
    return None


def _delimiter(line: str) -> str | None:
    for candidate in ("\t", ";", ","):
        if candidate in line:
            return candidate
    return None


def _read_text(path: Path) -> str:
    data = path.read_bytes()
    if b"\x00" in data[:4096] or data.startswith(b"PK\x03\x04"):  # a zip: .xlsx, .ods
        raise BiaxialFileError(
            f"{path} is a binary file (a spreadsheet or a machine's own format), not a test "
            "record: export the record as text (CSV or TSV)"
        )
    for encoding in ("utf-8-sig", "cp1252"):
        try:
            return data.decode(encoding)
        except UnicodeDecodeError:
            continue
    raise BiaxialFileError(f"{path}: neither UTF-8 nor Windows-1252 text")


def read_biaxial(path: str | Path, *, name: str | None = None) -> BiaxialRecord:
    """The record of one biaxial test file (see the module docs for what is accepted).

    ``name`` names the specimen (default: the preamble's specimen entry, else the file's stem).
    Raises :class:`BiaxialFileError` (one line: file, line, column) for a file that cannot be
    read, and :class:`FileNotFoundError` for one that does not exist.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    lines = _read_text(path).splitlines()
    metadata: dict[str, str] = {}
    header_at, roles, delimiter = None, {}, None
    best: tuple[int, int, set[str]] = (0, 0, set())  # the line naming most columns, for errors
    for number, raw in enumerate(lines, start=1):
        text = raw.strip().lstrip("\ufeff")
        if not text:
            continue
        if text.startswith("#"):
            _meta(text.lstrip("#"), metadata)
            continue
        delimiter = _delimiter(text)
        if delimiter is None:
            _meta(text, metadata)
            continue
        cells = text.split(delimiter)
        found = {i: _role(_split_unit(c)[0]) for i, c in enumerate(cells)}
        found = {i: r for i, r in found.items() if r is not None}
        if set(_COLUMNS) <= set(found.values()):
            header_at, roles, header_cells = number, found, cells
            break
        named = set(found.values()) & set(_COLUMNS)
        if len(named) > best[1]:
            best = (number, len(named), named)
        _meta(text, metadata, delimiter)
    if header_at is None and best[1] >= 2:
        lacking = [c for c in _COLUMNS if c not in best[2]]
        _fail(
            path,
            best[0],
            f"the header names no {' and no '.join(lacking)} column (it has: "
            f"{', '.join(c for c in _COLUMNS if c in best[2])})",
        )
    if header_at is None and path.suffix.lower() == ".toml":
        raise BiaxialFileError(
            f"{path} is a TOML file (a fabric or job file?), not a test record (CSV or TSV)"
        )
    if header_at is None:
        raise BiaxialFileError(
            f"{path}: no header line naming the time, warp force, fill force, warp strain and "
            f"fill strain columns (read {len(lines)} lines)"
        )
    for role in (*_COLUMNS, "stage"):
        where = [i for i, r in roles.items() if r == role]
        if len(where) > 1:
            _fail(path, header_at, f"two {role} columns ({where[0] + 1} and {where[1] + 1})")
    column = {r: i for i, r in roles.items()}
    units = {i: _split_unit(header_cells[i])[1] for i in roles}
    first_data = header_at
    if any(units[column[r]] is None for r in _COLUMNS[1:]):
        below = _next_line(lines, header_at)
        if below is not None:
            cells = lines[below - 1].strip().split(delimiter)
            if len(cells) >= len(header_cells) and all(
                _unit(cells[i]) in {*FORCE_UNITS, *STRAIN_UNITS, *TIME_UNITS, ""}
                for i in roles
                if roles[i] != "stage"
            ):
                units = {i: _unit(cells[i]) or None for i in roles}
                first_data = below
    factors = {}
    for role in _COLUMNS:
        i = column[role]
        table = TIME_UNITS if role == "time" else FORCE_UNITS if "force" in role else STRAIN_UNITS
        unit = units[i]
        if unit is None:
            if role == "time":
                factors[role] = 1.0
                continue
            _fail(path, header_at, f"names no unit (known: {', '.join(table)})", i + 1, role)
        if unit not in table:
            _fail(
                path, header_at, f"unknown unit {unit!r} (known: {', '.join(table)})", i + 1, role
            )
        factors[role] = table[unit]
    width = len(header_cells)
    rows: list[list[float]] = []
    stage_text: list[str] = []
    decimal_comma = delimiter != ","  # with semicolons or tabs a comma can only be decimal
    for number in range(first_data + 1, len(lines) + 1):
        text = lines[number - 1].strip()
        if not text or text.startswith("#"):
            continue
        cells = text.split(delimiter)
        while len(cells) > width and not cells[-1].strip():
            cells.pop()
        if len(cells) != width:
            _fail(path, number, f"{len(cells)} fields, the header (line {header_at}) has {width}")
        row = []
        for role in _COLUMNS:
            i = column[role]
            row.append(_number(cells[i], decimal_comma, path, number, i + 1, role))
        rows.append(row)
        if "stage" in column:
            stage_text.append(cells[column["stage"]].strip().strip('"'))
    if len(rows) < 3:
        raise BiaxialFileError(
            f"{path}: {len(rows)} data line(s) under the header; a record needs 3"
        )
    data = np.array(rows)
    time = data[:, 0] * factors["time"]
    back = np.flatnonzero(np.diff(time) <= 0)
    if len(back):
        line = _data_line(lines, first_data, int(back[0]) + 1)
        _fail(path, line, "time does not increase", column["time"] + 1, "time")
    force = data[:, 1:3] * np.array([factors["warp force"], factors["fill force"]])
    strain = data[:, 3:5] * np.array([factors["warp strain"], factors["fill strain"]])
    stage = _stages(stage_text) if stage_text else None
    specimen = name or metadata.get("specimen") or metadata.get("probe") or path.stem
    try:
        return BiaxialRecord(
            time, force, strain, stage, name=specimen, source=str(path), metadata=metadata
        )
    except RecordError as exc:
        raise BiaxialFileError(f"{path}: {exc}") from None


def _next_line(lines: list[str], after: int) -> int | None:
    for number in range(after + 1, len(lines) + 1):
        if lines[number - 1].strip():
            return number
    return None


def _data_line(lines: list[str], first_data: int, index: int) -> int:
    """The line number of the ``index``-th (0-based) data line."""
    count = -1
    for number in range(first_data + 1, len(lines) + 1):
        text = lines[number - 1].strip()
        if text and not text.startswith("#"):
            count += 1
            if count == index:
                return number
    return len(lines)


def _number(cell: str, decimal_comma: bool, path: Path, line: int, column: int, name: str) -> float:
    text = cell.strip().strip('"').replace("\u202f", "").replace("\xa0", "")
    if decimal_comma:
        text = text.replace(",", ".")
    try:
        value = float(text)
    except ValueError:
        _fail(path, line, f"{cell.strip()!r} is not a number", column, name)
    if not np.isfinite(value):
        _fail(path, line, f"{cell.strip()!r} is not a finite number", column, name)
    return value


def _stages(texts: list[str]) -> np.ndarray:
    codes: dict[str, int] = {}
    out = []
    for text in texts:
        try:
            out.append(int(float(text.replace(",", "."))))
            continue
        except ValueError:
            pass
        codes.setdefault(text, len(codes) + 1)
        out.append(codes[text])
    return np.array(out, dtype=int)


def _meta(text: str, metadata: dict[str, str], delimiter: str | None = None) -> None:
    if delimiter is not None:
        key, _, value = text.partition(delimiter)
    else:
        key, _, value = text.partition(":")
    key, value = key.strip().strip('"').lower(), value.strip().strip(delimiter or "").strip()
    if key and value:
        metadata[key] = value.strip('"')


#: The layouts :func:`write_biaxial` writes.
LAYOUTS = ("de-lab", "tsv")

_DE_HEADER = (
    "Zeit [s]",
    "Stufe",
    "Kraft Kette [N/5cm]",
    "Kraft Schuss [N/5cm]",
    "Dehnung Kette [%]",
    "Dehnung Schuss [%]",
)
_TSV_HEADER = (
    "time (s)",
    "warp force (kN/m)",
    "fill force (kN/m)",
    "warp strain (mm/mm)",
    "fill strain (mm/mm)",
)


def write_biaxial(
    record: BiaxialRecord,
    path: str | Path,
    layout: str = "tsv",
    preamble: dict[str, str] | None = None,
) -> Path:
    """Write ``record`` in ``layout`` (:data:`LAYOUTS`) to ``path`` (atomically).

    ``"de-lab"``: a German lab's export (BOM, ``Probe;…`` preamble, semicolons, decimal commas,
    forces in N/5cm, strains in %, a stage column). ``"tsv"``: ``#`` preamble, tabs, kN/m and
    mm/mm, no stage column (stages are found from the force signal).
    """
    if layout not in LAYOUTS:
        raise ValueError(f"unknown layout {layout!r}; choose from {', '.join(LAYOUTS)}")
    path = Path(path)
    info = {"specimen": record.name, **(preamble or {})}
    if layout == "de-lab":
        labels = {"specimen": "Probe"}
        lines = [f"{labels.get(k, k)};{v}" for k, v in info.items()]
        lines.append("")
        lines.append(";".join(_DE_HEADER))
        stage = record.stage if record.stage is not None else np.ones(record.samples, int)
        for i in range(record.samples):
            fields = (
                f"{record.time[i]:.1f}",
                str(int(stage[i])),
                f"{record.force[i, 0] / 0.02:.2f}",
                f"{record.force[i, 1] / 0.02:.2f}",
                f"{100 * record.strain[i, 0]:.4f}",
                f"{100 * record.strain[i, 1]:.4f}",
            )
            lines.append(";".join(f.replace(".", ",") for f in fields))
        text = "\ufeff" + "\r\n".join(lines) + "\r\n"
    else:
        lines = [f"# {k}: {v}" for k, v in info.items()]
        lines.append("\t".join(_TSV_HEADER))
        for i in range(record.samples):
            lines.append(
                f"{record.time[i]:.1f}\t{record.force[i, 0]:.4f}\t{record.force[i, 1]:.4f}\t"
                f"{record.strain[i, 0]:.7f}\t{record.strain[i, 1]:.7f}"
            )
        text = "\n".join(lines) + "\n"
    write_text(path, text)
    return path
