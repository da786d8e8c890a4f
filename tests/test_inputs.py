"""Real inputs: readers for ordinary files, repair said aloud, units, coarse precision."""

import json
import re

import meshio
import numpy as np
import pytest
from conftest import error_line, run

import vares
from vares.geometry.examples import hypar
from vares.geometry.mesh import MeshError
from vares.geometry.repair import repair
from vares.io.meshes import read_mesh_file
from vares.io.rhino import NamedMesh, write_3dm


def _obj_with_texture(path, mesh):
    """An OBJ as modellers write it: texture and normal indices, negative indices for the last
    face, a comment and a group."""
    lines = ["# exported", "o roof", "g canopy"]
    lines += [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in mesh.points]
    lines += [f"vt {u:.3f} {v:.3f}" for u, v in mesh.points[:, :2] / 10]
    lines += ["vn 0 0 1"]
    triangles = mesh.cells["triangle"] + 1
    for a, b, c in triangles[:-1]:
        lines.append(f"f {a}/{a}/1 {b}/{b}/1 {c}/{c}/1")
    n = mesh.num_points
    a, b, c = triangles[-1] - n - 1  # relative indices
    lines.append(f"f {a}//1 {b}//1 {c}//1")
    path.write_text("\n".join(lines) + "\n")


def test_obj_with_texture_normal_and_relative_indices(tmp_path):
    mesh = hypar(n=6)
    path = tmp_path / "roof.obj"
    _obj_with_texture(path, mesh)
    read = vares.read_mesh(path)
    np.testing.assert_array_equal(read.points, mesh.points)
    np.testing.assert_array_equal(read.cells["triangle"], mesh.cells["triangle"])


@pytest.mark.parametrize(
    ("tail", "message"),
    [
        ("f \n", "ends in an incomplete face at line {line} ('f')"),
        ("f", "ends in an incomplete face at line {line} ('f')"),
        ("f 1 2\n\n", "ends in an incomplete face at line {line} ('f 1 2')"),
        ("f 1 2\nf 1 2 3\n", "line {line}: a face needs three vertices or more"),
    ],
)
def test_an_obj_with_an_incomplete_face_names_its_line(tmp_path, tail, message):
    mesh = hypar(n=4)
    lines = [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in mesh.points]
    lines += [f"f {a} {b} {c}" for a, b, c in mesh.cells["triangle"] + 1]
    path = tmp_path / "cut_short.obj"
    path.write_text("\n".join(lines) + "\n" + tail)
    expected = message.format(line=len(lines) + 1)
    with pytest.raises(MeshError, match=re.escape(expected)):
        read_mesh_file(path)
    result = run("pattern", path, "-o", tmp_path / "out")
    assert result.exit_code == 2 and expected in error_line(result)
    assert not (tmp_path / "out").exists()


def test_an_obj_of_faces_of_several_sizes_is_read_face_by_face(tmp_path):
    # quads first and last, a triangle and a pentagon between: as many indices as four quads
    path = tmp_path / "mixed.obj"
    points = [(0, 0), (1, 0), (2, 0), (3, 0), (0, 1), (1, 1), (2, 1), (3, 1), (1.5, 0), (1.5, 1)]
    faces = ["1 2 6 5", "2 9 6", "9 3 7 10 6", "3 4 8 7"]
    path.write_text(
        "".join(f"v {x} {y} 0\n" for x, y in points) + "".join(f"f {f}\n" for f in faces)
    )
    mesh_file = read_mesh_file(path)
    assert mesh_file.repair.triangulated_polygons == 1
    surface = mesh_file.surface()
    assert len(surface.cells["quad"]) == 2 and len(surface.cells["triangle"]) == 1 + 3
    assert surface.cell_areas().sum() == pytest.approx(3.0, rel=1e-12)


