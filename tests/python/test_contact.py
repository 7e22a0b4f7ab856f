"""Contact laws (eqs. 1–15): the Rust-backed ``demfem.contact`` against closed forms and
against independent scipy computations (``contact_oracles``: Brent's method on eq. 12 and on
the series law, adaptive DOP853 integrations of the Tsuji impact), never against itself."""
import inspect
import math

import contact_oracles as oracle
import numpy as np
import pytest

import demfem._core as core
import demfem.contact as contact
from demfem.cartridge import Cartridge
from demfem.contact import (
    ContactBody,
    effective_mass,
    effective_modulus,
    effective_radius,
    hertz_contact_duration,
    hertz_max_overlap,
    hertz_stiffness,
    k_eq,
    k_linear,
    max_contact_force,
    normal_force,
    rayleigh_time_step,
    reissner_stiffness,
    tsuji_damping_for_restitution,
    tsuji_restitution,
)
from demfem.errors import InvalidParameterError

CART = Cartridge()


def body(E=45e9, shell=True):
    c = ContactBody.from_cartridge(CART)
    return ContactBody(c.mass, c.radius, E, c.nu, c.shell_thickness if shell else None,
                       c.shell_radius if shell else None)


def test_stiffness_formulas():
    # eq. 2-4 for two equal spheres: R* = R/2, E* = E / (2 (1 - nu^2))
    k = hertz_stiffness(0.008, 0.008, 45e9, 0.22, 45e9, 0.22)
    assert k == pytest.approx(4 / 3 * math.sqrt(0.004) * 45e9 / (2 * (1 - 0.22**2)), rel=1e-14)
    # eq. 6
    assert reissner_stiffness(45e9, 0.22, 1.1e-3, 5.25e-3) == pytest.approx(
        4 / math.sqrt(3 * (1 - 0.22**2)) * 45e9 * 1.1e-3**2 / 5.25e-3, rel=1e-14)


def test_from_cartridge_uses_mid_surface_radius():
    b = ContactBody.from_cartridge(CART)
    assert b.shell_radius == pytest.approx(5.25e-3)
    assert b.radius == pytest.approx(CART.equivalent_sphere().radius)
    assert b.mass == CART.mass


def test_hertz_energy_balance():
    """Integrating an undamped Hertz impact (the oracle's DOP853, in metres and seconds)
    gives the core's maximum force, overlap, duration and an elastic rebound."""
    a = body(shell=False)
    for v in (0.01, 0.2, 2.0):
        imp = oracle.damped_hertz_impact(a, a, v, zeta=0.0, n_out=4000)
        assert imp.restitution == pytest.approx(1.0, abs=1e-7)
        assert imp.max_force == pytest.approx(max_contact_force(a, a, v, "hertz"), rel=1e-5)
        assert imp.overlap.max() == pytest.approx(hertz_max_overlap(a, a, v), rel=1e-5)
        assert imp.time[-1] == pytest.approx(hertz_contact_duration(a, a, v), rel=1e-7)


def test_linearized_is_sqrt_four_fifths_of_hertz_without_shells():
    a = body(shell=False)
    for v in (1e-4, 0.2, 10.0):
        ratio = max_contact_force(a, a, v, "linearized") / max_contact_force(a, a, v, "hertz")
        assert ratio == pytest.approx(math.sqrt(0.8), rel=1e-12)
    # with a very stiff (thick, flat) shell the limit is approached: k_R ~ 1e3 k_linear
    stiff = ContactBody(a.mass, a.radius, a.E, a.nu, 0.999, 1.0)
    r = max_contact_force(stiff, stiff, 0.2, "linearized") / max_contact_force(stiff, stiff, 0.2, "hertz")
    assert r == pytest.approx(math.sqrt(0.8), rel=1e-4)


