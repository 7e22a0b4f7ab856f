"""demfem.risk: Weibull weakest-link, slow crack growth and the per-cartridge combination,
each checked against a closed form."""
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from demfem.errors import InvalidParameterError, ShapeError
from demfem.risk import (
    INNER_SURFACE,
    OUTER_SURFACE,
    RANGES,
    SCG_BOROSILICATE,
    SCG_SODA_LIME,
    SlowCrackGrowth,
    SurfaceStrength,
    cartridge_failure_probability,
    constant_pulse_equivalent_stress,
    effective_area,
    equivalent_static_stress,
    exceeds_threshold,
    expected_broken_per_hour,
    failure_probability,
    half_sine_equivalent_stress,
    risk_of_rupture,
    scale_strength,
    stress_rate_test_reference_time,
    utilisation,
    weibull_strength_at_area,
)

M, S0, A0 = 6.0, 70e6, 1e-4


# --- Weibull weakest link ------------------------------------------------------------------

@pytest.mark.parametrize("n_elements", [1, 7, 1000])
def test_characteristic_stress_over_reference_area_gives_one_minus_inv_e(n_elements):
    stress = np.full(n_elements, S0)
    area = np.full(n_elements, A0 / n_elements)
    p = failure_probability(stress, area, M, S0, A0)
    assert p == pytest.approx(1.0 - math.exp(-1.0), rel=1e-13)
    assert risk_of_rupture(stress, area, M, S0, A0) == pytest.approx(1.0, rel=1e-13)


@pytest.mark.parametrize("m", [1.0, 5.0, 10.0, 20.0])
def test_effective_area_of_linear_gradient_is_area_over_m_plus_1(m):
    total, n = 2e-4, 20000
    x = (np.arange(n) + 0.5) / n  # element midpoints, σ from 0 to σ_max
    stress = 120e6 * x
    area = np.full(n, total / n)
    a_eff = effective_area(stress, area, m)
    assert a_eff == pytest.approx(total / (m + 1.0), rel=0.01)
    # the effective area reproduces the probability at the peak stress
    p = failure_probability(stress, area, m, S0, A0)
    smax = stress.max()
    assert p == pytest.approx(-math.expm1(-(a_eff / A0) * (smax / S0) ** m), rel=1e-12)


def test_effective_area_of_gaussian_spot_is_2_pi_w2_over_m():
    w, h, m = 1e-3, 5e-5, 10.0
    x = np.arange(-160, 161) * h  # element centres, one at the peak
    X, Y = np.meshgrid(x, x)
    stress = 90e6 * np.exp(-(X**2 + Y**2).ravel() / (2 * w**2))
    a_eff = effective_area(stress, np.full(stress.size, h * h), m)
    assert a_eff == pytest.approx(2 * math.pi * w**2 / m, rel=1e-3)


def test_compressive_stresses_contribute_nothing():
    stress = np.array([50e6, 30e6])
    area = np.array([2e-5, 3e-5])
    p = failure_probability(stress, area, M, S0, A0)
    p_more = failure_probability(np.r_[stress, -500e6, 0.0], np.r_[area, 1.0, 1.0], M, S0, A0)
    assert p_more == p
    assert failure_probability([-1e9, -1.0, 0.0], [1.0, 1.0, 1.0], M, S0, A0) == 0.0
    assert effective_area([-1e9, 0.0], [1.0, 1.0], M) == 0.0
    # compressive principal stresses are dropped too
    pp = failure_probability(None, area, M, S0, A0,
                             principal_stresses=np.c_[stress, [-80e6, -10e6]])
    assert pp == pytest.approx(p, rel=1e-14)


def test_pia_with_zero_second_principal_equals_uniaxial():
    rng = np.random.default_rng(1)
    s1 = rng.uniform(-20e6, 90e6, 50)
    area = rng.uniform(1e-7, 1e-5, 50)
    p_uni = failure_probability(s1, area, M, S0, A0)
    p_pia = failure_probability(None, area, M, S0, A0, principal_stresses=np.c_[s1, 0 * s1])
    assert p_pia == pytest.approx(p_uni, rel=1e-13)


