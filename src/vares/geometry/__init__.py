"""The fixed 3D shape: surface meshes, reference elements, flattenings (initial guesses), the
erected warp direction, and the shipped example surfaces."""

from . import examples
from .elements import ELEMENTS, ReferenceElement
from .flatten import ProjectionPlane, lscm, projection_distortion, projection_plane, signed_area
from .mesh import MeshError, SurfaceMesh
from .orientation import warp_deviation

__all__ = [
    "ELEMENTS",
    "MeshError",
    "ProjectionPlane",
    "ReferenceElement",
    "SurfaceMesh",
    "examples",
    "lscm",
    "projection_distortion",
    "projection_plane",
    "signed_area",
    "warp_deviation",
]