def test_combined_force_is_below_each_law_and_monotonic():
    Es = np.logspace(6, 12, 25)
    vs = np.logspace(-4, 1, 21)
    prev_e = np.zeros(vs.size)
    for E in Es:
        a = body(E)
        fs = []
        for v in vs:
            f = max_contact_force(a, a, v, "hertz_reissner")
            assert f < max_contact_force(a, a, v, "hertz")
            assert f < max_contact_force(a, a, v, "reissner")
            # eq. 12 holds at the root (the pair's constants from the closed forms), which
            # Brent's method finds independently
            p = oracle.pair_constants(a, a)
            lhs = f**2 / p.k_r + 0.8 * f ** (5 / 3) / p.k_h ** (2 / 3)
            assert lhs == pytest.approx(p.m_star * v * v, rel=1e-12)
            assert f == pytest.approx(
                oracle.hertz_reissner_max_force(p.k_h, p.k_r, p.m_star, v), rel=1e-12)
            fs.append(f)
        fs = np.array(fs)
        assert np.all(np.diff(fs) > 0)           # monotonic in v_rel
        assert np.all(fs > prev_e)               # monotonic in E
        prev_e = fs


def test_normal_force_matches_closed_forms_and_the_brent_oracle():
    a = body()
    p = oracle.pair_constants(a, a)
    k_h, k_r = p.k_h, p.k_r
    d = np.logspace(-10, -4, 61)
    np.testing.assert_allclose(normal_force(d, "hertz", k_h=k_h), k_h * d**1.5, rtol=1e-14)
    np.testing.assert_allclose(normal_force(d, "linear", k=k_r), k_r * d, rtol=1e-15)
    f_hr = normal_force(d, "hertz_reissner", k_h=k_h, k_r=k_r)
    np.testing.assert_allclose(f_hr, oracle.hertz_reissner_force(d, k_h, k_r), rtol=1e-12)
    # the series law holds at the core's root
    np.testing.assert_allclose((f_hr / k_h) ** (2 / 3) + f_hr / k_r, d, rtol=1e-12)
    for model, kw in (("hertz", {"k_h": k_h}), ("linear", {"k": k_r}),
                      ("hertz_reissner", {"k_h": k_h, "k_r": k_r})):
        # the core's tangent stiffness is the derivative of its force (central difference)
        _, stiff = core.normal_force(d, model, **kw)
        h = d * 1e-6
        fd = (normal_force(d + h, model, **kw) - normal_force(d - h, model, **kw)) / (2 * h)
        np.testing.assert_allclose(stiff, fd, rtol=1e-6)
        # zero at and below contact, in the shape of the overlap given
        assert np.all(normal_force(np.array([-1e-6, 0.0]), model, **kw) == 0.0)
        grid = d[:6].reshape(2, 3)
        f2 = normal_force(grid, model, **kw)
        assert f2.shape == (2, 3)
        np.testing.assert_array_equal(f2.reshape(-1), normal_force(d[:6], model, **kw))
        assert normal_force(np.float64(d[3]), model, **kw).shape == ()


def test_series_law_at_extreme_stiffness_ratios_matches_the_brent_oracle():
    d = np.array([1e-3, 2e-3])
    for k_h, k_r in [(1.0, 1e-300), (1e-300, 1e300), (1e300, 1e-300), (1e10, 1e6)]:
        f = normal_force(d, "hertz_reissner", k_h=k_h, k_r=k_r)
        assert np.isfinite(f).all() and (f > 0).all() and f[1] > f[0]
        np.testing.assert_allclose(f, oracle.hertz_reissner_force(d, k_h, k_r), rtol=1e-9)