def test_pia_equal_biaxial_equals_uniaxial_at_doubled_area():
    s = np.array([40e6, 60e6, 75e6])
    area = np.array([1e-5, 2e-5, 5e-6])
    p_biax = failure_probability(s, area, M, S0, A0, principal_stresses=np.c_[s, s])
    p_uni_2a = failure_probability(s, 2 * area, M, S0, A0)
    assert p_biax == pytest.approx(p_uni_2a, rel=1e-13)
    # closed form for one element: 1 − exp(−2 (A/A0)(σ/σ0)^m)
    one = failure_probability(None, [A0], M, S0, A0, principal_stresses=[[S0, S0]])
    assert one == pytest.approx(1.0 - math.exp(-2.0), rel=1e-13)
    # the maximum-principal criterion counts one of the two
    p_max = failure_probability(None, area, M, S0, A0, principal_stresses=np.c_[s, s],
                                criterion="max_principal")
    assert p_max == pytest.approx(failure_probability(s, area, M, S0, A0), rel=1e-13)
    # a consistent stress argument is accepted alongside the principal stresses
    assert failure_probability(s, area, M, S0, A0, principal_stresses=np.c_[s, s]) == p_biax


@pytest.mark.parametrize("m", [3.0, 6.0, 12.0])
@pytest.mark.parametrize("p", [1e-6, 0.01, 0.5])
def test_size_effect_doubling_area_scales_strength_by_2_pow_minus_1_over_m(m, p):
    a = 3e-5
    s1 = weibull_strength_at_area(a, m, S0, A0, p)
    s2 = weibull_strength_at_area(2 * a, m, S0, A0, p)
    assert s2 / s1 == pytest.approx(2.0 ** (-1.0 / m), rel=1e-13)
    assert failure_probability([s1], [a], m, S0, A0) == pytest.approx(p, rel=1e-10)
    assert failure_probability([s2], [2 * a], m, S0, A0) == pytest.approx(p, rel=1e-10)
    assert scale_strength(s1, a, 2 * a, m) == pytest.approx(s2, rel=1e-13)
    assert weibull_strength_at_area(A0, m, S0, A0) == pytest.approx(S0, rel=1e-13)


def test_tiny_and_huge_probabilities_are_accurate_and_saturate():
    # R = (A/A0)(σ/σ0)^m = 1e-20: P = 1e-20 to full precision, no underflow to 0
    sigma = S0 * (1e-20) ** (1.0 / M)
    assert failure_probability([sigma], [A0], M, S0, A0) == pytest.approx(1e-20, rel=1e-12)
    with np.errstate(all="raise"):
        assert failure_probability([1e12], [1.0], 50.0, 1e6, 1e-6) == 1.0


def test_surface_strength_wraps_the_functions():
    s = np.array([50e6, 80e6])
    a = np.array([1e-6, 2e-6])
    assert OUTER_SURFACE.failure_probability(s, a) == failure_probability(
        s, a, OUTER_SURFACE.weibull_modulus, OUTER_SURFACE.characteristic_strength,
        OUTER_SURFACE.reference_area)
    assert OUTER_SURFACE.effective_area(s, a) == effective_area(s, a, OUTER_SURFACE.weibull_modulus)
    assert INNER_SURFACE.strength_at_area(INNER_SURFACE.reference_area) == pytest.approx(
        INNER_SURFACE.characteristic_strength)
    with pytest.raises(AttributeError):
        OUTER_SURFACE.weibull_modulus = 1.0  # frozen


def test_defaults_are_documented_planning_assumptions_within_their_ranges():
    for name, surf in (("outer", OUTER_SURFACE), ("inner", INNER_SURFACE)):
        assert "planning assumption" in surf.source
        lo, hi = RANGES[f"{name}.weibull_modulus"]
        assert lo <= surf.weibull_modulus <= hi
        lo, hi = RANGES[f"{name}.characteristic_strength"]
        assert lo <= surf.characteristic_strength <= hi
    assert INNER_SURFACE.characteristic_strength > OUTER_SURFACE.characteristic_strength
    lo, hi = RANGES["soda_lime.crack_growth_exponent"]
    assert lo <= SCG_SODA_LIME.crack_growth_exponent <= hi
    lo, hi = RANGES["borosilicate.crack_growth_exponent"]
    assert lo <= SCG_BOROSILICATE.crack_growth_exponent <= hi
    assert SCG_BOROSILICATE.crack_growth_exponent > SCG_SODA_LIME.crack_growth_exponent