def test_a_file_named_stl_must_be_an_stl(tmp_path):
    mesh = hypar(n=4)
    surface = meshio.Mesh(mesh.points, [("triangle", mesh.cells["triangle"])])
    meshio.write(tmp_path / "ascii.stl", surface, binary=False)
    meshio.write(tmp_path / "binary.stl", surface, binary=True)
    binary = (tmp_path / "binary.stl").read_bytes()
    # some exporters begin a binary STL's header with "solid", as an ASCII one begins
    (tmp_path / "solid.stl").write_bytes(b"solid part".ljust(80) + binary[80:])
    for name in ("ascii.stl", "binary.stl", "solid.stl"):
        read = vares.read_mesh(tmp_path / name)
        assert read.num_cells == mesh.num_cells and read.num_points == mesh.num_points, name
    n = mesh.num_cells
    obj = ["# roof"] + [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in mesh.points]
    obj += ["vn 0 0 1"] * 3 + [f"f {a} {b} {c}" for a, b, c in mesh.cells["triangle"] + 1]
    ascii_lines = (tmp_path / "ascii.stl").read_text().splitlines()
    ascii_lines[3] = ascii_lines[3].replace("vertex", "v")
    bad = {
        # meshio reads it as ASCII STL: the last three numbers of each line, scattered triangles
        "obj.stl": ("\n".join(obj).encode(), f"an OBJ file ({mesh.num_points} 'v' and {n} 'f'"),
        "short.stl": (binary[:-7], f"84 + 50·{n} = {84 + 50 * n} bytes, this file has "),
        "text.stl": (b"mesh\n1 2 3\n4 5 6\n", "an ASCII STL begins with 'solid'"),
        "stray.stl": ("\n".join(ascii_lines).encode(), "line 4: 'v "),
    }
    for name, (content, message) in bad.items():
        (tmp_path / name).write_bytes(content)
        with pytest.raises(MeshError, match=re.escape(message)):
            read_mesh_file(tmp_path / name)
    result = run("pattern", tmp_path / "obj.stl", "-o", tmp_path / "out")
    assert result.exit_code == 2
    assert "obj.stl is not an STL file: it is an OBJ file" in error_line(result)
    assert not (tmp_path / "out").exists()


def test_off_and_ply_with_quads_and_polygons(tmp_path):
    # a 3 × 2 grid of quads and a pentagon closing one side
    x, y = np.meshgrid(np.arange(4.0), np.arange(3.0))
    points = np.column_stack([x.ravel(), y.ravel(), 0.05 * x.ravel() ** 2])
    quads = [
        [j * 4 + i, j * 4 + i + 1, (j + 1) * 4 + i + 1, (j + 1) * 4 + i]
        for j in range(2)
        for i in range(3)
    ]
    points = np.vstack([points, [[4.0, 0.0, 0.8], [4.5, 1.0, 1.0], [4.0, 2.0, 0.8]]])
    pentagon = [3, 12, 13, 14, 11, 7]  # a hexagon, to be triangulated
    off = tmp_path / "panel.off"
    off.write_text(
        "OFF\n# a comment\n"
        + f"{len(points)} {len(quads) + 1} 0\n"
        + "".join(f"{p[0]} {p[1]} {p[2]}\n" for p in points)
        + "".join(f"4 {' '.join(map(str, q))} 255 0 0\n" for q in quads)
        + f"6 {' '.join(map(str, pentagon))}\n"
    )
    mesh_file = read_mesh_file(off)
    assert mesh_file.repair.triangulated_polygons == 1
    surface = mesh_file.surface()
    assert len(surface.cells["quad"]) == 6 and len(surface.cells["triangle"]) == 4
    # the triangles cover the polygon: their vector areas add up to the polygon's (which any
    # triangulation of a closed polygon, planar or not, must give)
    polygon = points[pentagon]
    vector_area = 0.5 * np.cross(polygon, np.roll(polygon, -1, axis=0)).sum(axis=0)
    triangles = surface.points[surface.cells["triangle"]]
    covered = 0.5 * np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    np.testing.assert_allclose(covered.sum(axis=0), vector_area, atol=1e-12)
    assert set(surface.cells["triangle"].ravel()) == set(pentagon)
    ply = tmp_path / "panel.ply"
    meshio.write(ply, meshio.Mesh(points[:12], [("quad", np.array(quads))]), binary=False)
    assert len(vares.read_mesh(ply).cells["quad"]) == 6


