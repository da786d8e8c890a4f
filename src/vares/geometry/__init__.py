"""The fixed 3D shape: surface meshes, reference elements, flattenings (initial guesses), the
erected warp direction, the kinematic drape of a ply, and the shipped example surfaces."""

from typing import TYPE_CHECKING

from .._lazy import lazy_exports

if TYPE_CHECKING:
    from . import examples
    from .drape import KinematicDrape, kinematic_drape
    from .drape_net import KinematicNet, kinematic_net
    from .elements import ELEMENTS, ReferenceElement
    from .flatten import ProjectionPlane, lscm, projection_distortion, projection_plane, signed_area
    from .mesh import MeshError, SurfaceMesh
    from .orientation import warp_deviation

__getattr__, __dir__, __all__ = lazy_exports(__name__, __file__)