# --- slow crack growth ----------------------------------------------------------------------

@pytest.mark.parametrize("n", [16.0, 25.0, 40.5])
def test_constant_pulse_equivalent_stress(n):
    sigma, tau, t_ref = 90e6, 2e-3, 1.0
    expected = sigma * (tau / t_ref) ** (1.0 / n)
    sampled = equivalent_static_stress([sigma, sigma, sigma], [0.0, 0.5e-3, tau], n, t_ref)
    assert sampled == pytest.approx(expected, rel=1e-13)
    assert constant_pulse_equivalent_stress(sigma, tau, n, t_ref) == pytest.approx(expected,
                                                                                  rel=1e-14)
    # a pulse as long as the reference time is its own equivalent
    assert constant_pulse_equivalent_stress(sigma, t_ref, n, t_ref) == pytest.approx(sigma)


@pytest.mark.parametrize("n", [3.0, 16.0, 25.0, 33.3, 80.0])
def test_half_sine_closed_form_matches_quadrature(n):
    peak, tau, t_ref = 120e6, 1.5e-4, 2.0
    integral, _ = quad(lambda t: math.sin(math.pi * t / tau) ** n, 0.0, tau,
                       epsabs=0.0, epsrel=1e-13, limit=200)  # ∫ (σ/σ_p)^n dt, no overflow
    expected = peak * (integral / t_ref) ** (1.0 / n)
    assert half_sine_equivalent_stress(peak, tau, n, t_ref) == pytest.approx(expected, rel=1e-10)
    # and the sampled integrator agrees (piecewise-linear, fine sampling)
    t = np.linspace(0.0, tau, 40001)
    sampled = equivalent_static_stress(peak * np.sin(np.pi * t / tau), t, n, t_ref)
    assert sampled == pytest.approx(expected, rel=1e-6)
    assert SlowCrackGrowth(n, t_ref).half_sine(peak, tau) == half_sine_equivalent_stress(
        peak, tau, n, t_ref)


def test_equivalent_stress_is_exact_for_linear_segments_through_zero():
    n, sigma, tau, t_ref = 20.0, 50e6, 1e-3, 0.1
    # ramp from −σ to +σ: only the second half is tensile, ∫ = σ^n (τ/2) / (n+1)
    got = equivalent_static_stress([-sigma, sigma], [0.0, tau], n, t_ref)
    assert got == pytest.approx(sigma * (tau / 2 / (n + 1) / t_ref) ** (1 / n), rel=1e-13)
    # a constant-stress-rate test to σ_f at t_f is equivalent to σ_f over t_f/(n+1)
    t_f = 35.0
    t_ref_test = stress_rate_test_reference_time(t_f, n)
    assert equivalent_static_stress([0.0, 70e6], [0.0, t_f], n, t_ref_test) == pytest.approx(
        70e6, rel=1e-13)
    # columns are independent histories; compressive histories give 0
    hist = np.array([[0.0, -1e6, sigma], [sigma, -2e6, sigma]])
    out = equivalent_static_stress(hist, [0.0, tau], n, t_ref)
    assert out.shape == (3,)
    assert out[1] == 0.0
    assert out[2] == pytest.approx(constant_pulse_equivalent_stress(sigma, tau, n, t_ref))


def test_near_constant_segments_use_the_series_accurately():
    n, t_ref = 30.0, 1.0
    s = np.array([100e6, 100e6 * (1 + 1e-5)])
    # exact ∫: τ (b^{n+1} − a^{n+1}) / ((n+1)(b−a)), evaluated in high precision by hand
    a, b = 1.0, 1.0 + 1e-5
    exact = sum(a ** (n - k) * b ** k for k in range(int(n) + 1)) / (n + 1)  # geometric sum
    got = equivalent_static_stress(s, [0.0, 1.0], n, t_ref)
    assert got == pytest.approx(100e6 * (1 + 1e-5) * (exact / b ** n) ** (1 / n), rel=1e-13)


# --- threshold ------------------------------------------------------------------------------

