"""Property-based input checks (issue 32, hypothesis): random materials, contact-law inputs,
small scenes and engine settings either run with finite outputs or are refused with a
:class:`demfem.errors.DemfemError`; never a pyo3 ``PanicException`` (a ``BaseException``, so
it is not caught here and fails the test), a hang (small sizes, ``max_examples`` modest) or a
NaN. SI units throughout.
"""
from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from demfem import _core, contact, dem  # noqa: E402
from demfem.errors import DemfemError  # noqa: E402
from demfem.materials import Material  # noqa: E402
from demfem.scenes.table import AccumulationTable  # noqa: E402

SETTINGS = settings(max_examples=50, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])
R = 0.008
MM = 1e-3

#: Awkward reals: NaN, infinities, zero, signs. (Values like 1e-300 or 5e-324 for a modulus,
#: density or stiffness overflow or underflow in closed forms; the known failures they cause
#: are pinned by the xfail tests at the end.)
SPECIAL = st.sampled_from([math.nan, math.inf, -math.inf, 0.0, -0.0, -1.0])


def reals(lo: float, hi: float) -> st.SearchStrategy[float]:
    """Mostly valid values in [lo, hi] (log-uniform if lo > 0), sometimes awkward ones."""
    if lo > 0:
        core = st.floats(math.log10(lo), math.log10(hi)).map(lambda e: 10.0 ** e)
    else:
        core = st.floats(lo, hi)
    return st.one_of(core, core, core, SPECIAL)


class _Refused:
    def __repr__(self) -> str:
        return "REFUSED"


#: What :func:`outcome` returns for a call refused with a DemfemError.
REFUSED: Any = _Refused()


def outcome(fn: Callable[[], Any]) -> Any:
    """``fn()``, or :data:`REFUSED` if it was refused with a DemfemError (any other
    exception, including a Rust panic, propagates and fails the test)."""
    try:
        return fn()
    except DemfemError as exc:
        assert str(exc), "a refusal must say why"
        return REFUSED


def finite(*arrays: Any) -> bool:
    return all(np.isfinite(np.asarray(a, float)).all() for a in arrays)


E_ = reals(1e3, 1e13)
NU_ = st.one_of(st.floats(-1.5, 0.8), SPECIAL)
RHO_ = reals(1.0, 1e5)


# --------------------------------------------------------------------------------------------
# Materials
# --------------------------------------------------------------------------------------------

@SETTINGS
@given(E=E_, nu=NU_, rho=RHO_)
def test_material_is_valid_or_refused_naming_the_field(E, nu, rho):
    m = outcome(lambda: Material(E, nu, rho))
    valid = (math.isfinite(E) and E > 0 and math.isfinite(nu) and -1 < nu < 0.5
             and math.isfinite(rho) and rho > 0)
    assert (m is not REFUSED) == valid
    if m is not REFUSED:
        assert math.isfinite(m.shear_modulus) and math.isfinite(m.p_wave_speed) and m.p_wave_speed >= 0
    else:
        with pytest.raises(DemfemError, match="E|nu|density"):
            Material(E, nu, rho)


@SETTINGS
@given(E=E_, nu=NU_, rho=RHO_, friction=reals(1e-3, 10.0), restitution=st.one_of(st.floats(0.0, 1.2), SPECIAL),
       v=st.floats(0.0, 5.0))
def test_two_sphere_impact_runs_finite_or_is_refused(E, nu, rho, friction, restitution, v):
    mat = dem.material(E, nu, rho, friction=friction, restitution=restitution)
    effects = ["friction", "rotation", "damping"]

    def build():
        return dem.DemSimulation(np.array([[0.0, 0, 0], [2 * R + 1e-4, 0.3 * R, 0]]), np.full(2, R),
                                 [mat], [], effects, velocities=np.array([[v, 0, 0], [0, 0, 0]]),
                                 gravity=(0, 0, 0), expected_max_speed=max(v, 0.1))

    sim = outcome(build)
    if sim is REFUSED:
        return
    assert outcome(lambda: sim.step(300)) is not REFUSED
    assert sim.steps == 300
    assert finite(sim.positions(), sim.velocities(), sim.angular_velocities(), sim.kinetic_energy(),
                  sim.max_overlap())
    assert sim.dt > 0 and sim.dt <= sim.stable_dt * (1 + 1e-12)


@SETTINGS
@given(E=st.floats(6.0, 12.0).map(lambda e: 10.0 ** e), nu=st.floats(-0.9, 0.49),
       restitution=st.floats(0.05, 1.0), v=st.floats(0.01, 5.0), offset=st.floats(0.0, 1.5))
