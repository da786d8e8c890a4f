"""A generator of biaxial test records from a known fabric model.

No public data set of biaxial tests of coated fabrics exists; to develop and check the fit
(:mod:`vares.materials.fitting`) vares makes its own records from a model whose constants are
known, driven through the load protocols the standards prescribe, with measurement noise.

The model: the **elastic–creep–ratchet (ECR) fabric model**
--------------------------------------------------------------

A model put together for vares from standard pieces (a complementary-energy backbone,
Norton–Bailey creep, a saturating ratchet); it is not fitted to any real fabric, only made to
show what real records show: nonlinearity, hysteresis, permanent set and creep.

The strain of a specimen under the force per width ``σ = (σ_w, σ_f)`` (kN/m) is the sum of three
parts and the noise of the measurement,

    ε = ε_e(σ) + ε_c + ε_r + noise                                   (all mm/mm, shape (2,))

- **Nonlinear elastic backbone** from the complementary energy
  ``W*(σ) = ½ σᵀ C σ + k_w σ_w³/3 + k_f σ_f³/3``:
  ``ε_e = C σ + (k_w σ_w², k_f σ_f²)`` with the plane-stress compliance
  ``C = [[1/E_w, −ν_wf/E_w], [−ν_wf/E_w, 1/E_f]]`` (reciprocal: ``ν_fw/E_f = ν_wf/E_w``).
  ``k < 0`` stiffens the yarn as it straightens; ``k = 0`` is the linear law.
- **Norton–Bailey creep**, irreversible, in its strain-hardening form: under a constant force
  ``ε_c = A_i (σ_i/σ_ref)^n t^m`` per yarn direction; under a varying one the creep strain
  reached so far gives the equivalent time from which each step continues (exact for a step of
  constant force), so creep runs while the force is held and, more slowly, while it changes.
- **Cyclic ratchet** (permanent set and hysteresis): while a yarn is loaded (``dσ_i > 0``) it
  gains the plastic strain ``dε_r,i = ρ_i (σ_i/σ_s) exp(−ε_r,i/ε*_i) dσ_i / E_i``; unloading is
  elastic. The first loading leaves a permanent set, each further cycle a smaller one (the
  exponential shakes it down), and every loading branch lies to the right of its unloading.
- **Noise**: independent Gaussian errors of the strain (standard deviation ``strain_noise``,
  mm/mm) and of the force (``force_noise``, kN/m), per sample.

With ``A = ρ = k = 0`` it is the linear orthotropic law of vares
(:class:`~vares.materials.OrthotropicStVenantKirchhoff` with ``E1 = E_w``, ``E2 = E_f``,
``nu12 = ν_wf``) plus noise.

Protocols
---------

:func:`msaj_protocol`: the load ratios of MSAJ/M-02 (1:1, 2:1, 1:2, 1:0, 0:1 warp:fill) in
turn, each cycled ``cycles`` times between the preload and the largest force (the side of a
0-ratio held at the preload). :func:`compensation_protocol` (EN 17117-2 style): loaded at the
prestress ratio to the prestress and held, cycled between the prestress and the design load
with holds at the top, then held at the prestress, where the compensation is read. Each
protocol is a list of :class:`Leg` (a ramp or a hold) that :func:`simulate` integrates.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace

import numpy as np

from .biaxial import BiaxialRecord

__all__ = [
    "ECRModel",
    "Leg",
    "compensation_protocol",
    "msaj_protocol",
    "simulate",
    "specimen_batch",
]


@dataclass(frozen=True)
class ECRModel:
    """The elastic–creep–ratchet fabric model (see the module docs); forces per width in kN/m.

    ``E_w``, ``E_f`` (kN/m) and ``nu_wf`` are the linear elastic constants (tangent at zero
    force); ``k_w``, ``k_f`` ((kN/m)⁻²) the backbone's quadratic terms; ``creep_A`` (mm/mm),
    ``creep_n``, ``creep_m`` and ``creep_reference`` (kN/m) the Norton–Bailey creep law (time
    in s); ``ratchet`` (ρ), ``ratchet_stress`` (σ_s, kN/m) and ``ratchet_saturation`` (ε*,
    mm/mm) the cyclic ratchet; ``strain_noise`` (mm/mm) and ``force_noise`` (kN/m) the
    standard deviations of the measurement errors.
    """

    E_w: float = 600.0
    E_f: float = 450.0
    nu_wf: float = 0.35
    k_w: float = 0.0
    k_f: float = 0.0
    creep_A: float = 0.0
    creep_n: float = 1.5
    creep_m: float = 0.3
    creep_reference: float = 10.0
    ratchet: float = 0.0
    ratchet_stress: float = 20.0
    ratchet_saturation: float = 0.01
    strain_noise: float = 5e-5
    force_noise: float = 0.0

    @classmethod
    def pes_pvc(cls, **changes: float) -> ECRModel:
        """A PES/PVC-like fabric (type II order of stiffness) with all three effects:
        stiffening yarns, creep of some 0.1 % in ten minutes at 10 kN/m, a permanent set of
        about 0.5 % after the first loading to 20 kN/m, and 5·10⁻⁵ strain noise."""
        base = cls(
            E_w=600.0,
            E_f=450.0,
            nu_wf=0.35,
            k_w=-2.0e-5,
            k_f=-3.0e-5,
            creep_A=2.0e-4,
            creep_n=1.5,
            creep_m=0.3,
            creep_reference=10.0,
            ratchet=0.4,
            ratchet_stress=20.0,
            ratchet_saturation=0.004,
            strain_noise=5e-5,
            force_noise=0.01,
        )
        return replace(base, **changes)

    @property
    def compliance(self) -> np.ndarray:
        """The linear plane-stress compliance ``C`` (2×2, m/kN): ``ε = C σ``."""
        coupling = -self.nu_wf / self.E_w
        return np.array([[1.0 / self.E_w, coupling], [coupling, 1.0 / self.E_f]])

    def elastic_strain(self, force: np.ndarray) -> np.ndarray:
        """The backbone strain ``ε_e`` of forces ``(..., 2)`` (kN/m) → ``(..., 2)`` mm/mm."""
        force = np.asarray(force, dtype=float)
        quadratic = np.array([self.k_w, self.k_f]) * force**2
        return force @ self.compliance.T + quadratic

    def parameters(self) -> dict[str, float]:
        return asdict(self)


@dataclass(frozen=True)
class Leg:
    """One leg of a load protocol: from the current force to ``force`` (warp, fill; kN/m) in
    ``duration`` s (equal forces: a hold), samples tagged with ``stage``."""

    duration: float
    force: tuple[float, float]
    stage: int


def msaj_protocol(
    largest: tuple[float, float] = (20.0, 20.0),
    preload: float = 0.5,
    cycles: int = 3,
    rate: float = 0.4,
    ratios: tuple[tuple[float, float], ...] = ((1, 1), (2, 1), (1, 2), (1, 0), (0, 1)),
) -> list[Leg]:
    """The MSAJ/M-02 protocol: each load ratio (warp:fill) cycled ``cycles`` times.

    ``largest``: the largest warp and fill forces (kN/m; the standard relates them to the
    fabric's tensile strength); a ratio's larger part goes to its direction's largest force,
    the other in proportion, a 0 part stays at ``preload`` (kN/m). ``rate``: loading and
    unloading rate of the leading direction (kN/m per s). Stage ``i`` is the ``i``-th ratio
    (1-based).
    """
    legs = [Leg(preload / rate, (preload, preload), 0)]
    for stage, (rw, rf) in enumerate(ratios, start=1):
        top = max(rw, rf)
        peak = (
            max(preload, largest[0] * rw / top),
            max(preload, largest[1] * rf / top),
        )
        duration = (max(peak) - preload) / rate
        for _ in range(cycles):
            legs.append(Leg(duration, peak, stage))
            legs.append(Leg(duration, (preload, preload), stage))
    return legs


def compensation_protocol(
    prestress: tuple[float, float] = (2.0, 1.5),
    design: tuple[float, float] = (10.0, 7.5),
    cycles: int = 5,
    rate: float = 0.2,
    first_hold: float = 300.0,
    top_hold: float = 60.0,
    last_hold: float = 600.0,
) -> list[Leg]:
    """A compensation protocol in the manner of EN 17117-2 (kN/m, s).

    Loaded from zero to the ``prestress`` (warp, fill) and held ``first_hold``; ``cycles``
    cycles between the prestress and the ``design`` load, held ``top_hold`` at each top; back to
    the prestress and held ``last_hold``, at whose end the compensation is read. ``rate``: the
    loading rate of the leading direction (kN/m per s). The holds and cycle count of a real
    test are those of the standard and the project; these defaults only illustrate.
    """
    up = max(prestress) / rate
    swing = max(d - p for d, p in zip(design, prestress, strict=True)) / rate
    legs = [Leg(up, prestress, 1), Leg(first_hold, prestress, 1)]
    for _ in range(cycles):
        legs.append(Leg(swing, design, 2))
        legs.append(Leg(top_hold, design, 2))
        legs.append(Leg(swing, prestress, 2))
    legs.append(Leg(last_hold, prestress, 3))
    return legs


def simulate(
    model: ECRModel,
    protocol: list[Leg],
    *,
    sample_interval: float = 1.0,
    substeps: int = 4,
    seed: int | None = 0,
    name: str = "generated",
) -> BiaxialRecord:
    """The record of a specimen of ``model`` driven through ``protocol``.

    Samples every ``sample_interval`` s (the force path is linear within each leg), each
    interval integrated in ``substeps`` steps; ``seed`` seeds the noise (None: fresh noise).
    Strains start at 0 at zero force (the state the extensometers are zeroed at). Returns a
    :class:`BiaxialRecord` with the protocol's stage numbers.
    """
    times, forces, stages = _path(protocol, sample_interval)
    A = np.array([model.creep_A, model.creep_A])
    E = np.array([model.E_w, model.E_f])
    saturation = model.ratchet_saturation
    creep = np.zeros(2)
    ratchet = np.zeros(2)
    strain = np.empty_like(forces)
    strain[0] = model.elastic_strain(forces[0])
    for i in range(1, len(times)):
        dt = (times[i] - times[i - 1]) / substeps
        for s in range(substeps):
            before = forces[i - 1] + (forces[i] - forces[i - 1]) * s / substeps
            after = forces[i - 1] + (forces[i] - forces[i - 1]) * (s + 1) / substeps
            middle = 0.5 * (before + after)
            if model.creep_A > 0:
                creep = _creep_step(creep, middle, dt, A, model)
            if model.ratchet > 0:
                rise = np.maximum(after - before, 0.0)
                ratchet = ratchet + (
                    model.ratchet
                    * (np.maximum(middle, 0.0) / model.ratchet_stress)
                    * np.exp(-ratchet / saturation)
                    * rise
                    / E
                )
        strain[i] = model.elastic_strain(forces[i]) + creep + ratchet
    rng = np.random.default_rng(seed)
    measured_strain = strain + rng.normal(0.0, model.strain_noise, strain.shape)
    measured_force = forces + (
        rng.normal(0.0, model.force_noise, forces.shape) if model.force_noise > 0 else 0.0
    )
    metadata = {"model": "vares ECR fabric model", "seed": str(seed)}
    metadata |= {k: f"{v:g}" for k, v in model.parameters().items()}
    return BiaxialRecord(
        times,
        measured_force,
        measured_strain,
        stages,
        name=name,
        source=f"vares ECR model (seed {seed})",
        metadata=metadata,
    )


def _creep_step(
    creep: np.ndarray, force: np.ndarray, dt: float, A: np.ndarray, model: ECRModel
) -> np.ndarray:
    """Creep strain ``(2,)`` after ``dt`` s at the constant ``force`` ``(2,)`` (kN/m), from
    the equivalent time of the creep strain reached so far (strain hardening)."""
    level = A * (np.maximum(force, 0.0) / model.creep_reference) ** model.creep_n
    out = creep.copy()
    active = level > 0
    equivalent = (creep[active] / level[active]) ** (1.0 / model.creep_m)
    out[active] = level[active] * (equivalent + dt) ** model.creep_m
    return out


def _path(protocol: list[Leg], interval: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sample times (s), forces ``(n, 2)`` and stages of a protocol starting at zero force."""
    times, forces, stages = [0.0], [(0.0, 0.0)], [protocol[0].stage if protocol else 0]
    now, current = 0.0, np.zeros(2)
    for leg in protocol:
        steps = max(1, round(leg.duration / interval))
        target = np.asarray(leg.force, dtype=float)
        for k in range(1, steps + 1):
            times.append(now + leg.duration * k / steps)
            forces.append(tuple(current + (target - current) * k / steps))
            stages.append(leg.stage)
        now += leg.duration
        current = target
    return np.array(times), np.array(forces), np.array(stages)


def specimen_batch(
    model: ECRModel,
    protocol: list[Leg],
    specimens: int = 3,
    scatter: float = 0.03,
    seed: int = 0,
    **simulate_options,
) -> tuple[list[BiaxialRecord], list[ECRModel]]:
    """Records of ``specimens`` specimens of one fabric batch, and each specimen's model.

    Each specimen's ``E_w``, ``E_f`` and ``nu_wf`` are the batch's times ``1 + scatter·z`` with
    independent standard normal ``z`` (``scatter`` is the coefficient of variation between
    specimens), drawn from ``seed``; each record has its own noise.
    """
    rng = np.random.default_rng(seed)
    records, models = [], []
    for i in range(specimens):
        factors = 1.0 + scatter * rng.standard_normal(3)
        own = replace(
            model,
            E_w=model.E_w * factors[0],
            E_f=model.E_f * factors[1],
            nu_wf=model.nu_wf * factors[2],
        )
        models.append(own)
        records.append(
            simulate(
                own,
                protocol,
                seed=seed * 1000 + i + 1,
                name=f"specimen-{i + 1}",
                **simulate_options,
            )
        )
    return records, models
