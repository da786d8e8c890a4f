import numpy as np
import pytest

from vares.materials import (
    Fibres,
    IncompressibleNeoHooke,
    MaterialError,
    NeoHooke,
    NonCrimpFabric,
    OrthotropicStVenantKirchhoff,
    StVenantKirchhoff,
    make_material,
)
from vares.materials.base import INVARIANTS, Hyperelastic

LAWS = [StVenantKirchhoff(E=7.0, nu=0.3), NeoHooke(E=7.0, nu=0.3), IncompressibleNeoHooke(mu=2.0)]
FABRICS = [
    OrthotropicStVenantKirchhoff(E1=800.0, E2=640.0, G12=40.0, nu12=0.4),
    NonCrimpFabric(A=[-3.0, 1.0, 2.0], B=[-2.0, 2.0], C=[0.5, 0.2, 0.1]),
]
FIBRES = Fibres.from_angles(25.0)


def random_c(rng, count=5):
    f = np.eye(2) + 0.2 * rng.normal(size=(count, 2, 2))
    return np.einsum("nki,nkj->nij", f, f)


def sym_unit(a, b):
    e = np.zeros((2, 2))
    e[a, b] += 0.5
    e[b, a] += 0.5
    return e


@pytest.mark.parametrize("law", LAWS + FABRICS, ids=lambda m: type(m).__name__)
def test_stress_and_tangent_are_derivatives_of_the_energy(law):
    """S = 2∂Ψ/∂C and ℂ = 4∂²Ψ/∂C∂C by complex step in symmetric directions."""
    rng = np.random.default_rng(1)
    C = random_c(rng)
    fibres = FIBRES if law.needs_fibres else None
    response = law.response(C, fibres)
    h = 1e-30
    for a, b in [(0, 0), (1, 1), (0, 1)]:
        direction = sym_unit(a, b)
        perturbed = law.response(C + 1j * h * direction, fibres)
        dpsi = perturbed.psi.imag / h
        np.testing.assert_allclose(
            dpsi, 0.5 * np.einsum("nab,ab->n", response.stress, direction), rtol=1e-12
        )
        dS = perturbed.stress.imag / h
        np.testing.assert_allclose(
            dS,
            0.5 * np.einsum("nabcd,cd->nab", response.tangent, direction),
            rtol=1e-12,
            atol=1e-12,
        )


@pytest.mark.parametrize("law", LAWS + FABRICS, ids=lambda m: type(m).__name__)
def test_tangent_has_major_and_minor_symmetry(law):
    fibres = FIBRES if law.needs_fibres else None
    cc = law.response(random_c(np.random.default_rng(2)), fibres).tangent
    np.testing.assert_allclose(cc, cc.transpose(0, 2, 1, 3, 4), atol=1e-12)
    np.testing.assert_allclose(cc, cc.transpose(0, 1, 2, 4, 3), atol=1e-12)
    np.testing.assert_allclose(cc, cc.transpose(0, 3, 4, 1, 2), atol=1e-12)


@pytest.mark.parametrize("law", LAWS, ids=lambda m: type(m).__name__)
def test_reference_state_is_stress_free_with_plane_stress_hooke_stiffness(law):
    E = law.stiffness_scale
    nu = getattr(law, "nu", 0.5)  # incompressible: small-strain nu = 1/2
    response = law.response(np.eye(2)[None])
    assert abs(response.psi[0]) < 1e-14
    np.testing.assert_allclose(response.stress[0], 0.0, atol=1e-14)
    # Plane-stress Hooke: S11 = E/(1−ν²)(E11 + ν E22), S12 = E/(1+ν) E12; ℂ maps dC = 2 dE.
    cc = response.tangent[0]
    factor = E / (1 - nu**2)
    np.testing.assert_allclose(cc[0, 0, 0, 0], factor, rtol=1e-12)
    np.testing.assert_allclose(cc[0, 0, 1, 1], factor * nu, rtol=1e-12)
    np.testing.assert_allclose(cc[0, 1, 0, 1], E / (2 * (1 + nu)), rtol=1e-12)


def test_neo_hooke_and_st_venant_kirchhoff_agree_at_small_strain():
    C = np.eye(2) + 2e-6 * np.array([[1.0, 0.3], [0.3, -0.5]])
    s_nh = NeoHooke(E=5.0, nu=0.25).response(C).stress
    s_svk = StVenantKirchhoff(E=5.0, nu=0.25).response(C).stress
    np.testing.assert_allclose(s_nh, s_svk, rtol=1e-5)


