"""Mesh files: reading surfaces (any format meshio reads, Rhino ``.3dm``, Kratos ``.mdpa``),
writing surfaces and patterns, reading a pattern back."""

from __future__ import annotations

import contextlib
import io
import itertools
import tempfile
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..geometry.elements import ELEMENTS
from ..geometry.mesh import MeshError, SurfaceMesh, connected_pieces, index_listing
from ..geometry.repair import RepairReport
from ..geometry.repair import repair as repair_surface
from ..units import METRES
from .files import write_with
from .formats import check_stl, read_dxf, read_mdpa, read_obj, read_off
from .vtu import FACTOR_FIELD, declare_units, declared_units, split_string_fields

__all__ = [
    "MeshFile",
    "RawSurface",
    "read_mesh",
    "read_mesh_data",
    "read_mesh_file",
    "read_pattern",
    "read_raw",
    "write_surface",
    "write_surfaces",
]

#: Cell types of meshio that are ignored when reading a surface (lower-dimensional helpers).
_IGNORED_CELL_TYPES = {"vertex", "line", "line3"}


@dataclass
class RawSurface:
    """A file's points and faces as stored (no repair), its cell data (by face, in the order
    triangles, quads, polygons), the length units it declares, and the resolution of its
    coordinates (the spacing of single precision numbers at its largest coordinate; 0 when
    stored in double precision or as text); ``cell_names`` names the integer values of a cell
    data field where the file gives names (a DXF's layers)."""

    points: np.ndarray
    cells: dict[str, np.ndarray]
    polygons: list[np.ndarray] = field(default_factory=list)
    cell_data: dict[str, np.ndarray] = field(default_factory=dict)
    units: str | None = None
    resolution: float = 0.0
    cell_names: dict[str, dict[int, str]] = field(default_factory=dict)


@dataclass
class MeshFile:
    """A mesh file, read and repaired: the points and cells, the cell data of the kept cells,
    the declared units, the coordinates' resolution and what the repair changed."""

    path: Path
    points: np.ndarray
    cells: dict[str, np.ndarray]
    cell_data: dict[str, np.ndarray]
    units: str | None
    resolution: float
    repair: RepairReport
    cell_names: dict[str, dict[int, str]] = field(default_factory=dict)

    def surface(self) -> SurfaceMesh:
        """The surface, validated (a :class:`MeshError` names what is wrong and where)."""
        try:
            return SurfaceMesh(self.points, self.cells)
        except MeshError as exc:
            raise MeshError(f"{self.path}: {exc}") from None

    def pieces(self) -> list[tuple[SurfaceMesh, np.ndarray]]:
        """The connected pieces of the mesh, each validated, with the global ids of its cells."""
        ids = connected_pieces(self.points, self.cells)
        out = []
        bounds = np.cumsum([0] + [len(c) for c in self.cells.values()])
        for piece in range(ids.max() + 1):
            cells, kept = {}, []
            for (cell_type, block), a, b in zip(
                self.cells.items(), bounds[:-1], bounds[1:], strict=True
            ):
                mine = ids[a:b] == piece
                if mine.any():
                    cells[cell_type] = block[mine]
                    kept.append(np.flatnonzero(mine) + a)
            used = np.unique(np.concatenate([c.ravel() for c in cells.values()]))
            renumber = np.full(len(self.points), -1)
            renumber[used] = np.arange(used.size)
            try:
                mesh = SurfaceMesh(self.points[used], {t: renumber[c] for t, c in cells.items()})
            except MeshError as exc:
                raise MeshError(f"{self.path}: piece {piece + 1}: {exc}") from None
            out.append((mesh, np.concatenate(kept)))
        return out

    def precision_warning(self) -> str | None:
        """A sentence when the stored precision is coarse for the mesh's edges, else ``None``."""
        if self.resolution <= 0:
            return None
        edges = [
            np.linalg.norm(self.points[c] - self.points[np.roll(c, -1, axis=1)], axis=-1).ravel()
            for c in self.cells.values()
        ]
        mean_edge = float(np.mean(np.concatenate(edges)))
        if self.resolution <= COARSE_PRECISION * mean_edge:
            return None
        return (
            f"{self.path.name} stores coordinates in single precision up to "
            f"{np.abs(self.points).max():.3g} from the origin: they are only known to "
            f"{self.resolution:.3g} ({100 * self.resolution / mean_edge:.2g} % of the mean edge "
            "length); export in double precision or move the model near the origin"
        )