def test_closed_two_sphere_impact_never_gains_energy(E, nu, restitution, v, offset):
    """Valid materials stiff enough that the impact overlap stays well below a radius
    (E >= 1e6 Pa at <= 5 m/s): no gravity, no drive, so the kinetic energy after the impact
    (all contacts open) is at most the initial one, and momentum is conserved."""
    mat = dem.material(E, nu, 2230.0, friction=0.3, restitution=restitution)
    effects = ["friction", "rotation"] + (["damping"] if restitution < 1 else [])
    pos = np.array([[0.0, 0, 0], [2 * R + 1e-4, offset * R, 0]])
    sim = dem.DemSimulation(pos, np.full(2, R), [mat], [], effects,
                            velocities=np.array([[v, 0, 0], [0, 0, 0]]), gravity=(0, 0, 0),
                            expected_max_speed=v)
    ke0 = sim.kinetic_energy()
    m = sim.masses()
    # long enough for the slowest impact to end (soft: Hertz duration ~ 3 (m*^2/(E*^2 R* v))^(1/5))
    t_c = 3.3 * ((m[0] / 2) ** 2 / ((E / (2 * (1 - nu**2))) ** 2 * (R / 2) * v)) ** 0.2
    sim.run_until(3 * t_c + 2e-4 / v)
    assert finite(sim.positions(), sim.velocities(), sim.angular_velocities())
    assert sim.kinetic_energy() <= ke0 * (1 + 1e-6)
    p = (m[:, None] * sim.velocities()).sum(axis=0)
    assert np.abs(p - m[0] * np.array([v, 0, 0])).max() <= 1e-9 * m[0] * v
    assert sim.max_overlap() < 0.5 * R


# --------------------------------------------------------------------------------------------
# Contact-law inputs
# --------------------------------------------------------------------------------------------

MODELS = st.sampled_from(["hertz", "linear", "hertz_reissner", "bogus", ""])
STIFF = reals(1e-3, 1e15)  # N/m^1.5 or N/m


@SETTINGS
@given(overlaps=st.lists(st.one_of(st.floats(-1e-2, 1e-2), SPECIAL), min_size=0, max_size=8),
       model=MODELS, k_h=STIFF, k_r=STIFF, k=STIFF)
def test_normal_force_is_finite_nonnegative_monotone_or_refused(overlaps, model, k_h, k_r, k):
    d = np.array(overlaps, float)
    out = outcome(lambda: _core.normal_force(d, model, k_h=k_h, k_r=k_r, k=k))
    if out is REFUSED:
        return
    assert model in ("hertz", "linear", "hertz_reissner")
    f, kt = out
    assert f.shape == d.shape and kt.shape == d.shape
    assert finite(f, kt) or not finite(d)  # an infinite overlap may give an infinite force
    if d.size and finite(d) and finite(f):
        assert (f >= 0).all() and (f[d <= 0] == 0).all()
        order = np.argsort(d)
        assert (np.diff(f[order]) >= -1e-12 * np.abs(f).max()).all()


@SETTINGS
@given(m=reals(1e-9, 10.0), v=reals(1e-6, 100.0), model=MODELS, k_h=STIFF, k_r=STIFF, k=STIFF)
def test_max_impact_force_and_duration_finite_or_refused(m, v, model, k_h, k_r, k):
    f = outcome(lambda: _core.max_impact_force(m, v, model, k_h=k_h, k_r=k_r, k=k))
    if f is not REFUSED:
        assert math.isfinite(f) and f >= 0
    t = outcome(lambda: _core.hertz_impact_duration(k_h, m, v))
    if t is not REFUSED:
        assert math.isfinite(t) and t > 0


@SETTINGS
@given(r=reals(1e-5, 1.0), E=E_, nu=NU_, rho=RHO_)
def test_rayleigh_step_is_the_closed_form_or_refused(r, E, nu, rho):
    import contact_oracles as oracle

    a = outcome(lambda: contact.rayleigh_time_step(r, E, nu, rho))
    if a is not REFUSED:   # the closed form of Li, Xu & Thornton, written independently
        assert math.isfinite(a) and a > 0
        assert a == pytest.approx(oracle.rayleigh_time_step(r, E, nu, rho), rel=1e-12)


@SETTINGS
@given(zeta=st.one_of(st.floats(-1.0, 2.0), st.sampled_from([math.nan, math.inf, -math.inf, -0.0])),
       e=st.one_of(st.floats(-0.5, 0.0), st.floats(0.02, 1.5), SPECIAL), clamp=st.booleans())