def test_st_venant_kirchhoff_closed_form():
    law = StVenantKirchhoff(E=3.0, nu=0.2)
    C = random_c(np.random.default_rng(3), 1)[0]
    E = 0.5 * (C - np.eye(2))
    lam, mu = 3.0 * 0.2 / (1 - 0.04), 3.0 / 2.4
    assert np.isclose(law.energy_density(C), lam / 2 * np.trace(E) ** 2 + mu * np.sum(E * E))
    np.testing.assert_allclose(law.response(C).stress, lam * np.trace(E) * np.eye(2) + 2 * mu * E)


@pytest.mark.parametrize(
    ("factory", "message"),
    [
        (lambda: StVenantKirchhoff(E=-1.0, nu=0.3), "E must be positive"),
        (lambda: NeoHooke(E=0.0, nu=0.3), "E must be positive"),
        (lambda: NeoHooke(E=1.0, nu=0.6), "Poisson"),
        (lambda: NeoHooke(E=1.0, nu=-1.0), "Poisson"),
        (lambda: NeoHooke(E=float("nan"), nu=0.3), "finite"),
        (lambda: IncompressibleNeoHooke(mu=-2.0), "mu must be positive"),
        (lambda: StVenantKirchhoff(E="steel", nu=0.3), "finite number"),
    ],
)
def test_parameters_are_validated(factory, message):
    with pytest.raises(MaterialError, match=message):
        factory()


class _AllInvariants(Hyperelastic):
    """A law that uses every invariant, to check their derivatives generically."""

    invariants = INVARIANTS
    weights = np.array([0.3, -0.2, 0.5, 0.7, -0.4, 0.25, 0.6])

    def psi_invariants(self, inv):
        return (
            (inv**2) @ self.weights + inv[..., 0] * inv[..., 6] + np.sin(inv[..., 1] * inv[..., 3])
        )

    def dpsi_invariants(self, inv):
        d = 2 * inv * self.weights
        d[..., 0] += inv[..., 6]
        d[..., 6] += inv[..., 0]
        c = np.cos(inv[..., 1] * inv[..., 3])
        d[..., 1] += c * inv[..., 3]
        d[..., 3] += c * inv[..., 1]
        return d

    def d2psi_invariants(self, inv):
        d2 = np.zeros((*inv.shape, inv.shape[-1]), dtype=inv.dtype)
        for k in range(inv.shape[-1]):
            d2[..., k, k] = 2 * self.weights[k]
        d2[..., 0, 6] = d2[..., 6, 0] = 1.0
        s, c = np.sin(inv[..., 1] * inv[..., 3]), np.cos(inv[..., 1] * inv[..., 3])
        d2[..., 1, 1] += -s * inv[..., 3] ** 2
        d2[..., 3, 3] += -s * inv[..., 1] ** 2
        d2[..., 1, 3] += c - s * inv[..., 1] * inv[..., 3]
        d2[..., 3, 1] = d2[..., 1, 3]
        return d2

    @property
    def stiffness_scale(self):
        return 1.0


def test_invariant_derivatives_for_every_invariant():
    """The generic S and ℂ are exact for a law that uses I1, I3, I4, I5, I6, I7 and I8."""
    law = _AllInvariants()
    fibres = Fibres.from_angles(20.0, 75.0)
    C = random_c(np.random.default_rng(4))
    response = law.response(C, fibres)
    h = 1e-30
    for a, b in [(0, 0), (1, 1), (0, 1)]:
        direction = sym_unit(a, b)
        perturbed = law.response(C + 1j * h * direction, fibres)
        np.testing.assert_allclose(
            perturbed.psi.imag / h,
            0.5 * np.einsum("nab,ab->n", response.stress, direction),
            rtol=1e-12,
        )
        np.testing.assert_allclose(
            perturbed.stress.imag / h,
            0.5 * np.einsum("nabcd,cd->nab", response.tangent, direction),
            rtol=1e-11,
            atol=1e-12,
        )


def test_fibre_invariants_need_fibres():
    with pytest.raises(MaterialError, match="fibre"):
        _AllInvariants().response(np.eye(2)[None])


def test_parallel_fibres_are_rejected():
    with pytest.raises(MaterialError, match="parallel"):
        Fibres.from_angles(10.0, 190.0)