#: Coordinates resolved more coarsely than this fraction of the mean edge length are warned of.
COARSE_PRECISION = 1e-4


def read_mesh(path: str | Path) -> SurfaceMesh:
    """Read a surface mesh: OBJ, OFF (polygons too), STL, PLY, VTK/VTU, Gmsh and any other
    format meshio reads, or a Rhino ``.3dm`` file holding one mesh (see :mod:`vares.io.rhino`).

    The clear repairs of :func:`vares.geometry.repair.repair` are made (welding coincident
    nodes, dropping collapsed cells, orienting cells consistently, triangulating polygons);
    vertex and line cells are ignored.

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    MeshError
        The file cannot be read as a mesh, or the mesh is not a valid surface.
    """
    return read_mesh_data(path)[0]


def read_mesh_data(path: str | Path) -> tuple[SurfaceMesh, dict[str, np.ndarray]]:
    """:func:`read_mesh`, and the file's cell data in the mesh's global cell order. What the
    repair changed is said in a warning."""
    mesh_file = read_mesh_file(path)
    if mesh_file.repair.changed:
        warnings.warn(
            f"repaired {mesh_file.path.name}: {'; '.join(mesh_file.repair.actions())}",
            stacklevel=2,
        )
    return mesh_file.surface(), mesh_file.cell_data


def read_mesh_file(path: str | Path, *, repair: bool = True) -> MeshFile:
    """Read and (unless ``repair`` is false) repair a mesh file; see :class:`MeshFile`."""
    path = Path(path)
    raw = read_raw(path)
    try:
        fixed = repair_surface(raw.points, raw.cells, raw.polygons, weld=repair)
    except MeshError as exc:
        raise MeshError(f"{path}: {exc}") from None
    given = sum(len(c) for c in raw.cells.values()) + len(raw.polygons or [])
    if given and not fixed.cells:
        report = fixed.report
        raise MeshError(
            f"{path}: every one of its {given} cell(s) is collapsed (no area) or a duplicate "
            f"({report.collapsed_cells} collapsed, {report.duplicate_cells} duplicate, "
            f"{report.flat_boundary_cells} flat on the boundary): nothing is left to pattern"
        )
    cell_data = {name: np.asarray(values)[fixed.cell_map] for name, values in raw.cell_data.items()}
    return MeshFile(
        path,
        fixed.points,
        fixed.cells,
        cell_data,
        raw.units,
        raw.resolution,
        fixed.report,
        raw.cell_names,
    )