def test_tsuji_maps_are_finite_bounded_or_refused(zeta, e, clamp):
    # zeta <= 2 and e >= 0.02: the unclamped map integrates for ~1 s per call at zeta >= 2.5,
    # its inverse for 4-40 s at e <= 1e-3, and the clamped map goes wrong at huge zeta
    # (pinned by an xfail test below)
    rest = outcome(lambda: _core.tsuji_restitution(zeta, clamp))
    if rest is not REFUSED:
        assert math.isfinite(rest) and 0.0 <= rest <= 1.0 + 1e-12
    z = outcome(lambda: _core.tsuji_damping_for_restitution(e, clamp))
    if z is not REFUSED:
        assert math.isfinite(z) and z >= 0.0
        back = _core.tsuji_restitution(z, clamp)
        assert back == pytest.approx(e, abs=1e-3)


# --------------------------------------------------------------------------------------------
# Small random scenes and engine settings
# --------------------------------------------------------------------------------------------

EFFECTS = ["gravity", "belt", "moving_walls", "friction", "rotation", "damping",
           "rolling_resistance", "planar"]


#: The setting a scene example breaks (about half the examples break none).
BROKEN = ["none"] * 16 + ["radius", "E", "nu", "density", "friction", "restitution", "rolling",
          "effect", "model", "dt_safety", "speed", "threads", "skin", "stiffness", "motion"]