def test_max_force_matches_closed_forms_and_the_brent_oracle():
    for E in (1e7, 45e9, 1e12):
        a = body(E)
        for b in (a, body(E, shell=False), ContactBody.rigid_wall()):
            p = oracle.pair_constants(a, b)
            for v in (1e-4, 0.2, 10.0):
                assert max_contact_force(a, b, v, "hertz") == pytest.approx(
                    oracle.hertz_max_force(p.k_h, p.m_star, v), rel=1e-14)
                assert max_contact_force(a, b, v, "reissner") == pytest.approx(
                    oracle.linear_max_force(p.k_r, p.m_star, v), rel=1e-14)
                assert max_contact_force(a, b, v, "hertz_reissner") == pytest.approx(
                    oracle.hertz_reissner_max_force(p.k_h, p.k_r, p.m_star, v), rel=1e-12)
                k_lin = oracle.k_linear(p.r_star, p.e_star, p.m_star, v)
                k_eq_ = 1.0 / (1.0 / p.k_r + 1.0 / k_lin)
                assert max_contact_force(a, b, v, "linearized") == pytest.approx(
                    oracle.linear_max_force(k_eq_, p.m_star, v), rel=1e-14)
                # the binding itself, given the pair's constants
                assert core.max_impact_force(p.m_star, v, "hertz_reissner", k_h=p.k_h,
                                             k_r=p.k_r) == pytest.approx(
                    oracle.hertz_reissner_max_force(p.k_h, p.k_r, p.m_star, v), rel=1e-12)
    # no shell on either side: eq. 12 is Hertz alone, and 'reissner' is refused
    s = body(shell=False)
    assert max_contact_force(s, s, 0.2) == max_contact_force(s, s, 0.2, "hertz")
    with pytest.raises(InvalidParameterError, match="reissner"):
        max_contact_force(s, s, 0.2, "reissner")
    assert max_contact_force(body(), body(), 0.0) == 0.0


def test_effective_quantities_match_closed_forms():
    for args in ((45e9, 0.22, 70e9, 0.3), (45e9, 0.22, math.inf, 0.0), (1e7, -0.5, 2e7, 0.49)):
        assert effective_modulus(*args) == pytest.approx(oracle.effective_modulus(*args),
                                                         rel=1e-15)
    for r in ((0.008, 0.005), (0.008, math.inf)):
        assert effective_radius(*r) == pytest.approx(oracle.effective_radius(*r), rel=1e-15)
    for m in ((0.01, 0.02), (0.01, math.inf)):
        assert effective_mass(*m) == pytest.approx(oracle.effective_mass(*m), rel=1e-15)
    # the pair's constants, with and without shells and against a rigid wall (the wall
    # first or second)
    wall = ContactBody.rigid_wall()
    for a, b in ((body(), body()), (body(), body(shell=False)), (body(), wall), (wall, body()),
                 (body(shell=False), wall)):
        p = oracle.pair_constants(a, b)
        q = contact._pair(a, b)
        assert q.r_star == pytest.approx(p.r_star, rel=1e-15)
        assert q.e_star == pytest.approx(p.e_star, rel=1e-15)
        assert q.m_star == pytest.approx(p.m_star, rel=1e-15)
        assert q.k_h == pytest.approx(p.k_h, rel=1e-14)
        assert q.k_r == pytest.approx(p.k_r, rel=1e-14) if math.isfinite(p.k_r) \
            else math.isinf(q.k_r)
    with pytest.raises(InvalidParameterError, match="both bodies"):
        max_contact_force(wall, wall, 0.2)


def test_linearized_stiffness_and_overlap_match_closed_forms():
    for a, b in ((body(), body()), (body(shell=False), ContactBody.rigid_wall())):
        p = oracle.pair_constants(a, b)
        for v in (1e-4, 0.2, 10.0):
            assert k_linear(a, b, v) == pytest.approx(
                oracle.k_linear(p.r_star, p.e_star, p.m_star, v), rel=1e-14)
            assert hertz_max_overlap(a, b, v) == pytest.approx(
                oracle.hertz_max_overlap(p.k_h, p.m_star, v), rel=1e-14)
            # k_lin is the secant stiffness F_H/δ_H at the Hertz maximum; an impact on a
            # spring of k_lin reaches √(4/5) of the Hertz maximum overlap (and force)
            k_lin, d_h = k_linear(a, b, v), hertz_max_overlap(a, b, v)
            assert k_lin * d_h == pytest.approx(
                oracle.hertz_max_force(p.k_h, p.m_star, v), rel=1e-13)
            assert oracle.linear_max_force(k_lin, p.m_star, v) / k_lin == pytest.approx(
                math.sqrt(0.8) * d_h, rel=1e-13)