def read_raw(path: Path) -> RawSurface:
    """The points, faces and cell data of a file as stored (see :class:`RawSurface`)."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    if path.stat().st_size == 0:
        raise MeshError(f"{path} is empty")
    suffix = path.suffix.lower()
    if suffix == ".3dm":
        return _read_3dm(path)
    if suffix == ".dxf":
        soup, units, layer, names = read_dxf(path)
        return RawSurface(
            soup.points,
            soup.cells,
            soup.polygons,
            {"layer": layer},
            units=units,
            cell_names={"layer": dict(enumerate(names))},
        )
    if suffix in (".obj", ".off", ".mdpa"):
        readers = {".obj": read_obj, ".off": read_off, ".mdpa": read_mdpa}
        soup = readers[suffix](path)
        return RawSurface(soup.points, soup.cells, soup.polygons)
    if suffix == ".stl":
        check_stl(path)
    import meshio

    if not any(path.name.lower().endswith(known) for known in meshio.extension_to_filetypes):
        raise MeshError(
            f"{path}: {suffix or 'no suffix'!r} is no mesh format vares reads (.obj, .off, .stl, "
            ".ply, .vtu, .msh, .3dm, .dxf and the others of meshio): give the file its format's "
            "suffix"
        )
    return _read_meshio(path)


def _read_3dm(path: Path) -> RawSurface:
    from .rhino import read_3dm_stored

    meshes, units = read_3dm_stored(path)  # one parse of the file
    if len(meshes) > 1:
        names = ", ".join(m.name for m in meshes)
        raise MeshError(
            f"{path} holds {len(meshes)} meshes ({names}); pattern them as panels ('vares panels')"
        )
    mesh = meshes[0]
    resolution = float(np.spacing(np.float32(np.abs(mesh.points).max())))
    return RawSurface(np.array(mesh.points), mesh.cells, units=units, resolution=resolution)


def _read_meshio(path: Path) -> RawSurface:
    import meshio

    strings, source = {}, path
    folder = contextlib.ExitStack()  # a copy without string arrays, removed once read
    if path.suffix.lower() == ".vtu":
        stripped, strings = split_string_fields(path.read_bytes())
        if strings:  # meshio refuses string arrays: it reads the file without them
            source = Path(folder.enter_context(tempfile.TemporaryDirectory())) / path.name
            source.write_bytes(stripped)
    chatter = io.StringIO()  # some readers print their complaints: keep them for the error
    try:
        with (
            folder,
            warnings.catch_warnings(),
            contextlib.redirect_stdout(chatter),
            contextlib.redirect_stderr(chatter),
        ):
            warnings.simplefilter("ignore")
            raw = meshio.read(source)
    except meshio.ReadError as exc:
        raise MeshError(f"cannot read {path}: {exc}") from exc
    except (Exception, SystemExit) as exc:  # a reader may even exit on a broken file
        detail = chatter.getvalue().strip().splitlines()
        reason = detail[-1] if detail else f"{type(exc).__name__}: {exc}"
        raise MeshError(f"cannot read {path}: {reason}") from None
    cells: dict[str, list[np.ndarray]] = {}
    polygons: list[np.ndarray] = []
    data: dict[str, dict[str, list[np.ndarray]]] = {}
    for index, block in enumerate(raw.cells):
        if block.type in _IGNORED_CELL_TYPES:
            continue
        kind = "polygon" if block.type.startswith("polygon") else block.type
        if kind not in (*ELEMENTS, "polygon"):
            raise MeshError(
                f"{path} contains {block.type!r} cells; vares needs a surface mesh of "
                "triangles, quads or polygons"
            )
        if kind == "polygon":
            polygons.extend(np.asarray(block.data))
        else:
            cells.setdefault(kind, []).append(np.asarray(block.data))
        for name, arrays in raw.cell_data.items():
            data.setdefault(name, {}).setdefault(kind, []).append(np.asarray(arrays[index]))
    if not cells and not polygons:
        raise MeshError(f"{path} contains no triangle or quad cells")
    blocks = {t: np.vstack(b) for t, b in cells.items()}
    counts = {**{t: len(b) for t, b in blocks.items()}, "polygon": len(polygons)}
    cell_data = {}
    for name, by_type in data.items():
        if all(sum(len(a) for a in by_type.get(t, [])) == n for t, n in counts.items() if n):
            cell_data[name] = np.concatenate(
                [np.concatenate(by_type[t]) for t in counts if counts[t]]
            )
    points = np.asarray(raw.points)
    resolution = 0.0
    if points.dtype == np.float32 and points.size:
        resolution = float(np.spacing(np.abs(points).max()))
    if points.ndim == 2 and points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    units = _declared_units(path, strings, raw.field_data.get(FACTOR_FIELD))
    return RawSurface(
        points.astype(float), blocks, polygons, cell_data, units=units, resolution=resolution
    )


def _declared_units(path: Path, strings: dict[str, str | None], factor) -> str | None:
    """The units a file's field data states: a string field (VTK's) or ``metres_per_unit``."""
    named = declared_units(strings)
    if named is not None and named not in METRES:
        raise MeshError(
            f"{path} declares its units as {named!r} (field data); vares knows "
            f"{', '.join(METRES)}: change the file's units field"
        )
    if factor is None or named is not None:
        return named
    value = float(np.ravel(factor)[0]) if np.size(factor) else float("nan")
    for name, metres in METRES.items():
        if abs(value - metres) <= 1e-9 * metres:
            return name
    raise MeshError(
        f"{path} states {value:g} metres per unit ({FACTOR_FIELD}); vares knows "
        + ", ".join(f"{name} ({metres:g})" for name, metres in METRES.items())
    )


def write_surface(
    path: Path,
    mesh: SurfaceMesh,
    coordinates: np.ndarray | None = None,
    fields: dict[str, np.ndarray] | None = None,
    point_data: dict[str, np.ndarray] | None = None,
    units: str | None = None,
) -> None:
    """Write the mesh (or, with ``coordinates`` ``(n, 2)``, the flat pattern at z = 0; ``(n, 3)``,
    the mesh moved there).

    The format follows the suffix (any format meshio writes: .obj, .vtu, .ply, .stl, …); nodes
    and cells are those of ``mesh``, in the same order. ``fields`` (per cell, global cell order)
    are written as cell data and ``point_data`` (per node) as point data where the format has
    them (VTU, VTK). A VTU file states ``units`` (length) in its field data (:mod:`.vtu`).
    """
    points = mesh.points
    if coordinates is not None and coordinates.shape[1] == 3:
        points = np.asarray(coordinates, dtype=float)
    elif coordinates is not None:
        points = np.column_stack([coordinates, np.zeros(len(coordinates))])
    blocks = list(mesh.cells.items())
    cell_data = {}
    if fields:
        bounds = np.cumsum([0] + [len(c) for _, c in blocks])
        cell_data = {
            name: [np.asarray(values[a:b], dtype=float) for a, b in itertools.pairwise(bounds)]
            for name, values in fields.items()
        }
    _write_meshio(path, points, blocks, cell_data, point_data, units)


def write_surfaces(
    path: Path,
    parts: Sequence[tuple[SurfaceMesh, np.ndarray, dict[str, np.ndarray]]],
    units: str | None = None,
) -> None:
    """Write several flat pieces into one file, as :func:`write_surface` one: each part its mesh
    (triangles), pattern coordinates ``(n, 2)`` (already placed where the piece is to be seen)
    and cell fields; nodes and cells part after part, with the cell field ``piece`` (1 for the
    first). A field is written when every part has it."""
    if not parts:
        raise ValueError("write_surfaces needs at least one part")
    points, cells, offset = [], [], 0
    for mesh, coordinates, _ in parts:
        if set(mesh.cells) != {"triangle"}:
            raise ValueError("write_surfaces writes triangle meshes only")
        flat = np.asarray(coordinates, dtype=float)
        points.append(np.column_stack([flat[:, :2], np.zeros(len(flat))]))
        cells.append(mesh.cells["triangle"] + offset)
        offset += mesh.num_points
    names = set.intersection(*(set(f) for _, _, f in parts))
    cell_data = {
        name: [np.concatenate([np.asarray(f[name], dtype=float) for _, _, f in parts])]
        for name in sorted(names)
    }
    cell_data["piece"] = [
        np.concatenate(
            [np.full(m.num_cells, k, dtype=float) for k, (m, _, _) in enumerate(parts, 1)]
        )
    ]
    _write_meshio(path, np.vstack(points), [("triangle", np.vstack(cells))], cell_data, None, units)


def _write_meshio(path, points, blocks, cell_data, point_data, units) -> None:
    import meshio

    point_data = {k: np.asarray(v, dtype=float) for k, v in (point_data or {}).items()}
    out = meshio.Mesh(points, blocks, cell_data=cell_data, point_data=point_data)
    # VTU stays uncompressed: zlib took 0.45 s of every 100k-cell file (binary, twice the size)
    vtu = Path(path).suffix.lower() == ".vtu"

    def write(temporary: Path) -> None:  # it keeps the suffix, from which meshio takes the format
        meshio.write(temporary, out, **({"compression": None} if vtu else {}))
        if vtu and units is not None:
            declare_units(temporary, METRES[units])

    write_with(Path(path), write)


def read_pattern(path: Path, mesh: SurfaceMesh) -> np.ndarray:
    """Pattern coordinates ``(n, 2)`` from a file with the nodes and faces of ``mesh`` (as
    :func:`write_surface` writes it), lying in a plane z = const."""
    path = Path(path)
    raw = read_raw(path)
    same = len(raw.points) == mesh.num_points and all(
        t in raw.cells and np.array_equal(raw.cells[t], c) for t, c in mesh.cells.items()
    )
    if not same:
        raise MeshError(f"{path} does not have the nodes and faces of the surface mesh")
    points = np.asarray(raw.points, dtype=float)
    bad = np.flatnonzero(~np.isfinite(points).all(axis=1))
    if bad.size:
        raise MeshError(
            f"{path}: the pattern's coordinates are not finite (NaN or inf) at nodes "
            f"{index_listing(bad)}"
        )
    height = np.ptp(points[:, 2]) if points.shape[1] == 3 else 0.0
    if height > 1e-9 * np.ptp(points[:, :2]):
        raise MeshError(f"{path} is not flat (its z varies): not a pattern")
    return points[:, :2].copy()
