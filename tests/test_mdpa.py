"""Kratos Multiphysics' MDPA files: the surface elements of a membrane or shell model read as the
mesh (meshio reads Kratos' own element names as 3-node lines, and the conditions as cells too)."""

from __future__ import annotations

import re

import numpy as np
import pytest
from conftest import error_line, run

from vares.geometry.mesh import MeshError
from vares.io.meshes import read_mesh

#: A 2 m × 2 m square of eight triangles as Kratos writes a membrane model: node ids from 10 with
#: a gap, a properties block with a nested table, the elements repeated as load conditions, and
#: sub-model parts listing node and element ids.
MEMBRANE = """Begin ModelPartData
//  VARIABLE_NAME value
End ModelPartData

Begin Properties 1
    DENSITY 1.0
    Begin Table 1 TIME PRESSURE
        0.0 0.0
        1.0 1.0
    End Table
End Properties

Begin Nodes
   10  0.0 0.0 0.0
   11  1.0 0.0 0.1
   12  2.0 0.0 0.0
   13  0.0 1.0 0.1
   14  1.0 1.0 0.3
   15  2.0 1.0 0.1
   16  0.0 2.0 0.0
   17  1.0 2.0 0.1
   20  2.0 2.0 0.0
End Nodes

Begin Elements MembraneElement3D3N// GUI group identifier: Membrane
    1 1 10 11 14
    2 1 10 14 13
    3 1 11 12 15
    4 1 11 15 14
    5 1 13 14 17
    6 1 13 17 16
    7 1 14 15 20
    8 1 14 20 17
End Elements

Begin Conditions SurfaceLoadCondition3D3N// GUI group identifier: Load
    1 0 10 11 14
    2 0 10 14 13
    3 0 11 12 15
    4 0 11 15 14
    5 0 13 14 17
    6 0 13 17 16
    7 0 14 15 20
    8 0 14 20 17
End Conditions

Begin SubModelPart Parts_Membrane // Group Membrane
    Begin SubModelPartNodes
        10
        11
    End SubModelPartNodes
    Begin SubModelPartElements
        1
    End SubModelPartElements
End SubModelPart
"""


def test_a_kratos_membrane_model_reads_as_its_elements(tmp_path):
    """The eight membrane triangles, once (not again as the load conditions), on the file's
    nodes by their ids; meshio alone reads the same file as 3-node lines."""
    import meshio

    path = tmp_path / "membrane.mdpa"
    path.write_text(MEMBRANE)
    mesh = read_mesh(path)
    assert mesh.num_points == 9 and mesh.num_cells == 8
    assert set(mesh.cells) == {"triangle"}
    np.testing.assert_allclose(mesh.points.min(axis=0), [0.0, 0.0, 0.0])
    np.testing.assert_allclose(mesh.points.max(axis=0), [2.0, 2.0, 0.3])
    corner = np.flatnonzero(np.all(mesh.points == [2.0, 2.0, 0.0], axis=1))
    assert len(corner) == 1  # node 20, after the gap in the ids
    assert mesh.area > 4.0 and mesh.area < 4.2
    assert {b.type for b in meshio.read(path).cells} == {"line3"}
    # meshio as a second reader, on the same model with node ids 1 … 9 (it takes an id less one
    # for the index, so ids with a gap are out of its range): the same corners for every cell
    renumbered = re.sub(
        r"\b(1[0-7]|20)\b",
        lambda m: str({**{str(i): str(i - 9) for i in range(10, 18)}, "20": "9"}[m.group(0)]),
        MEMBRANE.split("Begin Conditions")[0],
    )
    plain = path.with_name("plain.mdpa")
    plain.write_text(renumbered)
    theirs = meshio.read(plain)
    ours = read_mesh(plain)
    np.testing.assert_array_equal(
        ours.points[ours.cells["triangle"]], theirs.points[theirs.cells[0].data]
    )
    tabs = path.with_name("tabs.mdpa")  # Kratos' GiD writes tabs between an element's numbers
    tabs.write_text(MEMBRANE.replace("    1 1 10 11 14\n", "1\t1\t10\t11\t14\n"))
    assert read_mesh(tabs).num_cells == 8


def test_kratos_shell_quads_are_quads_and_solids_are_refused(tmp_path):
    quads = MEMBRANE.split("Begin Elements")[0] + (
        "Begin Elements ShellThinElementCorotational3D4N\n"
        "    1 1 10 11 14 13\n    2 1 11 12 15 14\n    3 1 13 14 17 16\n    4 1 14 15 20 17\n"
        "End Elements\n"
    )
    path = tmp_path / "shell.mdpa"
    path.write_text(quads)
    mesh = read_mesh(path)
    assert set(mesh.cells) == {"quad"} and mesh.num_cells == 4
    solid = path.with_name("solid.mdpa")
    solid.write_text(
        quads.replace("ShellThinElementCorotational3D4N", "TotalLagrangianElement3D4N")
    )
    with pytest.raises(MeshError, match="TotalLagrangianElement3D4N is a solid element"):
        read_mesh(solid)
    quadratic = path.with_name("quadratic.mdpa")
    quadratic.write_text(
        MEMBRANE.replace("MembraneElement3D3N", "MembraneElement3D6N").replace(
            "    1 1 10 11 14\n", "    1 1 10 11 14 13 12 15\n"
        )
    )
    with pytest.raises(MeshError, match="MembraneElement3D6N is a quadratic element"):
        read_mesh(quadratic)
    broken = path.with_name("broken.mdpa")
    broken.write_text(MEMBRANE.replace("    8 1 14 20 17\n", "    8 1 14 21 17\n"))
    with pytest.raises(MeshError, match="refer to node 21"):
        read_mesh(broken)
    empty = path.with_name("empty.mdpa")
    empty.write_text(MEMBRANE.split("Begin Elements")[0])
    result = run("pattern", empty, "-o", tmp_path / "out")
    assert result.exit_code == 2
    assert "holds no membrane or shell elements" in error_line(result)