def test_a_triangle_soup_is_welded_and_reoriented_and_said_so(tmp_path):
    mesh = hypar(n=5)
    triangles = mesh.cells["triangle"]
    soup_points = mesh.points[triangles.ravel()]  # every triangle its own three nodes
    soup = np.arange(soup_points.shape[0]).reshape(-1, 3)
    soup[::3] = soup[::3, ::-1]  # a third of the cells the other way round
    path = tmp_path / "soup.stl"
    meshio.write(path, meshio.Mesh(soup_points, [("triangle", soup)]), binary=False)
    raw = tmp_path / "soup.obj"
    raw.write_text(
        "".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in soup_points)
        + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in soup)
    )
    mesh_file = read_mesh_file(raw)
    report = mesh_file.repair
    assert report.welded_nodes == soup_points.shape[0] - mesh.num_points
    assert report.flipped_cells == len(soup[::3])
    surface = mesh_file.surface()
    assert surface.num_points == mesh.num_points and surface.area == pytest.approx(mesh.area)
    with pytest.warns(UserWarning, match=r"repaired soup.obj: welded 114 node"):
        vares.read_mesh(raw)
    result = run("pattern", raw, "-o", tmp_path / "out", "-q")
    assert result.exit_code == 0, result.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["repairs"]["soup.obj"]["welded_nodes"] == 114
    assert any("repaired soup.obj" in w for w in summary["warnings"])
    result = run("pattern", raw, "-o", tmp_path / "strict", "--no-repair", "-q")
    assert result.exit_code == 2 and "separate pieces" in error_line(result)


def test_repair_drops_collapsed_and_duplicate_cells_and_keeps_cell_data_aligned():
    points = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [1e-12, 0, 0]], float)
    cells = {"triangle": np.array([[0, 1, 2], [0, 2, 3], [2, 0, 1], [4, 1, 0]])}
    fixed = repair(points, cells)
    assert fixed.report.welded_nodes == 1 and fixed.report.collapsed_cells == 1
    assert fixed.report.unused_nodes == 0  # the welded node is not counted twice
    stray = repair(np.vstack([points, [[5.0, 5.0, 0.0]]]), cells)  # a node of no cell
    assert stray.report.welded_nodes == 1 and stray.report.unused_nodes == 1
    assert fixed.report.duplicate_cells == 1
    np.testing.assert_array_equal(fixed.cell_map, [0, 1])
    assert len(fixed.points) == 4


def test_units_declared_by_a_rhino_file_and_implausible_sizes(tmp_path):
    roof = hypar(size=27600.0, rise=0.06 / 1000, n=6)  # a 27.6 m roof modelled in millimetres
    path = tmp_path / "roof.3dm"
    write_3dm(path, [NamedMesh("roof", "membrane", roof)], units="mm")
    result = run("pattern", path, "-o", tmp_path / "out", "-q", "--allowance", 20)
    assert result.exit_code == 0, result.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["units"]["length"] == "mm"
    assert not any("implausible" in w for w in summary["warnings"])
    result = run("pattern", path, "-o", tmp_path / "m", "--units", "m", "-q")
    assert result.exit_code == 2 and "declares its coordinates in mm" in error_line(result)
    # the same roof as a unitless file, run without --units
    obj = tmp_path / "roof.obj"
    obj.write_text(
        "".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in roof.points)
        + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in roof.cells["triangle"])
    )
    result = run("pattern", obj, "-o", tmp_path / "guess")
    assert result.exit_code == 0, result.stderr
    assert "the surface is 27.6 km across in m" in result.stderr
    assert "pass --units mm" in result.stderr
    summary = json.loads((tmp_path / "guess" / "summary.json").read_text())
    assert any("27.6 km" in w for w in summary["warnings"])


