"""Rhino ``.3dm`` files: meshes, and the render meshes of surfaces and polysurfaces.

Every object that carries a mesh becomes a named surface: its object name, or else its layer
path, or else ``object-K``. A surface or polysurface (Brep, extrusion) has a mesh only when the
file was saved with render meshes (Rhino's default for shaded views); one without is skipped
and named in the error if no mesh is left.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..geometry.mesh import MeshError, SurfaceMesh
from ..geometry.repair import RepairReport, repair
from ..geometry.weld import coincident_nodes

__all__ = [
    "NamedMesh",
    "RawMesh",
    "RhinoFile",
    "read_3dm",
    "read_3dm_file",
    "read_3dm_raw",
    "read_3dm_stored",
    "unit_system",
    "write_3dm",
]

#: Rhino unit systems and vares' names for them.
_UNITS = {
    "Millimeters": "mm",
    "Centimeters": "cm",
    "Meters": "m",
    "Inches": "in",
    "Feet": "ft",
}


@dataclass(frozen=True)
class NamedMesh:
    """A mesh read from a file, with the name and layer it had there, and what its repair
    changed (:func:`vares.geometry.repair.repair`)."""

    name: str
    layer: str
    mesh: SurfaceMesh
    repair: RepairReport = field(default_factory=RepairReport)


@dataclass(frozen=True)
class RawMesh:
    """An object's mesh as the file stores it (a Brep's face meshes joined): points and cells,
    not yet repaired nor checked."""

    name: str
    layer: str
    points: np.ndarray
    cells: dict[str, np.ndarray]


def _rhino_mesh_arrays(mesh) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    vertices = mesh.Vertices
    points = np.array([[vertices[i].X, vertices[i].Y, vertices[i].Z] for i in range(len(vertices))])
    triangles, quads = [], []
    faces = mesh.Faces
    for k in range(faces.Count):
        face = faces[k]
        if face[2] == face[3]:
            triangles.append(face[:3])
        else:
            quads.append(face)
    cells = {}
    if triangles:
        cells["triangle"] = np.array(triangles, dtype=np.int64)
    if quads:
        cells["quad"] = np.array(quads, dtype=np.int64)
    return points, cells


def _weld(parts: list[tuple[np.ndarray, dict[str, np.ndarray]]]):
    """Join meshes, merging coincident vertices (render meshes of adjacent Brep faces)."""
    points = np.vstack([p for p, _ in parts])
    scale = float(np.ptp(points, axis=0).max()) or 1.0
    first, inverse = np.unique(coincident_nodes(points, 1e-9 * scale), return_inverse=True)
    cells: dict[str, list[np.ndarray]] = {}
    offset = 0
    for part_points, part_cells in parts:
        for cell_type, block in part_cells.items():
            cells.setdefault(cell_type, []).append(inverse[block + offset])
        offset += len(part_points)
    return points[first], {t: np.vstack(b) for t, b in cells.items()}


@dataclass(frozen=True)
class RhinoFile:
    """What a Rhino file holds for vares, read with one parse: its objects' meshes (repaired
    unless asked not to) and its declared length unit (``None`` when it declares none)."""

    meshes: list[NamedMesh]
    units: str | None


def _model(path: str | Path):
    """The parsed Rhino model of ``path`` (a one-line :class:`MeshError` if it is none)."""
    import rhino3dm

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    model = rhino3dm.File3dm.Read(str(path))
    if model is None:
        raise MeshError(f"cannot read {path}: not a Rhino 3dm file, or a damaged one")
    return model


def _raw_meshes(model, path: Path) -> list[RawMesh]:
    import rhino3dm

    layers = {i: model.Layers[i].FullPath for i in range(len(model.Layers))}
    out, skipped = [], []
    for index, obj in enumerate(model.Objects):
        geometry, attributes = obj.Geometry, obj.Attributes
        layer = layers.get(attributes.LayerIndex, "")
        name = attributes.Name or layer or f"object-{index}"
        parts = []
        if isinstance(geometry, rhino3dm.Mesh):
            parts.append(_rhino_mesh_arrays(geometry))
        elif isinstance(geometry, rhino3dm.Brep):
            for k in range(len(geometry.Faces)):
                face_mesh = geometry.Faces[k].GetMesh(rhino3dm.MeshType.Any)
                if face_mesh is not None:
                    parts.append(_rhino_mesh_arrays(face_mesh))
        elif isinstance(geometry, rhino3dm.Extrusion):
            extrusion_mesh = geometry.GetMesh(rhino3dm.MeshType.Any)
            if extrusion_mesh is not None:
                parts.append(_rhino_mesh_arrays(extrusion_mesh))
        else:
            continue
        parts = [p for p in parts if p[1]]
        if not parts:
            skipped.append(name)
            continue
        points, cells = parts[0] if len(parts) == 1 else _weld(parts)
        out.append(RawMesh(name, layer, points, cells))
    if not out:
        detail = f" (no render mesh in {', '.join(skipped)}: save with meshes)" if skipped else ""
        raise MeshError(f"{path} contains no usable mesh{detail}")
    return out


def _units(model, path: Path) -> str | None:
    system = model.Settings.ModelUnitSystem.name
    if system in ("None", "Unset"):
        return None
    if system not in _UNITS:
        raise MeshError(
            f"{path} is modelled in {system}; vares takes "
            f"{', '.join(_UNITS)}: change the model's units in Rhino"
        )
    return _UNITS[system]


def read_3dm_raw(path: str | Path) -> list[RawMesh]:
    """Every object's mesh of a Rhino file as stored, named (see the module docs).

    Raises
    ------
    FileNotFoundError
        No such file.
    MeshError
        Not a readable 3dm file, or no usable mesh in it.
    """
    return _raw_meshes(_model(path), Path(path))


def read_3dm_stored(path: str | Path) -> tuple[list[RawMesh], str | None]:
    """Every object's mesh as stored (:func:`read_3dm_raw`) and the file's length unit
    (:func:`unit_system`), from one parse of the file."""
    path = Path(path)
    model = _model(path)
    return _raw_meshes(model, path), _units(model, path)


def read_3dm_file(path: str | Path, *, repair_meshes: bool = True) -> RhinoFile:
    """All meshes of a Rhino file, named (see the module docs), and its length unit, from one
    parse of the file. Each mesh is repaired as a mesh file is
    (:func:`vares.geometry.repair.repair`: Rhino meshes often keep a vertex per face at
    creases and seams, which would cut the surface apart) unless ``repair_meshes`` is false;
    then it is taken as stored (only polygons triangulated, unused nodes dropped).

    Raises
    ------
    FileNotFoundError
        No such file.
    MeshError
        Not a readable 3dm file, no usable mesh in it, a unit vares does not know, or an
        invalid mesh (naming the object).
    """
    path = Path(path)
    stored, units = read_3dm_stored(path)
    out = []
    for raw in stored:
        try:
            fixed = repair(raw.points, raw.cells, weld=repair_meshes)
            if not fixed.cells:
                raise MeshError(
                    "every one of its cells is collapsed (no area) or a duplicate: nothing is "
                    "left to pattern"
                )
            mesh = SurfaceMesh(fixed.points, fixed.cells)
        except MeshError as exc:
            raise MeshError(f"{path}: object {raw.name!r}: {exc}") from exc
        out.append(NamedMesh(raw.name, raw.layer, mesh, fixed.report))
    return RhinoFile(out, units)


def read_3dm(path: str | Path, *, repair_meshes: bool = True) -> list[NamedMesh]:
    """All meshes of a Rhino file, named and repaired (:func:`read_3dm_file`).

    Raises
    ------
    FileNotFoundError
        No such file.
    MeshError
        Not a readable 3dm file, no usable mesh in it, or an invalid mesh (naming the object).
    """
    return read_3dm_file(path, repair_meshes=repair_meshes).meshes


def unit_system(path: str | Path) -> str | None:
    """The length unit a Rhino file declares (``"mm"``, ``"m"`` …), ``None`` when it declares
    none; a unit vares does not know is a :class:`MeshError`."""
    return _units(_model(path), Path(path))


def write_3dm(path: str | Path, meshes: list[NamedMesh], units: str | None = None) -> None:
    """Write meshes to a Rhino file, each as a named object on a layer of its own name, in the
    given length units (``"mm"``, ``"m"`` …; Rhino's default when None)."""
    import rhino3dm

    model = rhino3dm.File3dm()
    if units is not None:
        names = {v: k for k, v in _UNITS.items()}
        model.Settings.ModelUnitSystem = getattr(rhino3dm.UnitSystem, names[units])
    layer_index: dict[str, int] = {}
    for named in meshes:
        layer_name = named.layer or named.name
        if layer_name not in layer_index:
            layer = rhino3dm.Layer()
            layer.Name = layer_name
            layer_index[layer_name] = model.Layers.Add(layer)
        mesh = rhino3dm.Mesh()
        for x, y, z in named.mesh.points:
            mesh.Vertices.Add(float(x), float(y), float(z))
        for cells in named.mesh.cells.values():
            for cell in cells:
                mesh.Faces.AddFace(*(int(v) for v in cell))
        attributes = rhino3dm.ObjectAttributes()
        attributes.Name = named.name
        attributes.LayerIndex = layer_index[layer_name]
        model.Objects.AddMesh(mesh, attributes)
    from .files import atomic_path

    with atomic_path(Path(path)) as temporary:
        if not model.Write(str(temporary), 7):
            raise OSError(f"could not write {path}")
