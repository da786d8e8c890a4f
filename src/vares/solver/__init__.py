"""Finding the pattern: options, Newton's method and its globalisations, strategies, linear
solvers, and :func:`solve`."""

from .api import solve
from .linear import SOLVER_NAMES, LinearSolver, SingularMatrixError, available_solvers, get_solver
from .newton import Failure, NewtonContext, newton
from .options import INITIAL_GUESSES, ORIENTATIONS, STRATEGIES, SolveOptions
from .result import IterationRecord, PatternResult, StepRecord

__all__ = [
    "INITIAL_GUESSES",
    "ORIENTATIONS",
    "SOLVER_NAMES",
    "STRATEGIES",
    "Failure",
    "IterationRecord",
    "LinearSolver",
    "NewtonContext",
    "PatternResult",
    "SingularMatrixError",
    "SolveOptions",
    "StepRecord",
    "available_solvers",
    "get_solver",
    "newton",
    "solve",
]