def test_single_precision_far_from_the_origin_is_warned_of(tmp_path):
    roof = hypar(size=10.0, n=8)
    site = roof.points + np.array([4.3e6, 5.2e5, 300.0])  # UTM-like site coordinates
    path = tmp_path / "site.stl"
    cells = [("triangle", roof.cells["triangle"])]
    meshio.write(path, meshio.Mesh(site.astype(np.float32), cells), binary=True)
    mesh_file = read_mesh_file(path)
    assert mesh_file.resolution == pytest.approx(0.5)
    warning = mesh_file.precision_warning()
    assert "single precision" in warning and "only known to 0.5" in warning
    near = tmp_path / "near.stl"
    meshio.write(
        near, meshio.Mesh(roof.points.astype(np.float32), [("triangle", roof.cells["triangle"])])
    )
    assert read_mesh_file(near).precision_warning() is None


def test_a_bow_tie_node_is_split_by_the_repair(tmp_path):
    # two squares of two triangles each that touch at one node
    points = np.array(
        [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 1, 0.1], [2, 2, 0.1], [1, 2, 0.1]], float
    )
    triangles = np.array([[0, 1, 2], [0, 2, 3], [2, 4, 5], [2, 5, 6]])
    path = tmp_path / "bowtie.obj"
    path.write_text(
        "".join(f"v {x} {y} {z}\n" for x, y, z in points)
        + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in triangles)
    )
    with pytest.raises(vares.MeshError, match="2 separate pieces"):
        read_mesh_file(path, repair=False).surface()
    mesh_file = read_mesh_file(path)
    assert mesh_file.repair.split_nodes == 1 and len(mesh_file.points) == 8
    pieces = mesh_file.pieces()  # now two pieces, each a surface
    assert [p.num_cells for p, _ in pieces] == [2, 2]


def _dxf_roof(path, mesh, units: int) -> None:
    """The roof as CAD programs export a mesh to DXF: half its triangles as 3D faces (a triangle
    repeats its third corner), a quarter as a polyface mesh, the rest as a MESH entity."""
    import ezdxf

    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = units
    space = doc.modelspace()
    triangles = mesh.cells["triangle"]
    half, three_quarters = len(triangles) // 2, 3 * len(triangles) // 4
    for a, b, c in triangles[:half]:
        space.add_3dface([mesh.points[a], mesh.points[b], mesh.points[c], mesh.points[c]])
    polyface = space.add_polyface()
    polyface.append_faces(
        [[mesh.points[i] for i in cell] for cell in triangles[half:three_quarters]]
    )
    polyface.optimize()
    with space.add_mesh().edit_data() as data:
        data.vertices = [tuple(p) for p in mesh.points]
        data.faces = [list(cell) for cell in triangles[three_quarters:]]
    doc.saveas(path)