def test_hertz_duration_factor_is_the_beta_function_and_the_integral():
    assert oracle.hertz_duration_factor_quad() == pytest.approx(
        oracle.hertz_duration_factor_beta(), rel=1e-14)
    a = body(shell=False)
    p = oracle.pair_constants(a, a)
    for v in (1e-3, 0.2, 5.0):
        t_c = oracle.hertz_duration_factor_beta() * oracle.hertz_max_overlap(p.k_h, p.m_star,
                                                                              v) / v
        assert hertz_contact_duration(a, a, v) == pytest.approx(t_c, rel=1e-14)


@pytest.mark.parametrize("clamp", [False, True])
def test_restitution_matches_the_dop853_oracle(clamp):
    # unclamped, the core's RK4 agrees with the adaptive DOP853 to ~1e-11; clamped, the core
    # places the zero of the force by linear interpolation within a step, ~3e-9 (the oracle,
    # rerun at rtol 1e-13 and a 10x smaller step, moves by < 1e-11)
    rel = 1e-10 if not clamp else 5e-9
    for zeta in (0.0, 0.05, 0.5, 1.0, 1.5, 2.0):
        e = tsuji_restitution(zeta, clamp)
        assert e == pytest.approx(oracle.tsuji_restitution(zeta, clamp), rel=rel, abs=1e-14)
    if clamp:
        for zeta in (3.0, 10.0):
            assert tsuji_restitution(zeta, True) == pytest.approx(
                oracle.tsuji_restitution(zeta, True), rel=rel)
    else:  # overdamped: the attraction holds the bodies together
        assert tsuji_restitution(3.0) == oracle.tsuji_restitution(3.0) == 0.0


@pytest.mark.parametrize("clamp", [False, True])
def test_damping_for_restitution_matches_the_brent_oracle(clamp):
    for e in (0.1, 0.5, 0.9):
        zeta = tsuji_damping_for_restitution(e, clamp)
        # the core's zeta realises e in the oracle's integration ...
        assert oracle.tsuji_restitution(zeta, clamp) == pytest.approx(
            e, rel=1e-10 if not clamp else 5e-9)
        # ... and is the oracle's root (the clamped e(zeta) is flat: 3e-9 in e is 2e-8 in zeta)
        assert zeta == pytest.approx(oracle.tsuji_damping_for_restitution(e, clamp),
                                     rel=1e-9 if not clamp else 5e-8)
    assert tsuji_damping_for_restitution(1.0, clamp) == 0.0


@pytest.mark.parametrize("clamp", [False, True])
@pytest.mark.parametrize("e", [0.1, 0.5, 0.9])
def test_restitution_recovered_by_a_damped_impact(e, clamp):
    """Tsuji damping calibrated in dimensionless form gives the same restitution in a real
    glass impact at any speed (scale invariance of the damped Hertz oscillator)."""
    a = body(shell=False)
    zeta = tsuji_damping_for_restitution(e, clamp)
    for v in (0.02, 1.0):
        imp = oracle.damped_hertz_impact(a, a, v, zeta=zeta, clamp=clamp)
        assert imp.restitution == pytest.approx(e, abs=2e-6)


def test_clamping_changes_the_realised_restitution():
    """Documented effect: with the damping tuned for an unclamped force, clamping F >= 0
    raises the realised restitution (e.g. 0.5 -> 0.550)."""
    zeta = tsuji_damping_for_restitution(0.5)
    e_clamped = tsuji_restitution(zeta, clamp=True)
    assert 0.54 < e_clamped < 0.56


