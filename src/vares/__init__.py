"""vares: cutting patterns of doubly curved membranes by the Variation of Reference Strategy.

The pattern is the stress-free reference configuration whose erection onto the fixed 3D surface
stores the least elastic energy (minus the work of the intended prestress).

>>> import vares
>>> mesh = vares.examples.cylinder160()
>>> result = vares.solve(mesh, vares.materials.NeoHooke(E=1000.0, nu=0.3))
>>> result.converged
True

The package is layered along the data path (docs/architecture.md): ``materials`` and
``geometry`` → ``mechanics`` → ``solver`` → ``analysis`` → ``structures`` → ``io`` → ``app``.
"""

from typing import TYPE_CHECKING

from ._lazy import lazy_exports
from ._version import __version__

if TYPE_CHECKING:
    from . import materials
    from .analysis import (
        ErectionOptions,
        ErectionResult,
        OptimisedPatterns,
        PatternEvaluation,
        cell_fields,
        compensation_report,
        erect,
        evaluate,
        optimise_for_erection,
    )
    from .geometry import MeshError, ProjectionPlane, SurfaceMesh, examples, projection_plane
    from .io import read_mesh, read_mesh_data
    from .materials import Fibres
    from .mechanics import Problem
    from .options import OptionsError
    from .solver import IterationRecord, PatternResult, SolveOptions, StepRecord, solve
    from .structures import (
        CutOptions,
        CutResult,
        Panel,
        StructureOptions,
        StructureResult,
        cut,
        find_seams,
        solve_structure,
        split_panels,
    )

__getattr__, __dir__, _names = lazy_exports(__name__, __file__)
__all__ = ["__version__", *_names]
