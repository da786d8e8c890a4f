"""The length units of VTU files, and the string field data VTK writes into them.

vares states a VTU file's length units as a number every reader takes: a ``Float64`` array
``metres_per_unit`` in the grid's ``FieldData`` (0.001 for millimetres; ParaView lists it with
the data arrays, meshio reads it as field data). VTK's own string arrays (``vtkStringArray``,
e.g. a field ``units`` = "mm") are honoured too: meshio refuses a whole file that holds one, so
they are taken out before meshio reads it.
"""

from __future__ import annotations

import base64
import struct
import xml.etree.ElementTree as ET
from pathlib import Path

__all__ = [
    "FACTOR_FIELD",
    "UNIT_FIELDS",
    "declare_units",
    "declared_units",
    "split_string_fields",
]

#: The numeric field that states a file's length units.
FACTOR_FIELD = "metres_per_unit"
#: Names of a string field that gives the length units (compared in lower case).
UNIT_FIELDS = ("units", "unit", "length_units", "length_unit", "lengthunits", "lengthunit")

_OPEN, _CLOSE = b"<FieldData", b"</FieldData>"


def split_string_fields(data: bytes) -> tuple[bytes, dict[str, str | None]]:
    """The file's bytes without the string arrays of its field data, and those arrays' values
    by name (``None`` where the value is stored in a way not read here: appended or
    compressed). A file without string fields comes back unchanged."""
    appended = data.find(b"<AppendedData")
    head = data if appended < 0 else data[:appended]
    start = head.find(_OPEN)
    end = head.find(_CLOSE, start)
    if start < 0 or end < 0:
        return data, {}
    end += len(_CLOSE)
    try:
        element = ET.fromstring(data[start:end])
    except ET.ParseError:
        return data, {}
    header = _header_size(data[:start])
    compressed = b"compressor=" in data[:start]
    strings: dict[str, str | None] = {}
    for array in list(element):
        if array.get("type") == "String":
            strings[array.get("Name", "")] = _value(array, header, compressed)
            element.remove(array)
    if not strings:
        return data, {}
    rest = ET.tostring(element) if len(element) else b""
    return data[:start] + rest + data[end:], strings


def declared_units(strings: dict[str, str | None]) -> str | None:
    """The length units named by a string field of :data:`UNIT_FIELDS`, if any."""
    for name, value in strings.items():
        if name.lower() in UNIT_FIELDS and value:
            return value.strip()
    return None


def declare_units(path: Path, metres_per_unit: float) -> None:
    """Add the field ``metres_per_unit`` to the grid of a VTU file that meshio wrote (its
    writer leaves field data out)."""
    data = Path(path).read_bytes()
    grid = data.find(b"<UnstructuredGrid>")
    if grid < 0:
        raise ValueError(f"{path} has no unstructured grid")
    field = (
        f'\n<FieldData>\n<DataArray type="Float64" Name="{FACTOR_FIELD}" NumberOfTuples="1" '
        f'format="ascii">\n{metres_per_unit!r}\n</DataArray>\n</FieldData>'
    ).encode("ascii")
    at = grid + len(b"<UnstructuredGrid>")
    Path(path).write_bytes(data[:at] + field + data[at:])


def _header_size(head: bytes) -> int:
    """Bytes of the length header before binary data: 8 for ``header_type="UInt64"``."""
    return 8 if b'header_type="UInt64"' in head else 4


def _value(array: ET.Element, header: int, compressed: bool) -> str | None:
    text = (array.text or "").strip()
    form = array.get("format", "ascii")
    if form == "ascii":
        try:
            raw = bytes(int(token) for token in text.split())
        except ValueError:
            return None
    elif form == "binary" and text and not compressed:
        try:
            decoded = base64.b64decode(text)
        except ValueError:
            return None
        size = struct.unpack("<Q" if header == 8 else "<I", decoded[:header])[0]
        raw = decoded[header : header + size]
    else:  # appended data or a compressed block: not needed for a name
        return None
    return raw.split(b"\0")[0].decode("utf-8", errors="replace") or None