def test_core_functions_take_the_python_argument_order():
    """Same name, same argument names and order in demfem.contact and demfem._core."""
    assert list(inspect.signature(rayleigh_time_step).parameters) == ["radius", "E", "nu",
                                                                       "density"]
    assert core.rayleigh_time_step(radius=0.01, E=45e9, nu=0.22, density=2230.0) == \
        pytest.approx(rayleigh_time_step(radius=0.01, E=45e9, nu=0.22, density=2230.0),
                      rel=1e-14)
    d = np.array([1e-6, 2e-6])
    np.testing.assert_allclose(core.normal_force(overlap=d, model="hertz", k_h=1e9)[0],
                               normal_force(overlap=d, model="hertz", k_h=1e9), rtol=1e-14)


def test_hertz_impact_duration_is_the_bodies_contact_duration():
    a = body(shell=False)
    k_h = hertz_stiffness(a.radius, a.radius, a.E, a.nu, a.E, a.nu)
    assert core.hertz_impact_duration(k_h, a.mass / 2, 0.2) == pytest.approx(
        hertz_contact_duration(a, a, 0.2), rel=1e-9)


def test_rayleigh_step_matches_the_closed_form():
    s = CART.equivalent_sphere()
    m = CART.material
    py = rayleigh_time_step(s.radius, m.E, m.nu, m.density)
    assert py == pytest.approx(oracle.rayleigh_time_step(s.radius, m.E, m.nu, m.density),
                               rel=1e-14)
    # about 0.1-0.2 of the sphere's P-wave transit time, as is usual for glass
    assert 5e-6 < py < 2e-5


def test_k_eq_and_linear_are_series():
    a = body()
    v = 0.2
    assert 1 / k_eq(a, a, v) == pytest.approx(2 / a.k_reissner + 1 / k_linear(a, a, v), rel=1e-14)
    # no shell: k_eq is k_lin
    s = body(shell=False)
    assert k_eq(s, s, v) == pytest.approx(k_linear(s, s, v), rel=1e-15)


def test_stiffnesses_match_closed_forms():
    for E, nu, t, R in ((45e9, 0.22, 1.1e-3, 5.25e-3), (1e6, -0.9, 1e-6, 1.0)):
        assert reissner_stiffness(E, nu, t, R) == pytest.approx(
            oracle.reissner_stiffness(E, nu, t, R), rel=1e-14)
    r_star = oracle.effective_radius(0.008, math.inf)
    e_star = oracle.effective_modulus(45e9, 0.22, math.inf, 0.0)
    assert hertz_stiffness(0.008, math.inf, 45e9, 0.22, math.inf, 0.0) == pytest.approx(
        4 / 3 * math.sqrt(r_star) * e_star, rel=1e-15)
    assert body().k_reissner == pytest.approx(
        oracle.reissner_stiffness(45e9, CART.material.nu, CART.wall_thickness,
                                  CART.body_mid_radius), rel=1e-14)
    assert math.isinf(body(shell=False).k_reissner)


def test_the_front_holds_no_second_implementation():
    """demfem.contact computes through the core: no scipy root finder or integrator."""
    import ast

    tree = ast.parse(inspect.getsource(contact))
    imported = {a.name.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.Import)
                for a in n.names}
    imported |= {(n.module or "").split(".")[0] for n in ast.walk(tree)
                 if isinstance(n, ast.ImportFrom)}
    assert "scipy" not in imported
    assert not hasattr(contact, "damped_hertz_impact")
    assert "damped_hertz_impact" not in contact.__all__