def test_threshold():
    assert exceeds_threshold([10e6, 95e6, -200e6], 90e6)
    assert not exceeds_threshold([10e6, 90e6, -200e6], 90e6)
    assert utilisation([-5e6], 90e6) == 0.0
    assert utilisation([45e6], 90e6) == pytest.approx(0.5)


# --- combination ----------------------------------------------------------------------------

def test_product_combination_matches_direct_formula():
    p = np.array([0.1, 0.25, 0.0, 0.03])
    assert cartridge_failure_probability(p) == pytest.approx(1 - np.prod(1 - p), rel=1e-14)
    assert cartridge_failure_probability([]) == 0.0
    assert cartridge_failure_probability([0.2, 1.0]) == 1.0
    grid = np.array([[0.1, 0.2], [0.0, 0.5]])
    np.testing.assert_allclose(cartridge_failure_probability(grid, axis=1),
                               1 - np.prod(1 - grid, axis=1), rtol=1e-14)
    # risks of independent events add: the same rule as the weakest-link sum
    r1, r2 = 0.3, 0.05
    pc = cartridge_failure_probability([-math.expm1(-r1), -math.expm1(-r2)])
    assert pc == pytest.approx(-math.expm1(-(r1 + r2)), rel=1e-14)


def test_product_combination_is_stable_at_1e_minus_15():
    p, k = 1e-15, 1000
    assert cartridge_failure_probability([p]) == pytest.approx(p, rel=1e-15)
    expected = k * p - k * (k - 1) / 2 * p ** 2  # binomial series, exact to 1e-27 relative
    assert cartridge_failure_probability(np.full(k, p)) == pytest.approx(expected, rel=1e-13)
    # the direct formula loses the digits this guards against
    assert abs((1 - (1 - p)) - p) / p > 1e-4


def test_expected_broken_per_hour():
    assert expected_broken_per_hour(1e-6, 12000.0) == pytest.approx(0.012)
    assert expected_broken_per_hour([0.0, 2e-6], 12000.0) == pytest.approx(0.012)
    assert expected_broken_per_hour([], 12000.0) == 0.0


# --- validation -----------------------------------------------------------------------------

GOOD = dict(stress=[50e6], area=[1e-5], weibull_modulus=M, characteristic_strength=S0,
            reference_area=A0)


@pytest.mark.parametrize("change, field", [
    ({"weibull_modulus": 0.0}, "weibull_modulus"),
    ({"weibull_modulus": -2.0}, "weibull_modulus"),
    ({"weibull_modulus": float("nan")}, "weibull_modulus"),
    ({"characteristic_strength": -70e6}, "characteristic_strength"),
    ({"characteristic_strength": 0.0}, "characteristic_strength"),
    ({"reference_area": 0.0}, "reference_area"),
    ({"reference_area": float("inf")}, "reference_area"),
    ({"area": [-1e-5]}, "area"),
    ({"area": [0.0]}, "area"),
    ({"area": [float("inf")]}, "area"),
    ({"stress": [float("nan")]}, "stress"),
    ({"stress": [float("inf")]}, "stress"),
    ({"stress": ["big"]}, "stress"),
    ({"stress": [1e6, 2e6]}, "stress"),          # mismatched with area
    ({"stress": [[1e6]]}, "stress"),             # wrong dimensionality
    ({"stress": None}, "stress"),
])
def test_failure_probability_rejects_bad_parameters(change, field):
    kwargs = {**GOOD, **change}
    with pytest.raises(InvalidParameterError, match=field) as exc:
        failure_probability(**kwargs)
    assert isinstance(exc.value, ValueError)