def test_dxf_meshes_in_the_units_the_drawing_declares(tmp_path):
    roof = vares.examples.cad_roof_mm(n=12)
    path = tmp_path / "roof.dxf"
    _dxf_roof(path, roof, units=4)  # millimetres
    mesh_file = read_mesh_file(path)
    assert mesh_file.units == "mm"
    surface = mesh_file.surface()
    assert surface.num_points == roof.num_points and surface.num_cells == roof.num_cells
    assert surface.area == pytest.approx(roof.area, rel=1e-12)
    assert mesh_file.repair.welded_nodes > 0  # the 3D faces came as a soup
    result = run("pattern", path, "-o", tmp_path / "out", "-q")
    assert result.exit_code == 0, result.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["converged"] and summary["units"]["length"] == "mm"
    assert not any("km" in w for w in summary["warnings"])
    # unitless: the size warning names the fix
    _dxf_roof(tmp_path / "unitless.dxf", roof, units=0)
    assert read_mesh_file(tmp_path / "unitless.dxf").units is None
    result = run("pattern", tmp_path / "unitless.dxf", "-o", tmp_path / "guess", "-q")
    warnings = json.loads((tmp_path / "guess" / "summary.json").read_text())["warnings"]
    assert any("12 km across in m" in w and "pass --units mm" in w for w in warnings), warnings
    # a unit vares does not know, a drawing without faces, and garbage
    _dxf_roof(tmp_path / "miles.dxf", roof, units=3)
    result = run("pattern", tmp_path / "miles.dxf", "-o", tmp_path / "miles")
    assert result.exit_code == 2 and "declares its units as Miles" in error_line(result)
    import ezdxf

    lines = ezdxf.new()
    lines.modelspace().add_lwpolyline([(0, 0), (1, 0), (1, 1)])
    lines.saveas(tmp_path / "outline.dxf")
    result = run("pattern", tmp_path / "outline.dxf", "-o", tmp_path / "outline")
    assert result.exit_code == 2 and "holds no 3D faces" in error_line(result)
    (tmp_path / "garbage.dxf").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 8)
    result = run("pattern", tmp_path / "garbage.dxf", "-o", tmp_path / "garbage")
    assert result.exit_code == 2 and "cannot read" in error_line(result)
    assert not (tmp_path / "outline").exists() and not (tmp_path / "garbage").exists()


def _with_field_data(path, arrays: str) -> None:
    """Put a ``FieldData`` block (as VTK writes string arrays) into a VTU file."""
    text = path.read_text()
    path.write_text(
        text.replace("<UnstructuredGrid>", f"<UnstructuredGrid><FieldData>{arrays}</FieldData>", 1)
    )


def test_vtu_files_state_their_units_and_string_fields_are_read(tmp_path):
    import base64
    import struct

    roof = vares.examples.cad_roof_mm(n=12)
    _dxf_roof(tmp_path / "roof.dxf", roof, units=4)
    result = run("pattern", tmp_path / "roof.dxf", "-o", tmp_path / "out", "-q")
    assert result.exit_code == 0, result.stderr
    surface = read_mesh_file(tmp_path / "out" / "surface.vtu")
    assert surface.units == "mm" and surface.surface().num_cells == roof.num_cells
    assert read_mesh_file(tmp_path / "out" / "pattern.vtu").units == "mm"
    stated = meshio.read(tmp_path / "out" / "surface.vtu").field_data  # any reader sees it
    assert stated["metres_per_unit"].tolist() == [0.001]
    again = run("pattern", tmp_path / "out" / "surface.vtu", "-o", tmp_path / "again", "-q")
    assert again.exit_code == 0, again.stderr
    summary = json.loads((tmp_path / "again" / "summary.json").read_text())
    assert summary["units"]["length"] == "mm"
    # string arrays as VTK writes them (ASCII and base64), which meshio alone refuses
    plain = tmp_path / "plain.vtu"
    cells = [("triangle", roof.cells["triangle"])]
    meshio.write(plain, meshio.Mesh(roof.points, cells), compression=None)
    with pytest.raises((meshio.ReadError, SystemExit)):  # meshio even exits
        broken = tmp_path / "broken.vtu"
        broken.write_bytes(plain.read_bytes())
        _with_field_data(broken, '<Array type="String" Name="author" format="ascii">97 0</Array>')
        meshio.read(broken)
    word = b"mm\0"
    packed = base64.b64encode(struct.pack("<I", len(word)) + word).decode()  # UInt32 header
    for name, array in (
        ("ascii", '<Array type="String" Name="Units" format="ascii">109 109 0</Array>'),
        ("base64", f'<Array type="String" Name="units" format="binary">{packed}</Array>'),
    ):
        path = tmp_path / f"{name}.vtu"
        path.write_bytes(plain.read_bytes())
        note = '<Array type="String" Name="author" format="ascii">97 0</Array>'
        _with_field_data(path, array + note)
        mesh_file = read_mesh_file(path)
        assert mesh_file.units == "mm", name
        assert mesh_file.surface().num_points == roof.num_points
    path = tmp_path / "furlong.vtu"
    path.write_bytes(plain.read_bytes())
    _with_field_data(path, '<Array type="String" Name="units" format="ascii">102 117 114 0</Array>')
    result = run("pattern", path, "-o", tmp_path / "furlong")
    assert result.exit_code == 2 and "declares its units as 'fur'" in error_line(result)
    factor = '<DataArray type="Float64" Name="metres_per_unit" format="ascii">201.168</DataArray>'
    path.write_bytes(plain.read_bytes())
    _with_field_data(path, factor)
    result = run("pattern", path, "-o", tmp_path / "furlong")
    assert result.exit_code == 2 and "states 201.168 metres per unit" in error_line(result)


