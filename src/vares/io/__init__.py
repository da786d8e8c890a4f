"""Files: mesh and pattern files, Rhino models, DXF for the cutter, drawings, JSON summaries.

Every file is written atomically (:func:`vares.io.files.atomic_path`); none is overwritten unless
the caller allows it. Drawings (matplotlib) and DXF (ezdxf) are imported where used.
"""

from typing import TYPE_CHECKING

from .._lazy import lazy_exports

if TYPE_CHECKING:
    from .biaxial import read_biaxial, write_biaxial
    from .files import OutputExistsError, atomic_path, check_writable, write_json
    from .meshes import read_mesh, read_mesh_data, read_pattern, write_surface
    from .summary import summary

__getattr__, __dir__, __all__ = lazy_exports(__name__, __file__)
