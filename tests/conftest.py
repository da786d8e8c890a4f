import numpy as np
import pytest

from vares import SurfaceMesh
from vares.materials import (
    Fibres,
    IncompressibleNeoHooke,
    NeoHooke,
    NonCrimpFabric,
    OrthotropicStVenantKirchhoff,
    StVenantKirchhoff,
)


def rotation(seed: int = 0) -> np.ndarray:
    """A random proper rotation of 3D space."""
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q *= np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] *= -1
    return q


def align_2d(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``b`` moved by the proper 2D rigid motion that best fits it onto ``a`` (Kabsch)."""
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    u, _, vt = np.linalg.svd((b - cb).T @ (a - ca))
    d = np.sign(np.linalg.det(u @ vt))
    r = u @ np.diag([1.0, d]) @ vt
    return (b - cb) @ r + ca


@pytest.fixture
def mixed_mesh() -> SurfaceMesh:
    """A small curved mesh with both triangles and quads."""
    x, y = np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 1, 3), indexing="xy")
    points = np.column_stack([x.ravel(), y.ravel(), 0.3 * x.ravel() ** 2 - 0.2 * y.ravel() ** 2])
    quads = np.array([[0, 1, 5, 4], [1, 2, 6, 5], [4, 5, 9, 8], [5, 6, 10, 9]])
    triangles = np.array([[2, 3, 7], [2, 7, 6], [6, 7, 11], [6, 11, 10]])
    return SurfaceMesh(points, {"quad": quads, "triangle": triangles})


#: One law of each kind, with the parameters the derivative checks use.
LAWS = [
    StVenantKirchhoff(E=10.0, nu=0.3),
    NeoHooke(E=10.0, nu=0.2),
    IncompressibleNeoHooke(mu=3.0),
    OrthotropicStVenantKirchhoff(E1=12.0, E2=8.0, G12=1.5, nu12=0.3),
    NonCrimpFabric(A=[-2.0, 1.0, 1.0], B=[-1.5, 1.5], C=[0.2, 0.1]),
]
FIBRES = Fibres.from_angles(35.0)


def run(*args):
    """``vares ARGS…`` in this process (typer's runner): its exit code, stdout and stderr."""
    from typer.testing import CliRunner

    from vares.app.cli import app

    return CliRunner().invoke(app, [str(a) for a in args], env={"COLUMNS": "200"})


def error_line(result) -> str:
    """The one ``vares: error:`` line a failed command printed (asserted to be one)."""
    lines = [line for line in result.stderr.splitlines() if line.startswith("vares: error:")]
    assert len(lines) == 1, result.stderr
    return lines[0]