def test_dxf_layers_name_the_panels_of_a_structure(tmp_path):
    """Three strips of a roof on three layers of one DXF, joined at their seams (one piece):
    ``--panel-field layer`` makes them the panels, named by their layers."""
    import ezdxf

    roof = hypar(size=6.0, n=12)
    cells = roof.cells["triangle"]
    strip = np.minimum(((roof.points[cells].mean(axis=1)[:, 0] + 3.0) // 2.0).astype(int), 2)
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 6
    for index, layer in enumerate(("EAST", "MIDDLE", "WEST")):
        for a, b, c in cells[strip == index]:
            doc.modelspace().add_3dface(
                [roof.points[a], roof.points[b], roof.points[c], roof.points[c]],
                dxfattribs={"layer": layer},
            )
    path = tmp_path / "strips.dxf"
    doc.saveas(path)
    mesh_file = read_mesh_file(path)
    assert mesh_file.cell_names["layer"] == {0: "EAST", 1: "MIDDLE", 2: "WEST"}
    assert np.bincount(mesh_file.cell_data["layer"]).tolist() == np.bincount(strip).tolist()
    result = run("panels", path, "--panel-field", "layer", "-o", tmp_path / "out", "-q")
    assert result.exit_code == 0, result.stderr
    structure = json.loads((tmp_path / "out" / "structure.json").read_text())
    assert structure["converged"]
    assert sorted(p["name"] for p in structure["panels"]) == ["EAST", "MIDDLE", "WEST"]
    assert all((tmp_path / "out" / name / "pattern.dxf").is_file() for name in ("EAST", "WEST"))


def test_a_non_convex_polygon_is_cut_into_triangles_that_tile_it():
    """An L-shaped face with thin arms (the shape whose best-fit normal came out reversed
    without the closing edge's term): every triangle faces the polygon's way and their areas
    add up to the polygon's, so none overlaps another."""
    from vares.geometry.repair import triangulate_polygon

    outline = np.array([[0, 0], [2, 0], [2, 0.1], [0.1, 0.1], [0.1, 2], [0, 2]], dtype=float)
    tilt = np.radians(20.0)
    points = np.column_stack(
        [outline[:, 0], outline[:, 1] * np.cos(tilt), outline[:, 1] * np.sin(tilt)]
    )
    triangles = triangulate_polygon(points, np.arange(len(points)))
    assert triangles.shape == (4, 3)
    p = points[triangles]
    normals = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    facing = normals @ np.array([0.0, -np.sin(tilt), np.cos(tilt)])
    assert np.all(facing > 0)
    assert 0.5 * np.linalg.norm(normals, axis=1).sum() == pytest.approx(2 * 0.1 + 1.9 * 0.1)


def test_zero_area_cells_are_dropped_only_on_the_boundary_of_the_whole_mesh():
    """On a 3 × 2 grid of quads: a zero-area triangle on the boundary is dropped; one inside,
    every edge shared with a quad of the other block, stays (the validation names it); a quad
    with a straight corner but an area is kept whatever corner is straight."""
    x, y = np.meshgrid(np.arange(4.0), np.arange(3.0))
    grid = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    quads = [[0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [4, 5, 9, 8], [6, 7, 11, 10]]
    points = np.vstack([grid, [[1.5, 0.0, 0.0]]])  # node 12 on the boundary edge 1–2
    cells = {"quad": np.array([*quads, [5, 6, 10, 9]]), "triangle": np.array([[2, 12, 1]])}
    fixed = repair(points, cells)
    assert fixed.report.flat_boundary_cells == 1 and "triangle" not in fixed.cells
    # the edge 5–6 split at node 12 above; the flat triangle 6–12–5 between the two rows
    points = np.vstack([grid, [[1.5, 1.0, 0.0], [1.5, 2.0, 0.0]]])
    cells = {
        "quad": np.array([*quads, [5, 12, 13, 9], [12, 6, 10, 13]]),
        "triangle": np.array([[6, 12, 5]]),
    }
    fixed = repair(points, cells)
    assert fixed.report.flat_boundary_cells == 0 and len(fixed.cells["triangle"]) == 1
    with pytest.raises(vares.MeshError, match="triangle cells 0"):
        vares.SurfaceMesh(fixed.points, fixed.cells)
    # a quad of area 0.5 whose corner 0 is straight (its neighbours in line), on the boundary
    points = np.vstack([grid, [[4.0, 0.0, 0.0], [3.5, 0.5, 0.0]]])
    cells = {"quad": np.array([*quads, [5, 6, 10, 9], [13, 7, 3, 12]])}
    fixed = repair(points, cells)
    assert fixed.report.flat_boundary_cells == 0 and len(fixed.cells["quad"]) == 7


def test_a_soup_knows_which_file_face_each_of_its_cells_is(tmp_path):
    """Faces of mixed sizes are sorted into triangles, quads and polygons: ``order`` carries a
    per-face value of the file (a DXF face's layer) to the right cell."""
    from vares.io.formats import _soup

    points = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 1.5, 0]]
    faces = [[0, 1, 2, 3], [0, 1, 2], [0, 1, 2, 4, 3], [0, 2, 3], [0, 1]]  # the last: a line
    soup = _soup(points, faces, tmp_path / "mixed")
    np.testing.assert_array_equal(soup.order, [1, 3, 0, 2])
    np.testing.assert_array_equal(soup.cells["triangle"], [faces[1], faces[3]])
    np.testing.assert_array_equal(soup.cells["quad"], [faces[0]])


@pytest.mark.parametrize(
    ("face", "message"),
    [
        ("f 0 3 4", r"line 6: vertex index 0 .*OBJ counts vertices from 1"),
        ("f 1/1 3/1 0/1", r"line 6: vertex index 0 .*OBJ counts vertices from 1"),
        ("f -10 3 4", r"line 6: vertex index -10 counts back past the first vertex \(4 read"),
    ],
)
def test_an_obj_face_index_out_of_range_is_named_as_written(tmp_path, face, message):
    # index 0 was taken as the vertex after the last ("vertex 5 of 4"), -10 of 4 as "vertex -6"
    path = tmp_path / "zero.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\n" + face + "\n")
    with pytest.raises(MeshError, match=message):
        read_mesh_file(path)


