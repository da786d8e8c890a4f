"""A non-crimp fabric that locks (vares.materials.shear_locking): the added term's stiffness at
the locking angle is the one asked for, small below it and steep beyond."""

from __future__ import annotations

import numpy as np
import pytest

from vares.materials import NonCrimpFabric
from vares.materials.shear_locking import locking_coefficient, locking_fabric, shear_stiffness

A = [-250.0, 250.0]


def energy(law: NonCrimpFabric, shear_angle: np.ndarray) -> np.ndarray:
    """The law's energy with inextensible yarns sheared by ``shear_angle`` (degrees):
    ``I4 = I6 = 1``, ``I8 = cos(90° − γ) = sin γ``."""
    g = np.radians(np.atleast_1d(shear_angle))
    inv = np.stack([np.ones_like(g), np.ones_like(g), np.sin(g)], axis=-1)
    return law.psi_invariants(inv)


def second_derivative(law: NonCrimpFabric, shear_angle: float, h: float = 1e-3) -> float:
    """``d²Ψ/dγ²`` (per rad²) of the law's own energy by central differences."""
    step = np.degrees(h)
    values = energy(law, np.array([shear_angle - step, shear_angle, shear_angle + step]))
    return float((values[0] - 2.0 * values[1] + values[2]) / h**2)


def test_the_added_term_has_the_stiffness_asked_for_at_the_locking_angle():
    law = locking_fabric(A, A, [0.5], 50.0, 100.0)
    plain = NonCrimpFabric(A, A, [0.5])
    assert law.C.size == 12 and law.C[:11].tolist() == [0.5] + [0.0] * 10
    # the law's own energy, differentiated twice: the plain part plus 100 at 50°
    added = second_derivative(law, 50.0) - second_derivative(plain, 50.0)
    assert added == pytest.approx(100.0, rel=1e-4)
    assert shear_stiffness(law, 50.0) == pytest.approx(second_derivative(law, 50.0), rel=1e-4)
    assert shear_stiffness(plain, 0.0) == pytest.approx(1.0)  # 2 C₁: the shear modulus
    # small well below the locking angle, steep beyond it
    extra = {g: shear_stiffness(law, g) - shear_stiffness(plain, g) for g in (30, 40, 45, 55)}
    assert extra[30] < 0.001 * 100.0 and extra[40] < 0.05 * 100.0
    assert 0.1 * 100.0 < extra[45] < 0.5 * 100.0 and extra[55] > 3.0 * 100.0
    # the small-strain moduli are the plain law's
    assert law.warp_modulus == plain.warp_modulus and energy(law, 0.0)[0] == 0.0


def test_the_term_is_added_to_a_law_that_has_one_of_that_power():
    c = locking_coefficient(50.0, 100.0, power=6)
    law = locking_fabric(A, A, [0.5, 0.0, 0.0, 0.0, 0.0, 10.0], 50.0, 100.0, power=6)
    assert law.C.tolist() == pytest.approx([0.5, 0.0, 0.0, 0.0, 0.0, 10.0 + c])


@pytest.mark.parametrize(
    "settings, message",
    [
        ({"locking_angle": 0.0, "stiffness": 1.0}, "locking angle"),
        ({"locking_angle": 95.0, "stiffness": 1.0}, "locking angle"),
        ({"locking_angle": 50.0, "stiffness": -1.0}, "stiffness"),
        ({"locking_angle": 50.0, "stiffness": 1.0, "power": 1}, "power"),
        ({"locking_angle": 80.0, "stiffness": 1.0, "power": 2}, "does not stiffen"),
    ],
)
def test_bad_settings_are_refused(settings, message):
    with pytest.raises(Exception, match=message):
        locking_coefficient(**settings)
