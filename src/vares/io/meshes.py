"""Mesh files: reading surfaces (any format meshio reads, and Rhino ``.3dm``), writing surfaces
and patterns, reading a pattern back."""

from __future__ import annotations

import contextlib
import io
import itertools
import warnings
from pathlib import Path

import numpy as np

from ..geometry.elements import ELEMENTS
from ..geometry.mesh import MeshError, SurfaceMesh
from .files import write_with

__all__ = ["read_mesh", "read_mesh_data", "read_pattern", "write_surface"]

#: Cell types of meshio that are ignored when reading a surface (lower-dimensional helpers).
_IGNORED_CELL_TYPES = {"vertex", "line", "line3"}


def read_mesh(path: str | Path) -> SurfaceMesh:
    """Read a surface mesh from any format meshio reads (OBJ, STL, PLY, VTK/VTU, Gmsh, …) or
    from a Rhino ``.3dm`` file holding one mesh (see :mod:`vares.rhino`).

    Triangle and quad cells are kept; vertex and line cells (boundary markers in many
    formats) are ignored. Nodes that belong to no cell are dropped with a warning.

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    MeshError
        The file cannot be read as a mesh, or the mesh is not a valid surface.
    """
    return read_mesh_data(path)[0]


def _meshio_read(path: Path):
    """``meshio.read``, every failure a :class:`MeshError` naming the file."""
    import meshio

    chatter = io.StringIO()  # some readers print their complaints: keep them for the error
    try:
        with (
            warnings.catch_warnings(),
            contextlib.redirect_stdout(chatter),
            contextlib.redirect_stderr(chatter),
        ):
            warnings.simplefilter("ignore")
            return meshio.read(path)
    except meshio.ReadError as exc:
        raise MeshError(f"cannot read {path}: {exc}") from exc
    except (Exception, SystemExit) as exc:  # a reader may even exit on a broken file
        detail = chatter.getvalue().strip().splitlines()
        reason = detail[-1] if detail else f"{type(exc).__name__}: {exc}"
        raise MeshError(f"cannot read {path}: {reason}") from None


def read_mesh_data(path: str | Path) -> tuple[SurfaceMesh, dict[str, np.ndarray]]:
    """:func:`read_mesh`, and the file's cell data in the mesh's global cell order.

    Each cell data array has shape ``(num_cells,)`` or ``(num_cells, k)``; arrays that exist
    only on some cell blocks are left out.
    """

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    if path.stat().st_size == 0:
        raise MeshError(f"{path} is empty")
    if path.suffix.lower() == ".3dm":
        from .rhino import read_3dm

        meshes = read_3dm(path)
        if len(meshes) > 1:
            names = ", ".join(m.name for m in meshes)
            raise MeshError(
                f"{path} holds {len(meshes)} meshes ({names}); pattern them as panels "
                "('vares panels')"
            )
        return meshes[0].mesh, {}
    raw = _meshio_read(path)
    cells: dict[str, list[np.ndarray]] = {}
    data: dict[str, dict[str, list[np.ndarray]]] = {}
    for index, block in enumerate(raw.cells):
        if block.type in _IGNORED_CELL_TYPES:
            continue
        if block.type not in ELEMENTS:
            raise MeshError(
                f"{path} contains {block.type!r} cells; vares needs a surface mesh of "
                "triangles and/or quads"
            )
        cells.setdefault(block.type, []).append(np.asarray(block.data))
        for name, arrays in raw.cell_data.items():
            data.setdefault(name, {}).setdefault(block.type, []).append(np.asarray(arrays[index]))
    if not cells:
        raise MeshError(f"{path} contains no triangle or quad cells")
    mesh = SurfaceMesh(
        raw.points, {t: np.vstack(blocks) for t, blocks in cells.items()}, drop_unused_nodes=True
    )
    cell_data = {}
    for name, by_type in data.items():
        if all(len(by_type.get(t, [])) == len(cells[t]) for t in cells):
            cell_data[name] = np.concatenate([np.concatenate(by_type[t]) for t in cells])
    return mesh, cell_data


def write_surface(
    path: Path,
    mesh: SurfaceMesh,
    coordinates: np.ndarray | None = None,
    fields: dict[str, np.ndarray] | None = None,
    point_data: dict[str, np.ndarray] | None = None,
) -> None:
    """Write the mesh (or, with ``coordinates`` ``(n, 2)``, the flat pattern at z = 0; ``(n, 3)``,
    the mesh moved there).

    The format follows the suffix (any format meshio writes: .obj, .vtu, .ply, .stl, …); nodes
    and cells are those of ``mesh``, in the same order. ``fields`` (per cell, global cell order)
    are written as cell data and ``point_data`` (per node) as point data where the format has
    them (VTU, VTK).
    """
    import meshio

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
    point_data = {k: np.asarray(v, dtype=float) for k, v in (point_data or {}).items()}
    out = meshio.Mesh(points, blocks, cell_data=cell_data, point_data=point_data)
    # the temporary file keeps the suffix, from which meshio takes the format
    write_with(Path(path), lambda p: meshio.write(p, out))


def read_pattern(path: Path, mesh: SurfaceMesh) -> np.ndarray:
    """Pattern coordinates ``(n, 2)`` from a file written by :func:`write_surface` for ``mesh``.

    The file must have the same cells as ``mesh`` (same nodes and faces) and lie in z = 0.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    raw = _meshio_read(path)
    cells = {b.type: b.data for b in raw.cells if b.type in mesh.cells}
    same = len(raw.points) == mesh.num_points and all(
        t in cells and np.array_equal(cells[t], c) for t, c in mesh.cells.items()
    )
    if not same:
        raise MeshError(f"{path} does not have the nodes and faces of the surface mesh")
    points = np.asarray(raw.points, dtype=float)
    if points.shape[1] == 3 and np.abs(points[:, 2]).max(initial=0.0) > 1e-9 * np.ptp(points):
        raise MeshError(f"{path} is not flat (z ≠ 0): not a pattern")
    return points[:, :2].copy()