def _unwelded_panels_3dm(path, units="m"):
    """Two hypar panels in a Rhino file, each stored with a vertex per face along x = 0 (as
    Rhino often keeps seams), so that only welding makes each one piece."""
    import rhino3dm

    model = rhino3dm.File3dm()
    model.Settings.ModelUnitSystem = rhino3dm.UnitSystem.Meters
    for name, shift in (("left", -5.0), ("right", 5.0)):
        mesh = hypar(size=4.0, rise=0.05, n=4)
        points, cells = [tuple(p) for p in mesh.points], mesh.cells["triangle"].copy()
        right = mesh.points[cells].mean(axis=1)[:, 0] > 0
        copies = {}
        for row in np.flatnonzero(right):
            for k, node in enumerate(cells[row]):
                if abs(mesh.points[node, 0]) < 1e-12:
                    copies.setdefault(node, len(points) + len(copies))
                    cells[row, k] = copies[node]
        points += [tuple(mesh.points[node]) for node in copies]
        rhino_mesh = rhino3dm.Mesh()
        for x, y, z in points:
            rhino_mesh.Vertices.Add(float(x) + shift, float(y), float(z))
        for a, b, c in cells:
            rhino_mesh.Faces.AddFace(int(a), int(b), int(c))
        attributes = rhino3dm.ObjectAttributes()
        attributes.Name = name
        model.Objects.AddMesh(rhino_mesh, attributes)
    model.Write(str(path), 7)
    return path


