"""The tension-field (relaxed) energy: derivatives, global minimality, states, anisotropy."""

import numpy as np
import pytest
from conftest import FIBRES, LAWS
from scipy.optimize import minimize

from vares.materials import (
    NeoHooke,
    OrthotropicStVenantKirchhoff,
)
from vares.mechanics.wrinkling import SLACK, TAUT, WRINKLED, relaxed_response


def stretched(l1: float, l2: float, angle: float) -> np.ndarray:
    """``C`` with principal stretches ``l1``, ``l2``, the first at ``angle`` radians."""
    c, s = np.cos(angle), np.sin(angle)
    rotation = np.array([[c, -s], [s, c]])
    return rotation @ np.diag([l1**2, l2**2]) @ rotation.T


STATES = {
    "taut": (stretched(1.1, 1.05, 0.3), TAUT),
    "wrinkled": (stretched(1.1, 0.9, 0.3), WRINKLED),
    "barely wrinkled": (stretched(1.02, 0.97, 1.2), WRINKLED),
    "slack": (stretched(0.95, 0.9, 0.3), SLACK),
}


@pytest.mark.parametrize("law", LAWS, ids=lambda m: type(m).__name__)
@pytest.mark.parametrize("case", list(STATES))
def test_relaxed_stress_and_tangent_by_finite_differences(law, case):
    """S_rel = 2 ∂Ψ_rel/∂C and ℂ_rel = 2 ∂S_rel/∂C by central differences, in every state."""
    C, expected_state = STATES[case]
    fibres = FIBRES if law.needs_fibres else None
    exact = relaxed_response(law, C[None], fibres)
    assert exact.state[0] == expected_state
    h = 1e-6
    stress = np.zeros((2, 2))
    tangent = np.zeros((2, 2, 2, 2))
    for i in range(2):
        for j in range(2):
            dC = np.zeros((2, 2))
            dC[i, j] += 0.5 * h
            dC[j, i] += 0.5 * h
            plus = relaxed_response(law, (C + dC)[None], fibres)
            minus = relaxed_response(law, (C - dC)[None], fibres)
            stress[i, j] = (plus.psi[0] - minus.psi[0]) / h
            tangent[:, :, i, j] = (plus.stress[0] - minus.stress[0]) / h
    scale = law.stiffness_scale
    np.testing.assert_allclose(exact.stress[0], stress, atol=1e-8 * scale)
    np.testing.assert_allclose(exact.tangent[0], tangent, atol=1e-8 * scale)
    # the relaxed stress carries no compression: positive semi-definite
    assert np.linalg.eigvalsh(exact.stress[0]).min() >= -1e-12 * scale


@pytest.mark.parametrize("law", LAWS, ids=lambda m: type(m).__name__)
def test_relaxed_energy_is_the_least_energy_of_any_longer_state(law):
    """Ψ_rel(C) = min over D ⪰ 0 of Ψ(C + D), found here by a general-purpose minimiser over
    D = L Lᵀ (L lower triangular), from several starts."""
    fibres = FIBRES if law.needs_fibres else None
    rng = np.random.default_rng(3)
    for _ in range(4):
        C = stretched(rng.uniform(1.0, 1.15), rng.uniform(0.85, 1.0), rng.uniform(0, np.pi))
        relaxed = relaxed_response(law, C[None], fibres, tangent=False).psi[0]

        def energy(p, C=C):
            L = np.array([[p[0], 0.0], [p[1], p[2]]])
            return float(law.energy_density(C + L @ L.T, fibres))

        best = min(
            minimize(
                energy, start, method="Nelder-Mead", options={"xatol": 1e-10, "fatol": 1e-14}
            ).fun
            for start in ([0.3, 0.0, 0.3], [0.0, 0.3, 0.0], [0.3, 0.3, 0.0])
        )
        assert relaxed <= best + 1e-10 * law.stiffness_scale
        assert relaxed >= best - 1e-7 * law.stiffness_scale
        assert relaxed <= law.energy_density(C, fibres) + 1e-15


def test_isotropic_wrinkles_follow_the_principal_stretches_orthotropic_ones_do_not():
    """Isotropic law: the wrinkling strain v vᵀ is along the smaller principal stretch and the
    stress is uniaxial along the larger (classical tension-field theory). Orthotropic fabric with
    yarns at 35° to the principal axes: the wrinkles turn away from them."""
    C = stretched(1.08, 0.92, 0.0)
    isotropic = relaxed_response(NeoHooke(E=10.0, nu=0.3), C[None])
    v = isotropic.wrinkle[0] / np.linalg.norm(isotropic.wrinkle[0])
    assert abs(abs(v[1]) - 1.0) < 1e-12
    np.testing.assert_allclose(isotropic.stress[0][[0, 1, 1], [1, 0, 1]], 0.0, atol=1e-12)
    fabric = OrthotropicStVenantKirchhoff(E1=800.0, E2=600.0, G12=20.0, nu12=0.3)
    anisotropic = relaxed_response(fabric, C[None], FIBRES)
    w = anisotropic.wrinkle[0] / np.linalg.norm(anisotropic.wrinkle[0])
    assert anisotropic.state[0] == WRINKLED
    assert np.degrees(np.arccos(abs(w[1]))) > 1.0  # not along the principal axis
    # the relaxed stress is still uniaxial (rank one) and has the wrinkle as null direction
    assert abs(np.linalg.det(anisotropic.stress[0])) < 1e-10 * 800.0**2
    np.testing.assert_allclose(anisotropic.stress[0] @ w, 0.0, atol=1e-10)


def test_taut_states_are_unchanged_and_slack_ones_carry_nothing():
    law = NeoHooke(E=10.0, nu=0.3)
    C = np.stack([stretched(1.1, 1.02, 0.4), stretched(0.97, 0.9, 0.4)])
    relaxed = relaxed_response(law, C)
    plain = law.response(C)
    np.testing.assert_array_equal(relaxed.state, [TAUT, SLACK])
    np.testing.assert_array_equal(relaxed.stress[0], plain.stress[0])
    np.testing.assert_array_equal(relaxed.tangent[0], plain.tangent[0])
    assert relaxed.psi[1] == 0.0 and not relaxed.stress[1].any() and not relaxed.tangent[1].any()
