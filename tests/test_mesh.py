import warnings

import meshio
import numpy as np
import pytest

from vares import MeshError, SurfaceMesh, read_mesh
from vares.geometry.examples import cylinder160, grid_cells, hypar

SQUARE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)


def test_mixed_mesh_areas_and_read_only(mixed_mesh):
    assert mixed_mesh.num_cells == 8
    p = mixed_mesh.points
    t, q = p[mixed_mesh.cells["triangle"]], p[mixed_mesh.cells["quad"]]  # quads are flat here
    triangles = 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)
    quads = 0.5 * np.linalg.norm(np.cross(q[:, 2] - q[:, 0], q[:, 3] - q[:, 1]), axis=1)
    assert mixed_mesh.area == pytest.approx(triangles.sum() + quads.sum(), rel=1e-12)
    with pytest.raises(ValueError):
        mixed_mesh.points[0, 0] = 5.0
    with pytest.raises(ValueError):
        mixed_mesh.cells["quad"][0, 0] = 3


def test_area_vectors_are_areas_along_the_normals(mixed_mesh):
    """A flat square tilted about x by 30°: every cell's vector is its area along the tilted
    normal; on a mixed mesh of triangles and flat quads the vectors' lengths are the cells'
    areas."""
    tilt = np.radians(30.0)
    rotation = np.array(
        [[1, 0, 0], [0, np.cos(tilt), -np.sin(tilt)], [0, np.sin(tilt), np.cos(tilt)]]
    )
    grid = hypar(size=2.0, rise=0.0, n=4, cell_type="quad")
    tilted = grid.transformed(grid.points @ rotation.T)
    vectors = tilted.area_vectors()
    np.testing.assert_allclose(vectors, np.outer(tilted.cell_areas(), rotation[:, 2]), atol=1e-14)
    lengths = np.linalg.norm(mixed_mesh.area_vectors(), axis=1)
    np.testing.assert_allclose(lengths, mixed_mesh.cell_areas(), rtol=1e-12)


def test_flat_area_of_a_grid():
    mesh = SurfaceMesh(
        np.column_stack(
            [
                np.meshgrid(np.arange(4.0), np.arange(3.0))[0].ravel(),
                np.meshgrid(np.arange(4.0), np.arange(3.0))[1].ravel(),
            ]
        ),
        grid_cells(4, 3, "quad"),
    )
    assert mesh.area == pytest.approx(6.0, rel=1e-14)
    assert mesh.points.shape == (12, 3)


@pytest.mark.parametrize(
    ("points", "cells", "message"),
    [
        (SQUARE * np.nan, {"quad": [[0, 1, 2, 3]]}, r"non-finite coordinates .* nodes 0, 1, 2, 3"),
        (SQUARE, {"quad": [[0, 1, 2, 7]]}, r"quad cells 0 refer to nodes outside 0\.\.3"),
        (SQUARE, {"triangle": [[0, 1, 2], [0, 2, -1]]}, r"triangle cells 1 refer to nodes"),
        (
            SQUARE,
            {"triangle": [[0, 1, 2], [0, 2, 3], [0, 3, 3]]},
            r"degenerate triangle cells 2 repeat a node",
        ),
        (
            np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0]], float),
            {"triangle": [[0, 1, 2]]},
            r"degenerate triangle cells 0 have \(nearly\) zero area",
        ),
        (SQUARE, {"tetra": [[0, 1, 2, 3]]}, r"cell type 'tetra' is not supported"),
        (SQUARE, {"triangle": np.zeros((0, 3), int)}, r"no triangle or quad cells"),
        (
            SQUARE,
            {"triangle": [[0, 1, 2], [0, 1, 3]]},
            r"inconsistent orientation.*triangle cells 0, 1",
        ),
        (SQUARE[:, :1], {"triangle": [[0, 1, 2]]}, r"points must have shape"),
        (SQUARE, {"triangle": [[0.5, 1, 2]]}, r"must be integers"),
    ],
)
def test_invalid_meshes_are_rejected_with_the_offending_items(points, cells, message):
    with pytest.raises(MeshError, match=message):
        SurfaceMesh(points, cells)


def test_non_manifold_edge():
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1]], float)
    cells = {"triangle": [[0, 1, 2], [1, 0, 3], [0, 1, 4]]}
    with pytest.raises(MeshError, match=r"non-manifold edges: edge \(0, 1\)"):
        SurfaceMesh(points, cells)


@pytest.mark.filterwarnings("ignore:dropped")
def test_bow_tie_node_is_non_manifold():
    # Cells (1, 1) and (2, 2) of a 4 × 4 grid touch only at grid node (2, 2) = node 12, and are
    # joined through a strip of cells around it: node 12 has two separate fans.
    x, y = np.meshgrid(np.arange(5.0), np.arange(5.0))
    points = np.column_stack([x.ravel(), y.ravel(), 0.1 * x.ravel() * y.ravel()])
    grid = grid_cells(5, 5, "quad")["quad"]
    keep = [j * 4 + i for i, j in [(1, 1), (1, 0), (2, 0), (3, 0), (3, 1), (3, 2), (2, 2)]]
    with pytest.raises(MeshError, match="non-manifold nodes 12"):
        SurfaceMesh(points, {"quad": grid[keep]}, drop_unused_nodes=True)


def test_closed_surface_is_rejected_with_advice():
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    tetrahedron = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]
    with pytest.raises(MeshError, match=r"closed.*give it panels.*vares panels"):
        SurfaceMesh(points, {"triangle": tetrahedron})