@st.composite
def scenes(draw):
    """Up to six spheres on a belt, maybe a moving wall: consistent settings, except for at
    most one (``BROKEN``) drawn from invalid or awkward values."""
    broken = draw(st.sampled_from(BROKEN))

    def pick(name, valid, awkward):
        return draw(awkward if broken == name else valid)

    n = draw(st.integers(1, 6))
    radii = np.array(draw(st.lists(st.floats(2e-3, 2e-2), min_size=n, max_size=n)), float)
    if broken == "radius":
        radii[draw(st.integers(0, n - 1))] = draw(SPECIAL)
    # a grid of sites 5 cm apart, 2.5 cm up: valid radii never overlap at the start
    sites = np.array([(0.05 * (i % 3) + 0.03, 0.05 * (i // 3) + 0.03, 0.025) for i in range(n)]).reshape(n, 3)
    vel = np.array(draw(st.lists(st.floats(-3.0, 3.0), min_size=3 * n, max_size=3 * n)), float).reshape(n, 3)
    friction = pick("friction", st.sampled_from([0.0, 0.2, 0.6]), st.sampled_from([-0.1, math.nan]))
    restitution = pick("restitution", st.sampled_from([1.0, 0.5, 0.1]), st.sampled_from([0.0, 1.5]))
    rolling = pick("rolling", st.sampled_from([0.0, 0.05]), st.sampled_from([-1.0, math.inf]))
    mat = dem.material(pick("E", st.floats(6, 11).map(lambda e: 10.0 ** e), E_),
                       pick("nu", st.floats(-0.5, 0.49), NU_), pick("density", st.floats(1000, 8000), RHO_),
                       friction=friction, restitution=restitution, rolling_friction=rolling)
    belt = draw(st.booleans())
    walls = [dem.plane((0, 0, 0), (0, 0, 1), surface_velocity=(0.2, 0, 0) if belt else None)]
    motion = pick("motion", st.sampled_from([None, dem.harmonic((0, 1, 0), 0.01, 0.5),
                                             dem.constant_velocity((-0.1, 0, 0))]),
                  st.sampled_from([dem.harmonic((0, 1, 0), -0.01, 0.1), dem.harmonic((0, 1, 0), 0.01, 0.0),
                                   dem.harmonic((0, 0, 0), 0.01, 0.1)]))
    if draw(st.booleans()) or broken == "motion":
        walls.append(dem.polygon([(0.2, 0, 0), (0.2, 0.2, 0), (0.2, 0.2, 0.05), (0.2, 0, 0.05)], motion=motion))
    effects = {"gravity"} if draw(st.booleans()) else set()
    effects |= {"belt"} if belt else set()
    effects |= {"moving_walls"} if motion is not None and len(walls) > 1 else set()
    effects |= {"friction", "rotation"} if friction != 0 else set()
    effects |= {"damping"} if restitution != 1 else set()
    effects |= {"rolling_resistance", "rotation"} if rolling != 0 else set()
    effects |= {"planar"} if draw(st.booleans()) else set()
    if broken == "effect":  # one effect flipped: usually an EffectError
        effects ^= {draw(st.sampled_from(EFFECTS))}
    kw: dict[str, Any] = dict(
        model=pick("model", st.sampled_from(["hertz_mindlin", "hertz_reissner_mindlin", "linear"]),
                   st.sampled_from(["nope", ""])),
        dt_safety=pick("dt_safety", st.floats(0.01, 1.0), st.sampled_from([0.0, 1.5, math.nan])),
        expected_max_speed=pick("speed", st.floats(0.01, 20.0), st.sampled_from([0.0, -1.0, math.inf])),
        threads=pick("threads", st.sampled_from([1, 2]), st.sampled_from([0, -1])),
        gravity=(0.0, 0.0, -9.81) if "gravity" in effects else (0.0, 0.0, 0.0),
    )
    if draw(st.booleans()) or broken == "skin":
        kw["skin"] = pick("skin", st.floats(1e-5, 0.05), st.sampled_from([0.0, -1e-3, math.nan]))
    if kw["model"] == "linear":
        kw["linear_stiffness"] = pick("stiffness", st.tuples(st.floats(1e3, 1e8), st.floats(1e3, 1e8)),
                                      st.tuples(STIFF, STIFF))
    return sites, radii, vel, mat, walls, sorted(effects), kw


@SETTINGS
@given(scene=scenes(), n_steps=st.integers(0, 400))
def test_small_random_scene_runs_finite_or_is_refused(scene, n_steps):
    pos, radii, vel, mat, walls, effects, kw = scene
    sim = outcome(lambda: dem.DemSimulation(pos, radii, [mat], walls, effects, velocities=vel, **kw))
    if sim is REFUSED:
        return
    assert sim.dt > 0 and math.isfinite(sim.dt)
    n_steps = min(n_steps, max(1, int(0.05 / sim.dt)))  # at most 50 ms of simulated time
    if outcome(lambda: sim.step(n_steps, chunk=100)) is REFUSED:
        return
    assert sim.steps == n_steps
    alive = sim.alive()
    assert finite(sim.positions()[alive], sim.velocities()[alive], sim.angular_velocities()[alive],
                  sim.kinetic_energy(), sim.max_overlap(), sim.contact_force_sums()[alive])
    if len(sim):
        c = sim.contacts()
        assert finite(c["normal_force"], c["overlap"], c["tangential_force"])


@SETTINGS
@given(n=st.integers(-5, 500), chunk=st.integers(-5, 5000), t=st.one_of(st.floats(-1.0, 0.01), SPECIAL))
def test_step_counts_and_targets_run_or_are_refused(n, chunk, t):
    belt = dem.plane((0, 0, 0), (0, 0, 1), surface_velocity=(0.2, 0, 0))
    sim = dem.DemSimulation(np.array([[0.0, 0, R]]), np.array([R]),
                            [dem.material(1e8, 0.22, 2230.0, friction=0.2, restitution=0.5)], [belt],
                            ["gravity", "belt", "friction", "rotation", "damping"])
    done = outcome(lambda: sim.step(n, chunk=chunk))
    if done is REFUSED:
        assert n < 0 or chunk < 0
        assert sim.steps == 0
    else:
        assert sim.steps == n
    before = sim.steps
    taken = outcome(lambda: sim.run_until(t))
    if taken is not REFUSED:
        assert taken >= 0 and sim.steps == before + taken
    assert finite(sim.positions(), sim.velocities())


@SETTINGS
@given(params=st.fixed_dictionaries({}, optional={
    "n_spheres": st.integers(-10, 400),
    "length": reals(0.01, 1.0),
    "width": reals(0.01, 0.6),
    # >= 0.03 m: shorter tilted walls leave no room for a hexagonal site and build() fails
    # with a bare ValueError (pinned by an xfail test below)
    "tilted_wall_length": reals(0.03, 0.6),
    "tilted_wall_angle_deg": st.one_of(st.floats(-10, 100), SPECIAL),
    "opening_width": reals(1e-3, 0.2),
    "gate_amplitude": st.one_of(st.floats(0.0, 0.1), SPECIAL),
    "gate_period": reals(1e-3, 10.0),
    "young_modulus": E_,
    "poisson_ratio": NU_,
    "friction": st.one_of(st.floats(0.0, 2.0), SPECIAL),
    "restitution": st.one_of(st.floats(0.0, 1.2), SPECIAL),
    "packing_gap": st.one_of(st.floats(0.0, 1.0), SPECIAL),
}))
def test_table_parameters_build_a_valid_scene_or_are_refused(params):
    t = outcome(lambda: AccumulationTable(**params))
    if t is REFUSED:
        return
    scene = outcome(t.build)
    if scene is REFUSED:
        return
    scene.check_start_positions()  # raises on overlaps or spheres outside the walls
    assert scene.n_particles == t.n_spheres and finite(scene.positions, scene.radii, scene.masses)
    sim = outcome(lambda: dem.from_scene(scene, record_onsets=False))
    if sim is not REFUSED:
        sim.step(20)
        assert finite(sim.positions(), sim.velocities())


# --------------------------------------------------------------------------------------------
# Explicit FEM: materials, damping, mass scaling and step settings
# --------------------------------------------------------------------------------------------

_MESH = _core.fem_tet_mesh(np.array([0.0, 4 * MM]), np.array([4.7, 4.7]) * MM,
                           np.array([5.8, 5.8]) * MM, 12, 1, 2 * MM)


@SETTINGS
@given(E=E_, nu=NU_, rho=RHO_, safety=st.one_of(st.floats(0.05, 1.0), st.sampled_from([0.0, 1.2, math.nan])),
       alpha=st.one_of(st.floats(0.0, 1e6), st.sampled_from([-1.0, math.nan])),
       beta=st.one_of(st.floats(0.0, 1e-8), st.sampled_from([-1e-9, math.inf])),
       scaling=st.one_of(st.none(), reals(1e-9, 1e-5)), certified=st.booleans())
def test_fem_solver_settings_run_finite_or_are_refused(E, nu, rho, safety, alpha, beta, scaling, certified):
    nodes, tets, _ = _MESH

    def build():
        return _core.FemTetSolver(nodes, tets, E, nu, rho, safety_factor=safety, rayleigh_alpha=alpha,
                                  rayleigh_beta=beta, mass_scaling_dt=scaling, certified_step=certified)

    s = outcome(build)
    if s is REFUSED:
        return
    assert 0 < s.dt <= s.dt_limit * (1 + 1e-12) and math.isfinite(s.added_mass)
    v = np.zeros_like(nodes)
    v[:, 0] = 0.1
    s.set_initial_velocity(v)
    s.run(200)
    e = s.energy()
    assert all(math.isfinite(x) for x in e.values())
    assert finite(s.displacement(), s.velocity(), s.element_stresses())
    assert e["kinetic"] + e["internal"] <= e["initial"] * (1 + 1e-6) + 1e-30


@SETTINGS
@given(n_theta=st.integers(0, 40), layers=st.integers(0, 4),  # negative counts: xfail test below
       size=st.one_of(st.floats(0.5 * MM, 5 * MM), st.sampled_from([0.0, -1e-3, math.nan, math.inf])),
       r_out=st.one_of(st.floats(4.0 * MM, 7.0 * MM), SPECIAL))
def test_tet_mesh_inputs_give_a_valid_mesh_or_are_refused(n_theta, layers, size, r_out):
    z = np.array([0.0, 3 * MM])
    out = outcome(lambda: _core.fem_tet_mesh(z, np.array([4.7, 4.7]) * MM, np.array([r_out, r_out]), n_theta,
                                             layers, size))
    if out is REFUSED:
        return
    nodes, tets, q = out
    assert r_out > 4.7 * MM and n_theta >= 3 and layers >= 1
    assert finite(nodes) and tets.min() >= 0 and tets.max() < len(nodes)
    assert q["min_volume"] > 0 and q["min_dihedral_deg"] >= 5.0


# --------------------------------------------------------------------------------------------
# Known failures found by the properties above (strict xfail: each turns into a failure,
# to be removed, once the code outside these tests is fixed)
# --------------------------------------------------------------------------------------------

def test_known_clamped_tsuji_at_huge_zeta_is_a_restitution():
    e = _core.tsuji_restitution(1e20, True)
    assert 0.0 <= e <= 1.0


def test_known_tiny_tilted_wall_is_refused_with_a_demfem_error():
    assert outcome(lambda: AccumulationTable(tilted_wall_length=0.02).build()) is REFUSED


def test_known_negative_mesh_counts_are_refused_with_a_demfem_error():
    z = np.array([0.0, 3 * MM])
    assert outcome(lambda: _core.fem_tet_mesh(z, np.array([4.7, 4.7]) * MM, np.array([5.8, 5.8]) * MM,
                                              12, -1, 1 * MM)) is REFUSED


def test_known_subnormal_modulus_in_rayleigh_step():
    a = outcome(lambda: contact.rayleigh_time_step(1.0, 5e-324, 0.0, 1.0))
    assert a is REFUSED or math.isfinite(a)


def test_known_tiny_reissner_stiffness_gives_a_finite_force():
    f, kt = _core.normal_force(np.array([1e-3]), "hertz_reissner", k_h=1.0, k_r=1e-300, k=1.0)
    assert finite(f, kt)
