"""Readers for the polygon formats that meshio reads too narrowly or not at all: Wavefront OBJ
(faces with texture and normal indices ``f 1/1/1 …``, negative indices, polygons), OFF (quads
and polygons, ``COFF``/``NOFF`` variants, per-face colours ignored), DXF (3D faces, polyface
and polygon meshes, MESH entities of the model space, with the drawing's units) and Kratos
Multiphysics' MDPA (the surface elements of a membrane or shell model: meshio takes Kratos'
own element names, ``MembraneElement3D3N``, for 3-node lines, and reads the conditions that
repeat the elements as cells too).

Each returns a :class:`PolygonSoup`: points, triangle and quad blocks and the longer polygons,
in the order the faces appear in the file block by block (triangles, quads, polygons).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..geometry.mesh import MeshError
from .dxf import INSUNITS

__all__ = [
    "DXF_UNITS",
    "PolygonSoup",
    "check_stl",
    "read_dxf",
    "read_mdpa",
    "read_obj",
    "read_off",
]


@dataclass
class PolygonSoup:
    """Points ``(n, 3)``, faces by size, and for each face in the block-by-block numbering
    (triangles, quads, polygons) the number of the file's face it is (``order``, to carry a
    per-face value of the file along)."""

    points: np.ndarray
    cells: dict[str, np.ndarray] = field(default_factory=dict)
    polygons: list[np.ndarray] = field(default_factory=list)
    order: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))


def _soup(points: list[list[float]], faces: list[list[int]], path: Path) -> PolygonSoup:
    if not points:
        raise MeshError(f"{path} contains no vertices")
    coordinates = np.array(points, dtype=float)
    n = len(coordinates)
    triangles, quads, polygons = [], [], []
    numbers: tuple[list[int], list[int], list[int]] = ([], [], [])
    for number, face in enumerate(faces, start=1):
        if len(face) < 3:
            continue  # a point or a line, not a surface cell
        bad = [i for i in face if not -n <= i < n]
        if bad:
            raise MeshError(
                f"{path}: face {number} refers to vertex {bad[0] + 1 if bad[0] >= 0 else bad[0]} "
                f"but the file has {n} vertices"
            )
        face = [i % n for i in face]
        kind = min(len(face), 5) - 3  # triangles, quads, polygons
        (triangles, quads, polygons)[kind].append(face)
        numbers[kind].append(number - 1)
    if not (triangles or quads or polygons):
        raise MeshError(f"{path} contains no triangle or quad cells")
    cells = {}
    if triangles:
        cells["triangle"] = np.array(triangles, dtype=np.int64)
    if quads:
        cells["quad"] = np.array(quads, dtype=np.int64)
    order = np.array([*numbers[0], *numbers[1], *numbers[2]], dtype=np.int64)
    return PolygonSoup(coordinates, cells, [np.array(p, dtype=np.int64) for p in polygons], order)


def _numbers(tokens: list[str], path: Path, line: int, kind=float) -> list:
    try:
        return [kind(t) for t in tokens]
    except ValueError:
        raise MeshError(f"{path}, line {line}: cannot read {' '.join(tokens)!r}") from None


def read_obj(path: Path) -> PolygonSoup:
    """Vertices (``v x y z [w]``) and faces (``f a b c …`` with ``a``, ``a/t``, ``a//n`` or
    ``a/t/n``; 1-based, negative = relative to the end) of a Wavefront OBJ file."""
    text = _text(path)
    fast = _plain_obj(text)
    if fast is not None:
        return fast
    points: list[list[float]] = []
    faces: list[list[int]] = []
    lines = text.splitlines()
    last = max((n for n, line in enumerate(lines, start=1) if line.strip()), default=0)
    for number, line in enumerate(lines, start=1):
        tokens = line.split()
        if not tokens:
            continue
        if tokens[0] == "v":
            values = _numbers(tokens[1:4], path, number)
            if len(values) != 3:
                raise MeshError(f"{path}, line {number}: a vertex needs x, y and z")
            points.append(values)
        elif tokens[0] == "f":
            if len(tokens) < 4:
                if number == last:
                    raise MeshError(
                        f"{path} ends in an incomplete face at line {number} "
                        f"({line.strip()!r}): the file was cut short"
                    )
                raise MeshError(
                    f"{path}, line {number}: a face needs three vertices or more; "
                    f"got {line.strip()!r}"
                )
            indices = _numbers([t.split("/")[0] for t in tokens[1:]], path, number, int)
            if 0 in indices:
                raise MeshError(
                    f"{path}, line {number}: vertex index 0 in {line.strip()!r}: OBJ counts "
                    "vertices from 1 (or back from -1)"
                )
            behind = [i for i in indices if i < -len(points)]
            if behind:
                raise MeshError(
                    f"{path}, line {number}: vertex index {behind[0]} counts back past the "
                    f"first vertex ({len(points)} read so far)"
                )
            # 1-based; negative counts back from the vertices read so far
            faces.append([i - 1 if i > 0 else len(points) + i for i in indices])
    return _soup(points, faces, path)


#: Vertex or face lines the fast reader does not take: a keyword followed by a tab, or alone.
_UNUSUAL_OBJ_LINE = re.compile(r"^[vf](\t|[ \t]*\r?$)", re.MULTILINE)


def _plain_obj(text: str) -> PolygonSoup | None:
    """The common case read at numpy speed: ``v x y z`` lines and triangle or quad faces of
    positive plain indices only; ``None`` for anything else (read line by line instead)."""
    if _UNUSUAL_OBJ_LINE.search(text):
        return None
    lines = text.split("\n")
    vertices = [line[2:] for line in lines if line.startswith("v ")]
    faces = [line[2:] for line in lines if line.startswith("f ")]
    if not vertices or not faces or "/" in "".join(faces[:1]) or "-" in "".join(faces[:100]):
        return None
    try:
        points = np.array(" ".join(vertices).split(), dtype=float)
        indices = np.array(" ".join(faces).split(), dtype=np.int64)
    except ValueError:
        return None
    sizes = {len(face.split()) for face in faces}
    if points.size != 3 * len(vertices) or len(sizes) != 1:
        return None
    nen = sizes.pop()
    if nen not in (3, 4) or indices.min() < 1 or indices.max() > len(vertices):
        return None
    cells = {"triangle" if nen == 3 else "quad": indices.reshape(-1, nen) - 1}
    return PolygonSoup(points.reshape(-1, 3), cells)


def read_off(path: Path) -> PolygonSoup:
    """An OFF file: header (``OFF``, ``COFF``, ``NOFF`` …), counts, vertices, faces
    ``k i1 … ik [colour]``."""
    lines = [
        (number, line.split("#")[0].split())
        for number, line in enumerate(_text(path).splitlines(), start=1)
    ]
    lines = [(number, tokens) for number, tokens in lines if tokens]
    if not lines or not lines[0][1][0].endswith("OFF"):
        raise MeshError(f"{path} is not an OFF file (no OFF header)")
    header = lines[0][1][1:] or lines[1][1]
    body = lines[1:] if lines[0][1][1:] else lines[2:]
    counts = _numbers(header[:2], path, lines[0][0], int)
    if len(counts) != 2:
        raise MeshError(f"{path}: the OFF header needs the vertex and face counts")
    n_points, n_faces = counts
    if len(body) < n_points + n_faces:
        raise MeshError(
            f"{path} is truncated: it announces {n_points} vertices and {n_faces} faces but "
            f"holds {len(body)} lines of them"
        )
    points = [_numbers(tokens[:3], path, number) for number, tokens in body[:n_points]]
    faces = []
    for number, tokens in body[n_points : n_points + n_faces]:
        size = _numbers(tokens[:1], path, number, int)[0]
        faces.append(_numbers(tokens[1 : 1 + size], path, number, int))
    return _soup(points, faces, path)


#: Kratos element names (their part before the dimension, ``…3D4N``) of 4-node surface
#: elements; any other 4-node element is a solid's (a tetrahedron).
_MDPA_SURFACES = ("membrane", "shell", "surface", "quadrilateral")


def read_mdpa(path: Path) -> PolygonSoup:
    """A Kratos MDPA file: its nodes (``Begin Nodes``: ``id x y z``, any ids) and the cells of
    its ``Begin Elements NAME`` blocks (``id property n1 … nk``): 3 nodes a triangle, 4 a quad
    when NAME is a membrane's, shell's or surface's. Conditions, sub-model parts and data blocks
    are skipped; a line element block (2 nodes, or NAME with "Line") is left out; a block of
    solid elements is refused."""
    node_ids: list[int] = []
    points: list[list[float]] = []
    faces: list[list[int]] = []  # node ids, renumbered below
    blocks: list[str] = []  # the open blocks, outermost first (sub-model parts nest)
    name = ""
    for number, line in enumerate(_text(path).splitlines(), start=1):
        tokens = line.split("//")[0].split()
        if not tokens:
            continue
        if tokens[0] == "Begin":
            blocks.append(tokens[1] if len(tokens) > 1 else "")
            name = tokens[2] if len(tokens) > 2 else ""
            continue
        if tokens[0] == "End":
            if blocks:
                blocks.pop()
            continue
        block = blocks[0] if len(blocks) == 1 else None  # the model part's own blocks only
        if block == "Nodes":
            values = _numbers(tokens[:4], path, number)
            if len(values) != 4:
                raise MeshError(f"{path}, line {number}: a node needs an id and x y z")
            node_ids.append(int(values[0]))
            points.append(values[1:])
        elif block == "Elements":
            ids = _numbers(tokens, path, number, int)[2:]
            surface = any(k in name.lower() for k in _MDPA_SURFACES)
            if len(ids) > 4 or (len(ids) == 4 and not surface):
                kind = "a quadratic element" if surface else "a solid element"
                raise MeshError(
                    f"{path}, line {number}: {name} is {kind} ({len(ids)} nodes); vares reads "
                    "the 3- and 4-node surface elements of a membrane or shell model"
                )
            if len(ids) >= 3 and "line" not in name.lower():
                faces.append(ids)
    if not faces:
        raise MeshError(f"{path} holds no membrane or shell elements (Begin Elements …3D3N)")
    index = {node: k for k, node in enumerate(node_ids)}
    if len(index) < len(node_ids):
        raise MeshError(f"{path}: node ids repeat")
    missing = sorted({i for face in faces for i in face if i not in index})
    if missing:
        raise MeshError(f"{path}: elements refer to node {missing[0]}, which the file lacks")
    return _soup(points, [[index[i] for i in face] for face in faces], path)


#: A line of an ASCII STL file that does not begin with one of its keywords.
_NOT_STL_LINE = re.compile(
    rb"^[ \t]*(?!(?:solid|facet|outer|vertex|endloop|endfacet|endsolid)\b)\S[^\r\n]*",
    re.MULTILINE | re.IGNORECASE,
)


def check_stl(path: Path) -> None:
    """Refuse a file named ``.stl`` that is no STL (meshio reads any text as ASCII STL, taking
    the last three numbers of every line, so an OBJ renamed ``.stl`` became scattered
    triangles): a binary STL is ``84 + 50·n`` bytes for the ``n`` triangles its header
    announces; an ASCII STL begins with ``solid`` and has only its keywords' lines (``facet``,
    ``outer loop``, ``vertex``, ``endloop``, ``endfacet``, ``endsolid``)."""
    size = Path(path).stat().st_size
    with open(path, "rb") as file:
        header = file.read(84)
    announced = int.from_bytes(header[80:84], "little") if size >= 84 else None
    if announced is not None and size == 84 + 50 * announced:
        return  # binary
    data = Path(path).read_bytes()
    if b"\x00" in data[:4096]:  # binary, whether or not its header begins with "solid"
        if announced is None:
            raise MeshError(
                f"{path} is not an STL file: it is binary and {size} bytes long, less than the "
                "84 bytes of a binary STL's header"
            )
        raise MeshError(
            f"{path} is not an STL file: a binary STL of the {announced} triangles its header "
            f"announces has 84 + 50·{announced} = {84 + 50 * announced} bytes, this file has "
            f"{size} (cut short, or another format)"
        )
    if data.removeprefix(b"\xef\xbb\xbf").lstrip()[:5].lower() != b"solid":
        lines = data.decode("utf-8", errors="replace").splitlines()
        vertices = sum(1 for line in lines if line.startswith("v "))
        faces = sum(1 for line in lines if line.startswith("f "))
        if vertices and faces:
            raise MeshError(
                f"{path} is not an STL file: it is an OBJ file ({vertices} 'v' and {faces} "
                "'f' lines); name it .obj"
            )
        raise MeshError(
            f"{path} is not an STL file: an ASCII STL begins with 'solid', a binary one is "
            "84 + 50·n bytes for its n triangles"
        )
    stray = _NOT_STL_LINE.search(data, data.find(b"\n") + 1 or size)  # after "solid name"
    if stray is not None:
        number = data.count(b"\n", 0, stray.start()) + 1
        line = stray.group().decode("utf-8", errors="replace").strip()
        raise MeshError(
            f"{path}, line {number}: {line[:60]!r} is no line of an ASCII STL file (solid, "
            "facet, outer loop, vertex, endloop, endfacet, endsolid)"
        )
    if not re.search(rb"^[ \t]*vertex\b", data, re.MULTILINE | re.IGNORECASE):
        raise MeshError(f"{path} is an ASCII STL file without facets (no 'vertex' lines)")


def _text(path: Path) -> str:
    data = Path(path).read_bytes()
    if b"\x00" in data[:4096]:
        raise MeshError(f"cannot read {path}: it is a binary file, not text")
    return data.decode("utf-8", errors="replace")


#: DXF drawing units (``$INSUNITS``) and vares' names for them; 0 is "unitless".
DXF_UNITS = {code: name for name, code in INSUNITS.items()}


def read_dxf(path: Path) -> tuple[PolygonSoup, str | None, np.ndarray, list[str]]:
    """The faces of a DXF drawing's model space — ``3DFACE`` entities (a triangle when the last
    two corners coincide), polyface and polygon meshes (``POLYLINE``) and ``MESH`` entities —
    as one soup (coincident corners are welded by the repair), the units the drawing declares
    (``None`` when unitless), the layer of every face (an index into the layer names; faces in
    the soup's order: triangles, quads, polygons) and the layer names. Faces inside blocks are
    not read: explode the block references first."""
    import ezdxf
    from ezdxf.render import MeshBuilder

    try:
        doc = ezdxf.readfile(path)
    except (OSError, ezdxf.DXFError) as exc:  # ezdxf's own errors, and unreadable bytes
        raise MeshError(f"cannot read {path}: {exc}") from None
    points: list = []
    faces: list[list[int]] = []
    layer_of_face: list[int] = []
    layers: dict[str, int] = {}

    def add(vertices, face_lists, layer: str) -> None:
        start = len(points)
        points.extend((v.x, v.y, v.z) for v in vertices)
        face_lists = [[start + i for i in face] for face in face_lists]
        faces.extend(face_lists)
        layer_of_face.extend([layers.setdefault(layer, len(layers))] * len(face_lists))

    for entity in doc.modelspace():
        kind = entity.dxftype()
        if kind == "3DFACE":
            corners = list(entity.wcs_vertices())
            if len(corners) == 4 and corners[3].isclose(corners[2]):
                corners = corners[:3]
            add(corners, [range(len(corners))], entity.dxf.layer)
        elif kind == "POLYLINE" and (entity.is_poly_face_mesh or entity.is_polygon_mesh):
            mesh = MeshBuilder.from_polyface(entity)
            add(mesh.vertices, mesh.faces, entity.dxf.layer)
        elif kind == "MESH":
            mesh = MeshBuilder.from_mesh(entity)
            add(mesh.vertices, mesh.faces, entity.dxf.layer)
    if not faces:
        raise MeshError(
            f"{path} holds no 3D faces, polyface or polygon meshes, or MESH entities in its "
            "model space: export the surface as a mesh (explode blocks that hold it)"
        )
    code = int(doc.header.get("$INSUNITS", 0))
    if code and code not in DXF_UNITS:
        from ezdxf.units import unit_name

        raise MeshError(
            f"{path} declares its units as {unit_name(code)} ($INSUNITS {code}); vares knows "
            f"{', '.join(DXF_UNITS.values())}: change the drawing's units"
        )
    soup = _soup(points, faces, path)
    layer = np.array(layer_of_face, dtype=np.int64)[soup.order]
    return soup, DXF_UNITS.get(code), layer, list(layers)
