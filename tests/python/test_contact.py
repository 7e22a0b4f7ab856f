"""Contact laws (eqs. 1–15) against closed forms, and Python against the Rust core."""
import math

import numpy as np
import pytest

import demfem._core as core
from demfem.cartridge import Cartridge
from demfem.contact import (
    ContactBody,
    damped_hertz_impact,
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
    """Integrating an undamped Hertz impact gives the closed-form maximum force, overlap,
    duration and an elastic rebound."""
    a = body(shell=False)
    for v in (0.01, 0.2, 2.0):
        imp = damped_hertz_impact(a, a, v, restitution=1.0, n_out=4000)
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
            # eq. 12 holds at the root
            k_h = hertz_stiffness(a.radius, a.radius, E, a.nu, E, a.nu)
            m = a.mass / 2
            lhs = 2 * f**2 / a.k_reissner + 0.8 * f ** (5 / 3) / k_h ** (2 / 3)
            assert lhs == pytest.approx(m * v * v, rel=1e-12)
            fs.append(f)
        fs = np.array(fs)
        assert np.all(np.diff(fs) > 0)           # monotonic in v_rel
        assert np.all(fs > prev_e)               # monotonic in E
        prev_e = fs


def test_python_and_rust_laws_agree():
    a = body()
    k_h = hertz_stiffness(a.radius, a.radius, a.E, a.nu, a.E, a.nu)
    k_r = a.k_reissner / 2
    d = np.logspace(-10, -4, 61)
    for model, kw in (("hertz", {"k_h": k_h}), ("linear", {"k": k_r}),
                      ("hertz_reissner", {"k_h": k_h, "k_r": k_r})):
        f_py = normal_force(d, model, **kw)
        f_rs, stiff = core.normal_force(d, model, **kw)
        np.testing.assert_allclose(f_rs, f_py, rtol=1e-12, atol=0)
        # the tangent stiffness is the derivative of the force (central difference check)
        h = d * 1e-6
        fd = (normal_force(d + h, model, **kw) - normal_force(d - h, model, **kw)) / (2 * h)
        np.testing.assert_allclose(stiff, fd, rtol=1e-6)
    for v in (1e-4, 0.2, 10.0):
        for model, kw in (("hertz", {"k_h": k_h}), ("hertz_reissner", {"k_h": k_h, "k_r": k_r})):
            py = max_contact_force(a, a, v, "hertz" if model == "hertz" else "hertz_reissner")
            rs = core.max_impact_force(a.mass / 2, v, model, **kw)
            assert rs == pytest.approx(py, rel=1e-12)


def test_restitution_python_and_rust_agree():
    for zeta in (0.05, 0.5, 1.5):
        assert core.tsuji_restitution(zeta) == pytest.approx(tsuji_restitution(zeta), rel=1e-9)
        assert core.tsuji_restitution(zeta, clamp=True) == pytest.approx(
            tsuji_restitution(zeta, clamp=True), rel=1e-7)


@pytest.mark.parametrize("clamp", [False, True])
@pytest.mark.parametrize("e", [0.1, 0.5, 0.9])
def test_restitution_recovered_by_a_damped_impact(e, clamp):
    """Tsuji damping calibrated in dimensionless form gives the same restitution in a real
    glass impact at any speed (scale invariance of the damped Hertz oscillator)."""
    a = body(shell=False)
    for v in (0.02, 1.0):
        imp = damped_hertz_impact(a, a, v, restitution=e, clamp=clamp)
        assert imp.restitution == pytest.approx(e, abs=2e-6)


def test_clamping_changes_the_realised_restitution():
    """Documented effect: with the damping tuned for an unclamped force, clamping F >= 0
    raises the realised restitution (e.g. 0.5 -> 0.550)."""
    zeta = tsuji_damping_for_restitution(0.5)
    e_clamped = tsuji_restitution(zeta, clamp=True)
    assert 0.54 < e_clamped < 0.56


def test_core_functions_take_the_python_argument_order():
    """Same name, same argument names and order in demfem.contact and demfem._core."""
    import inspect

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


def test_rayleigh_step_and_core_agree():
    s = CART.equivalent_sphere()
    m = CART.material
    py = rayleigh_time_step(s.radius, m.E, m.nu, m.density)
    assert core.rayleigh_time_step(s.radius, m.E, m.nu, m.density) == pytest.approx(py, rel=1e-14)
    # about 0.1-0.2 of the sphere's P-wave transit time, as is usual for glass
    assert 5e-6 < py < 2e-5


def test_k_eq_and_linear_are_series():
    a = body()
    v = 0.2
    assert 1 / k_eq(a, a, v) == pytest.approx(2 / a.k_reissner + 1 / k_linear(a, a, v), rel=1e-14)


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
    (lambda: core.normal_force(np.array([1e-6]), "hertz", k_h=-1.0), "k_H"),
    (lambda: core.rayleigh_time_step(0.01, 45e9, 0.5, 2230.0), "nu"),
    (lambda: core.rayleigh_time_step(radius=0.01, E=45e9, nu=0.2, density=-1.0), "density"),
])
def test_bad_input_names_the_field(call, field):
    with pytest.raises(InvalidParameterError, match=field) as exc:
        call()
    assert isinstance(exc.value, ValueError)