@pytest.mark.parametrize("call, field", [
    (lambda: reissner_stiffness(-1.0, 0.2, 1e-3, 5e-3), "E"),
    (lambda: reissner_stiffness(1e9, 0.5, 1e-3, 5e-3), "nu"),
    (lambda: reissner_stiffness(1e9, 0.2, 0.0, 5e-3), "t"),
    (lambda: reissner_stiffness(1e9, 0.2, 5e-3, 5e-3), "t"),
    (lambda: ContactBody(1.0, 0.01, 1e9, 0.2, 0.02, 0.01), "shell_thickness"),
    (lambda: ContactBody(1.0, 0.01, 1e9, 0.2, -1e-3, 0.01), "shell_thickness"),
    (lambda: ContactBody(-1.0, 0.01, 1e9, 0.2), "mass"),
    (lambda: ContactBody(1.0, 0.01, float("nan"), 0.2), "E"),
    (lambda: max_contact_force(body(), body(), -0.1), "v_rel"),
    (lambda: max_contact_force(body(), body(), float("nan")), "v_rel"),
    (lambda: max_contact_force(body(), body(), float("inf")), "v_rel"),
    (lambda: max_contact_force(body(), body(), 0.2, "elastic"), "model"),
    (lambda: tsuji_damping_for_restitution(1.5), "restitution"),
    (lambda: tsuji_damping_for_restitution(0.0, True), "restitution"),
    (lambda: tsuji_restitution(-1.0), "zeta"),
    (lambda: tsuji_restitution(float("inf")), "zeta"),
    (lambda: effective_modulus(45e9, 0.2, float("nan"), 0.2), "E2"),
    (lambda: effective_modulus(0.0, 0.2, 45e9, 0.2), "E1"),
    (lambda: effective_modulus(45e9, 0.2, 45e9, 0.5), "nu2"),
    (lambda: effective_radius(0.01, -1.0), "R2"),
    (lambda: effective_radius(float("inf"), 0.01), "R1"),
    (lambda: effective_mass(0.01, 0.0), "m2"),
    (lambda: hertz_stiffness(0.01, 0.01, 45e9, 0.2, -1.0, 0.2), "E2"),
    (lambda: normal_force(np.array([1e-6]), "hertz_reissner", k_h=1e9), "k_r"),
    (lambda: normal_force(np.array([1e-6]), "hertz", k_h=0.0), "k_h"),
    (lambda: normal_force(np.array([np.nan]), "hertz", k_h=1e9), "overlap"),
    (lambda: normal_force(np.array([1e-6]), "spring", k=1.0), "model"),
    (lambda: hertz_contact_duration(body(), body(), 0.0), "v_rel"),
    (lambda: k_linear(body(), body(), 1e-13), "v_rel"),
    (lambda: rayleigh_time_step(0.01, 45e9, 0.2, 0.0), "density"),
    (lambda: rayleigh_time_step(1.0, 5e-324, 0.0, 1.0), "E"),
    (lambda: core.effective_modulus(45e9, 0.2, float("nan"), 0.2), "E2"),
    (lambda: core.effective_radius(-1.0, 0.01), "R1"),
    (lambda: core.effective_mass(0.01, float("nan")), "m2"),
    (lambda: core.hertz_stiffness(0.0, 45e9), "R_star"),
    (lambda: core.reissner_stiffness(45e9, 0.2, 5e-3, 5e-3), "t"),
    (lambda: core.series_stiffness(float("nan"), 1.0), "k1"),
    (lambda: core.series_stiffness(1.0, -1.0), "k2"),
    (lambda: core.linearized_hertz_stiffness(0.01, float("inf"), 0.01, 0.2), "E_star"),
    (lambda: core.linearized_hertz_stiffness(0.01, 45e9, 0.01, -0.2), "v_rel"),
    (lambda: core.hertz_max_overlap(0.0, 0.01, 0.2), "k_h"),
    (lambda: core.hertz_max_overlap(1e9, 0.01, float("nan")), "v_rel"),
    (lambda: core.normal_force(np.array([1e-6]), "hertz", k_h=-1.0), "k_H"),
    (lambda: core.rayleigh_time_step(0.01, 45e9, 0.5, 2230.0), "nu"),
    (lambda: core.rayleigh_time_step(radius=0.01, E=45e9, nu=0.2, density=-1.0), "density"),
])
def test_bad_input_names_the_field(call, field):
    with pytest.raises(InvalidParameterError, match=field) as exc:
        call()
    assert isinstance(exc.value, ValueError)
