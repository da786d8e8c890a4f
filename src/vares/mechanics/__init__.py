"""The energy of erecting a pattern: prestress, element kernels, the problem, assembly, rigid
modes, and the per-cell response (stresses, stretches) of any pattern; and the forward problem
of the erection (the patterns fixed, the 3D positions unknown) with its tension-field energy."""

from typing import TYPE_CHECKING

from .._lazy import lazy_exports

if TYPE_CHECKING:
    from .assembly import Assembler, Connectivity
    from .erection import ErectionProblem
    from .fields import FIELD_DESCRIPTIONS, KEY_FIELDS, cell_fields
    from .kernels import BlockResult, block_energy, projected_hessian
    from .prestress import PrestressWarning, prestress_components, prestress_tensor
    from .problem import Evaluation, Problem
    from .rigid import rigid_modes
    from .wrinkling import relaxed_response

__getattr__, __dir__, __all__ = lazy_exports(__name__, __file__)