@pytest.mark.filterwarnings("ignore:dropped")
def test_disconnected_pieces_are_reported():
    points = np.vstack([SQUARE, SQUARE + np.array([3.0, 0.0, 0.0])])
    with pytest.raises(
        MeshError, match=r"2 separate pieces \(cells per piece: 2, 1\).*vares panels FILE"
    ):
        SurfaceMesh(points, {"triangle": [[0, 1, 2], [0, 2, 3], [4, 5, 6]]}, drop_unused_nodes=True)


def test_pieces_touching_at_a_node_only_are_not_one_surface():
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]], float)
    with pytest.raises(MeshError, match="2 separate pieces"):
        SurfaceMesh(points, {"triangle": [[0, 1, 2], [0, 3, 4]]})


def test_unused_nodes_are_an_error_or_dropped_with_a_warning():
    points = np.vstack([SQUARE, [[5, 5, 5]]])
    with pytest.raises(MeshError, match="nodes 4 belong to no cell"):
        SurfaceMesh(points, {"quad": [[0, 1, 2, 3]]})
    with pytest.warns(UserWarning, match="dropped 1 node"):
        mesh = SurfaceMesh(
            np.vstack([[[5, 5, 5]], SQUARE]), {"quad": [[1, 2, 3, 4]]}, drop_unused_nodes=True
        )
    assert mesh.num_points == 4
    np.testing.assert_array_equal(mesh.cells["quad"], [[0, 1, 2, 3]])
    np.testing.assert_array_equal(mesh.node_map, [1, 2, 3, 4])


@pytest.mark.parametrize(
    ("suffix", "fmt"),
    [
        (".obj", None),
        (".stl", None),
        (".ply", None),
        (".vtu", None),
        (".vtk", None),
        (".msh", "gmsh22"),
        (".off", None),
    ],
)
def test_read_mesh_formats(tmp_path, suffix, fmt):
    mesh = cylinder160(n_around=8, n_along=4)
    path = tmp_path / f"surface{suffix}"
    meshio.write(
        path, meshio.Mesh(mesh.points, [("triangle", mesh.cells["triangle"])]), file_format=fmt
    )
    read = read_mesh(path)
    assert read.num_points == mesh.num_points
    assert read.num_cells == mesh.num_cells
    assert read.area == pytest.approx(mesh.area, rel=1e-6)  # STL stores single precision


def test_read_mesh_quads_and_ignored_line_cells(tmp_path):
    mesh = hypar(n=4, cell_type="quad")
    path = tmp_path / "hypar.vtu"
    boundary = mesh.boundary_edges()
    meshio.write(path, meshio.Mesh(mesh.points, [("quad", mesh.cells["quad"]), ("line", boundary)]))
    read = read_mesh(path)
    assert set(read.cells) == {"quad"}
    assert read.area == pytest.approx(mesh.area, rel=1e-14)


def test_read_mesh_drops_unused_nodes_with_a_warning(tmp_path):
    path = tmp_path / "extra.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 9 9 9\nv 1 1 0\nf 1 2 4\n")
    with pytest.warns(UserWarning, match="dropped 1 node"):
        mesh = read_mesh(path)
    assert mesh.num_points == 3


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (b"", "is empty"),
        (b"solid x\nfacet normal 0 0 1\n  outer loop\n vertex 0 0", "cannot read"),
        (b"\x00\x01\x02garbage", "is not an STL file: it is binary and 10 bytes long"),
    ],
)
def test_read_mesh_bad_files(tmp_path, content, message):
    path = tmp_path / "bad.stl"
    path.write_bytes(content)
    with pytest.raises(MeshError, match=message):
        read_mesh(path)


def test_read_mesh_volume_mesh_and_missing_file(tmp_path):
    path = tmp_path / "tet.vtu"
    meshio.write(
        path, meshio.Mesh(np.vstack([SQUARE[:3], [[0, 0, 1]]]), [("tetra", [[0, 1, 2, 3]])])
    )
    with pytest.raises(MeshError, match="'tetra' cells"):
        read_mesh(path)
    with pytest.raises(FileNotFoundError):
        read_mesh(tmp_path / "missing.obj")


def test_read_mesh_with_nan(tmp_path):
    path = tmp_path / "nan.obj"
    path.write_text("v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(MeshError, match=r"non-finite coordinates .* nodes 1"):
            read_mesh(path)


@pytest.mark.parametrize("nodes", [40, 2500, 25000])
@pytest.mark.parametrize("crowded", [False, True])
def test_coincident_nodes_by_a_sweep_and_by_a_k_d_tree_agree(nodes, crowded, monkeypatch):
    """Nodes are compared along a sweep (up to _SWEEP_NODES), else through a k-d tree; both
    find the same clusters (chains of nodes closer than the tolerance join), also where every
    node lies at one place along the sweep (the sweep then hands over to the tree)."""
    from vares.geometry import weld

    rng = np.random.default_rng(nodes)
    points = rng.random((nodes, 3))
    if crowded:  # a plane across the sweep's direction
        points -= np.outer(points @ weld._SWEEP, weld._SWEEP)
    near = rng.choice(nodes, 3 * (nodes // 15), replace=False).reshape(3, -1)
    for step in (1, 2):  # chains of three: each node within the tolerance of the one before
        points[near[step]] = points[near[step - 1]] + rng.normal(
            scale=2e-5, size=(near.shape[1], 3)
        )
    merged = weld.coincident_nodes(points, 2e-4)
    monkeypatch.setattr(weld, "_SWEEP_NODES", 0 if nodes <= 20_000 else 10**6)
    other = weld.coincident_nodes(points, 2e-4)
    np.testing.assert_array_equal(merged, other)
    assert (merged != np.arange(nodes)).sum() >= near.shape[1] * 2  # the chains were found
    assert np.all(merged <= np.arange(nodes))  # each node goes to its cluster's first