def _structure_job(tmp_path, repair_meshes: bool):
    from vares.app.job import load_job

    job_file = tmp_path / f"job-{repair_meshes}.toml"
    job_file.write_text(
        f'[input]\nmeshes = ["panels.3dm"]\nrepair = {str(repair_meshes).lower()}\n'
        '[material]\nfabric = "pes-pvc-type-2"\n[structure]\n[output]\ndirectory = "out"\n'
    )
    return load_job(job_file)


def test_a_rhino_structure_is_read_with_one_parse_and_repaired_as_asked(tmp_path, monkeypatch):
    import rhino3dm

    from vares.app.inputs import load_input

    _unwelded_panels_3dm(tmp_path / "panels.3dm")
    parses = []
    read = rhino3dm.File3dm.Read

    def counted(path):
        parses.append(path)
        return read(path)

    monkeypatch.setattr(rhino3dm.File3dm, "Read", counted)
    loaded = load_input(_structure_job(tmp_path, repair_meshes=True))
    assert len(parses) == 1  # meshes and units from the same parse
    assert [p.name for p in loaded.panels] == ["left", "right"]
    assert loaded.units == "m"
    assert all(p.mesh.num_points == 25 for p in loaded.panels)  # 5 welded nodes each
    assert sorted(loaded.repairs) == ["panels.3dm, object 'left'", "panels.3dm, object 'right'"]
    assert all(r["welded_nodes"] == 5 for r in loaded.repairs.values())
    assert any("repaired panels.3dm, object 'left'" in w for w in loaded.warnings)
    # --no-repair (repair = false): taken as stored, each panel is two pieces along its seam
    with pytest.raises(MeshError, match=r"panels.3dm: object 'left': .*2 separate pieces"):
        load_input(_structure_job(tmp_path, repair_meshes=False))
    assert len(parses) == 2
    from vares.io.rhino import read_3dm_stored

    stored, units = read_3dm_stored(tmp_path / "panels.3dm")  # as stored, with the unit
    assert len(parses) == 3 and units == "m"
    assert [len(m.points) for m in stored] == [30, 30]  # the seams' copies still there


def test_a_single_rhino_surface_is_read_with_one_parse(tmp_path, monkeypatch):
    """`vares pattern roof.3dm`: the mesh and the file's unit from one parse of the file."""
    import rhino3dm

    write_3dm(
        tmp_path / "one.3dm", [NamedMesh("roof", "roof", hypar(size=4.0, rise=0.05, n=4))], "mm"
    )
    parses = []
    read = rhino3dm.File3dm.Read

    def counted(path):
        parses.append(path)
        return read(path)

    monkeypatch.setattr(rhino3dm.File3dm, "Read", counted)
    raw = read_mesh_file(tmp_path / "one.3dm")
    assert len(parses) == 1
    assert raw.units == "mm" and raw.surface().num_cells == 32