@pytest.mark.parametrize("call, field", [
    (lambda: failure_probability(None, [1e-5, 1e-5], M, S0, A0,
                                 principal_stresses=[[1e6, 0.0]]), "principal_stresses"),
    (lambda: failure_probability(None, [1e-5], M, S0, A0,
                                 principal_stresses=[[1e6, 0.0, 0.0, 0.0]]), "principal_stresses"),
    (lambda: failure_probability(None, [1e-5], M, S0, A0,
                                 principal_stresses=[[float("nan"), 0.0]]), "principal_stresses"),
    (lambda: failure_probability([2e6], [1e-5], M, S0, A0,
                                 principal_stresses=[[1e6, 0.0]]), "stress"),
    (lambda: failure_probability([1e6], [1e-5], M, S0, A0, criterion="tresca"), "criterion"),
    (lambda: effective_area([1e6], [1e-5], 0.0), "weibull_modulus"),
    (lambda: weibull_strength_at_area(1e-5, M, S0, A0, probability=1.0), "probability"),
    (lambda: weibull_strength_at_area(-1e-5, M, S0, A0), "area"),
    (lambda: scale_strength(-1.0, 1e-5, 2e-5, M), "strength"),
    (lambda: SurfaceStrength(0.0, S0, A0, "x"), "weibull_modulus"),
    (lambda: SurfaceStrength(M, -S0, A0, "x"), "characteristic_strength"),
    (lambda: SlowCrackGrowth(2.0, 1.0), "crack_growth_exponent"),
    (lambda: SlowCrackGrowth(16.0, 0.0), "reference_time"),
    (lambda: equivalent_static_stress([1e6, 1e6], [0.0, 0.0], 16.0, 1.0), "time"),
    (lambda: equivalent_static_stress([1e6, 1e6, 1e6], [0.0, 1.0], 16.0, 1.0), "stress"),
    (lambda: equivalent_static_stress([1e6], [0.0], 16.0, 1.0), "time"),
    (lambda: equivalent_static_stress([1e6, float("nan")], [0.0, 1.0], 16.0, 1.0), "stress"),
    (lambda: half_sine_equivalent_stress(1e6, -1e-3, 16.0, 1.0), "duration"),
    (lambda: half_sine_equivalent_stress(1e6, 1e-3, 1.5, 1.0), "crack_growth_exponent"),
    (lambda: stress_rate_test_reference_time(0.0, 16.0), "time_to_failure"),
    (lambda: exceeds_threshold([1e6], 0.0), "threshold"),
    (lambda: cartridge_failure_probability([0.5, 1.5]), "p_collisions"),
    (lambda: cartridge_failure_probability([float("nan")]), "p_collisions"),
    (lambda: expected_broken_per_hour([0.1], -5.0), "throughput_per_hour"),
    (lambda: expected_broken_per_hour([-0.1], 5.0), "p_per_cartridge"),
])
def test_risk_functions_reject_bad_parameters(call, field):
    with pytest.raises(InvalidParameterError, match=field):
        call()


def test_shape_mismatch_is_also_a_shape_error():
    with pytest.raises(ShapeError):
        failure_probability([1e6, 2e6], [1e-5], M, S0, A0)


# --- properties -----------------------------------------------------------------------------

finite_stress = st.floats(-2e9, 2e9, allow_nan=False)
positive_area = st.floats(1e-10, 1e-2)


@settings(max_examples=300, deadline=None)
@given(
    data=st.lists(st.tuples(finite_stress, positive_area, st.floats(0.0, 5e8)),
                  min_size=1, max_size=30),
    m=st.floats(0.5, 60.0),
    sigma0=st.floats(1e6, 1e10),
    a0=st.floats(1e-8, 1.0),
)
def test_probability_in_unit_interval_and_monotone_in_stress(data, m, sigma0, a0):
    stress = np.array([d[0] for d in data])
    area = np.array([d[1] for d in data])
    increase = np.array([d[2] for d in data])
    p = failure_probability(stress, area, m, sigma0, a0)
    p_up = failure_probability(stress + increase, area, m, sigma0, a0)
    assert 0.0 <= p <= 1.0 and 0.0 <= p_up <= 1.0
    assert p_up >= p * (1.0 - 1e-12)
    # PIA with a second principal stress never lowers the probability
    p_pia = failure_probability(None, area, m, sigma0, a0,
                                principal_stresses=np.c_[stress, np.minimum(increase, stress)])
    assert p_pia >= p * (1.0 - 1e-12)


def test_docs_example_runs():
    import pathlib
    import re

    doc = pathlib.Path(__file__).resolve().parents[2] / "docs" / "risk.md"
    if not doc.exists():
        pytest.skip("docs/risk.md not found")
    code = re.search(r"```python\n(.*?)```", doc.read_text(encoding="utf-8"), re.S).group(1)
    exec(compile(code, str(doc), "exec"), {})
