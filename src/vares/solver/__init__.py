"""Finding the pattern: options, Newton's method and its globalisations, strategies, linear
solvers, and :func:`solve`."""

from typing import TYPE_CHECKING

from .._lazy import lazy_exports

if TYPE_CHECKING:
    from .api import solve
    from .linear import (
        SOLVER_NAMES,
        LinearSolver,
        SingularMatrixError,
        available_solvers,
        get_solver,
    )
    from .newton import Failure, NewtonContext, newton
    from .options import INITIAL_GUESSES, ORIENTATIONS, STRATEGIES, SolveOptions
    from .result import IterationRecord, PatternResult, StepRecord

__getattr__, __dir__, __all__ = lazy_exports(__name__, __file__)