@pytest.mark.parametrize("angle", [0.0, 30.0, 72.0])
def test_orthotropic_with_isotropic_constants_is_st_venant_kirchhoff(angle):
    E, nu = 5.0, 0.3
    ortho = OrthotropicStVenantKirchhoff(E1=E, E2=E, G12=E / (2 * (1 + nu)), nu12=nu)
    iso = StVenantKirchhoff(E=E, nu=nu)
    C = random_c(np.random.default_rng(5))
    a, b = ortho.response(C, Fibres.from_angles(angle)), iso.response(C)
    np.testing.assert_allclose(a.psi, b.psi, rtol=1e-12)
    np.testing.assert_allclose(a.stress, b.stress, rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(a.tangent, b.tangent, rtol=1e-12, atol=1e-12)


def test_orthotropic_small_strain_stiffness_in_the_fibre_frame():
    law = OrthotropicStVenantKirchhoff(E1=800.0, E2=500.0, G12=30.0, nu12=0.35)
    fibres = Fibres.from_angles(0.0)
    cc = law.response(np.eye(2)[None], fibres).tangent[0]
    nu21 = 0.35 * 500 / 800
    # uniaxial stress along the warp: strain E11 = σ/E1, E22 = −ν12 σ/E1 (compliance check)
    Q = np.array([[cc[0, 0, 0, 0], cc[0, 0, 1, 1]], [cc[1, 1, 0, 0], cc[1, 1, 1, 1]]])
    compliance = np.linalg.inv(Q)
    np.testing.assert_allclose(
        compliance, [[1 / 800, -nu21 / 500], [-0.35 / 800, 1 / 500]], rtol=1e-12
    )
    assert cc[0, 1, 0, 1] == pytest.approx(30.0)


def test_non_crimp_fabric_reference_and_small_strain_moduli():
    law = NonCrimpFabric.from_moduli(1000.0, 600.0, 4.0)
    fibres = Fibres.from_angles(45.0)
    response = law.response(np.eye(2)[None], fibres)
    assert abs(response.psi[0]) < 1e-14
    np.testing.assert_allclose(response.stress[0], 0.0, atol=1e-13)
    cc = np.einsum("abcd,a,b,c,d->", response.tangent[0], *[fibres.warp] * 4)
    assert cc == pytest.approx(1000.0)
    assert np.einsum("abcd,a,b,c,d->", response.tangent[0], *[fibres.fill] * 4) == pytest.approx(
        600.0
    )
    shear = np.einsum(
        "abcd,a,b,c,d->", response.tangent[0], fibres.warp, fibres.fill, fibres.warp, fibres.fill
    )
    assert shear == pytest.approx(4.0)
    assert law.warp_modulus == pytest.approx(1000.0) and law.fill_modulus == pytest.approx(600.0)


def test_non_crimp_fabric_shear_energy_is_the_cos_squared_series():
    law = NonCrimpFabric(A=[-1.0, 1.0], B=[-1.0, 1.0], C=[2.0, 3.0])
    fibres = Fibres.from_angles(0.0)
    shear = np.radians(20.0)  # pure shear of the yarns, unit stretches
    C = np.array([[1.0, np.sin(shear)], [np.sin(shear), 1.0]])
    cos2 = np.sin(shear) ** 2  # angle between yarns is 90° − 20°
    assert law.energy_density(C, fibres) == pytest.approx(2.0 * cos2 + 3.0 / 2 * cos2**2)


@pytest.mark.parametrize(
    ("factory", "message"),
    [
        (lambda: OrthotropicStVenantKirchhoff(800, 100, 30, 3.0), "not positive definite"),
        (lambda: OrthotropicStVenantKirchhoff(800, -1, 30, 0.3), "E2 must be positive"),
        (lambda: OrthotropicStVenantKirchhoff(800, 100, 0, 0.3), "G12 must be positive"),
        (lambda: NonCrimpFabric([1.0, 1.0], [-1.0, 1.0], [1.0]), r"sum\(A\) must be 0"),
        (lambda: NonCrimpFabric([-1.0, 1.0], [1.0, -1.0], [1.0]), "moduli"),
        (lambda: NonCrimpFabric([-1.0, 1.0], [-1.0, 1.0], [-1.0]), r"C\[0\] must be positive"),
        (lambda: NonCrimpFabric([-1.0, 1.0], [-1.0, 1.0], []), "at least one"),
        (lambda: NonCrimpFabric([-1.0, np.nan], [-1.0, 1.0], [1.0]), "finite"),
        (lambda: make_material("kevlar", {}), "unknown material"),
        (lambda: make_material("orthotropic", {"E1": 1.0}), "needs E2, G12, nu12"),
        (lambda: make_material("neo-hooke", {"E": 1.0, "nu": 0.3, "mu": 2.0}), "mu"),
    ],
)
def test_fabric_parameters_are_validated(factory, message):
    with pytest.raises(MaterialError, match=message):
        factory()
