"""vares: cutting patterns of doubly curved membranes by the Variation of Reference Strategy.

The pattern is the stress-free reference configuration whose erection onto the fixed 3D surface
stores the least elastic energy (minus the work of the intended prestress).

>>> import vares
>>> mesh = vares.examples.cylinder160()
>>> result = vares.solve(mesh, vares.materials.NeoHooke(E=1000.0, nu=0.3))
>>> result.converged
True
"""

from . import examples, materials
from .analysis import PatternEvaluation, cell_fields, evaluate
from .initial import ProjectionPlane, projection_plane
from .materials import Fibres
from .mesh import MeshError, SurfaceMesh, read_mesh, read_mesh_data
from .problem import Problem
from .solver import IterationRecord, PatternResult, StepRecord, solve

__version__ = "0.1.0"

__all__ = [
    "Fibres",
    "IterationRecord",
    "MeshError",
    "PatternEvaluation",
    "PatternResult",
    "Problem",
    "ProjectionPlane",
    "StepRecord",
    "SurfaceMesh",
    "cell_fields",
    "evaluate",
    "examples",
    "materials",
    "projection_plane",
    "read_mesh",
    "read_mesh_data",
    "solve",
]
