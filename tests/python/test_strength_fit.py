"""Users' own strength tests: ASTM C1239 maximum-likelihood fit (unbiasing factor, bounds,
censoring), effective areas of the standard tests (C1499 ring-on-ring, side compression,
burst), the strength file and ``demfem strength-fit``."""
import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import minimize

from demfem.cli import main
from demfem.errors import DemfemIOError, InvalidParameterError
from demfem.risk import SurfaceStrength, effective_area
from demfem.risk.specimen_area import (
    burst_effective_area,
    burst_stress,
    effective_area_of_test,
    ring_on_ring_effective_area,
    ring_on_ring_stress,
    ring_on_ring_stress_field,
    side_compression_effective_area,
    side_compression_stress,
    side_compression_stress_field,
)
from demfem.risk.strength_file import load_strength_file, read_strength_csv, write_strength_file
from demfem.risk.strength_fit import (
    fit_strength,
    pivot_samples,
    unbiasing_factor,
    weibull_mle,
)

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "strength_data.csv"
ROR = dict(load_ring_diameter=8e-3, support_ring_diameter=16e-3, specimen_diameter=20e-3,
           poisson_ratio=0.2)
ROR_ARGS = tuple(ROR.values())


def _neg_log_likelihood(params, x, censored):
    """−ln L of a two-parameter Weibull with right-censored survival terms, written out."""
    m, theta = math.exp(params[0]), math.exp(params[1])
    z = (x / theta) ** m
    failed = ~censored
    ll = np.sum(np.log(m / theta) + (m - 1) * np.log(x[failed] / theta) - z[failed])
    return -(ll - np.sum(z[censored]))


# --- maximum likelihood -------------------------------------------------------------------

@pytest.mark.parametrize("with_censoring", [False, True])
def test_mle_is_the_maximum_of_the_likelihood_found_independently(with_censoring):
    x, c = read_strength_csv(EXAMPLE)
    if not with_censoring:
        x, c = x[~c], c[~c]
    m, theta = weibull_mle(x, c)
    # the C1239 likelihood equations hold at the estimate
    w = x ** m
    assert np.sum(w * np.log(x)) / np.sum(w) - np.mean(np.log(x[~c])) - 1 / m == \
        pytest.approx(0.0, abs=1e-12)
    assert theta == pytest.approx((np.sum(w) / np.sum(~c)) ** (1 / m), rel=1e-12)
    # and a general-purpose optimiser on the log-likelihood finds the same point
    res = minimize(_neg_log_likelihood, [math.log(5.0), math.log(np.median(x))], args=(x, c),
                   method="Nelder-Mead", options={"xatol": 1e-10, "fatol": 1e-12,
                                                  "maxiter": 5000})
    assert res.success
    assert math.exp(res.x[0]) == pytest.approx(m, rel=1e-7)
    assert math.exp(res.x[1]) == pytest.approx(theta, rel=1e-8)


def test_mle_recovers_the_parameters_of_a_large_sample():
    rng = np.random.default_rng(11)
    x = 150e6 * rng.weibull(7.0, 20000)
    m, theta = weibull_mle(x)
    assert m == pytest.approx(7.0, rel=0.02)        # SE ≈ 0.78 m/√N = 0.55 %
    assert theta == pytest.approx(150e6, rel=0.004)


def test_censored_specimens_are_survivals_not_failures():
    """Two flaw populations competing in each specimen: fitting the first with the second's
    failures censored recovers it; counting them as failures does not."""
    rng = np.random.default_rng(3)
    a = 150e6 * rng.weibull(7.0, 6000)          # the population of interest
    b = 140e6 * rng.weibull(15.0, 6000)         # e.g. load-ring contact damage
    x, cens = np.minimum(a, b), b < a
    assert 0.2 < cens.mean() < 0.6
    m, theta = weibull_mle(x, cens)
    assert m == pytest.approx(7.0, rel=0.04) and theta == pytest.approx(150e6, rel=0.01)
    m_naive, theta_naive = weibull_mle(x)
    assert m_naive > 8.0 and theta_naive < 140e6


def test_a_specimen_censored_above_every_failure_raises_the_strength():
    x = np.array([100e6, 120e6, 130e6, 140e6, 150e6])
    m0, t0 = weibull_mle(x)
    m1, t1 = weibull_mle(np.append(x, 200e6), np.array([0, 0, 0, 0, 0, 1]))
    assert t1 > t0 and m1 < m0


# --- unbiasing factor and bounds ----------------------------------------------------------

def test_unbiasing_factor_is_close_to_the_published_table():
    # ASTM C1239's unbiasing factors (as recalled from the standard; Thoman, Bain & Antle
    # 1969 computed them by Monte Carlo): the seeded Monte Carlo here agrees within 0.01.
    published = {5: 0.700, 10: 0.859, 20: 0.931, 30: 0.955, 50: 0.973, 100: 0.987}
    for n, b in published.items():
        assert unbiasing_factor(n) == pytest.approx(b, abs=0.01)
    assert unbiasing_factor(10) == unbiasing_factor(10)      # seeded


def test_unbiasing_factor_makes_the_mean_modulus_unbiased():
    rng = np.random.default_rng(2024)
    n, m_true = 10, 7.0
    b = unbiasing_factor(n)
    m_hat = np.array([weibull_mle(150e6 * rng.weibull(m_true, n))[0] for _ in range(2500)])
    assert np.mean(m_hat) / m_true > 1.1                       # the ML estimate is biased
    assert np.mean(b * m_hat) / m_true == pytest.approx(1.0, abs=0.02)


def test_bounds_cover_the_true_parameters_at_the_stated_rate():
    rng = np.random.default_rng(42)
    hits_m = hits_s = 0
    k = 400
    for _ in range(k):
        f = fit_strength(150e6 * rng.weibull(7.0, 12))
        hits_m += f.bounds["m"][0] <= 7.0 <= f.bounds["m"][1]
        hits_s += f.bounds["sigma_theta_Pa"][0] <= 150e6 <= f.bounds["sigma_theta_Pa"][1]
    assert 0.85 <= hits_m / k <= 0.95 and 0.85 <= hits_s / k <= 0.95


def test_bounds_with_censoring_cover_approximately():
    """Specimens that did not break at the test's maximum load (170 MPa) are censored there;
    the bootstrap bounds cover close to the stated 90 %."""
    rng = np.random.default_rng(5)
    hits_m = hits_s = k = 0
    while k < 150:
        x = 150e6 * rng.weibull(7.0, 15)
        c = x > 170e6
        if c.sum() == 0 or (~c).sum() < 2:
            continue
        f = fit_strength(np.minimum(x, 170e6), c, n_simulations=1000, seed=k)
        k += 1
        hits_m += f.bounds["m"][0] <= 7.0 <= f.bounds["m"][1]
        hits_s += f.bounds["sigma_theta_Pa"][0] <= 150e6 <= f.bounds["sigma_theta_Pa"][1]
    assert 0.80 <= hits_m / k <= 0.97 and 0.80 <= hits_s / k <= 0.97


def test_complete_sample_pivots_do_not_depend_on_the_parameters():
    x = 150e6 * np.random.default_rng(1).weibull(7.0, 20)
    q1, t1 = pivot_samples(x, n_simulations=2000)
    q2, t2 = pivot_samples(3.0 * x ** 0.5, n_simulations=2000)
    assert np.array_equal(q1, q2) and np.array_equal(t1, t2)
    f = fit_strength(x, n_simulations=2000)
    assert f.bounds["m"][0] < f.m < f.bounds["m"][1]
    assert f.bounds["sigma_theta_Pa"][0] < f.sigma_theta_Pa < f.bounds["sigma_theta_Pa"][1]
    assert f == fit_strength(x, n_simulations=2000)           # seeded: reproducible


# --- effective areas -------------------------------------------------------------------------

def _ror_grid_area(m, criterion, n=1201):
    """Brute force: the plate field sampled on a Cartesian grid over the disc."""
    r_disc = ROR["specimen_diameter"] / 2
    h = 2 * r_disc / n
    xs = -r_disc + (np.arange(n) + 0.5) * h
    xx, yy = np.meshgrid(xs, xs)
    r = np.hypot(xx, yy).ravel()
    r = r[r <= r_disc]
    sr, st = ring_on_ring_stress_field(r, *ROR_ARGS)
    area = np.full(r.size, h * h)
    if criterion == "pia":
        return effective_area(None, area, m, principal_stresses=np.c_[sr, st])
    return effective_area(np.maximum(sr, st), area, m)


@pytest.mark.parametrize("criterion", ["max_principal", "pia"])
@pytest.mark.parametrize("m", [5.0, 7.0, 12.0])
def test_ring_on_ring_effective_area_against_integrating_the_field(m, criterion):
    a = ring_on_ring_effective_area(m, *ROR_ARGS, criterion=criterion)
    assert a == pytest.approx(_ror_grid_area(m, criterion), rel=3e-3)


def test_ring_on_ring_field_is_the_plate_solution():
    b, a, big_r, nu = 4e-3, 8e-3, 10e-3, 0.2
    s = (1 + nu) * math.log(a / b) + (1 - nu) * (a * a - b * b) / (2 * big_r ** 2)
    # the nominal stress is ASTM C1499's formula
    f, h = 500.0, 1e-3
    c1499 = 3 * f / (2 * math.pi * h * h) * ((1 - nu) * (0.016 ** 2 - 0.008 ** 2)
                                            / (2 * 0.020 ** 2) + (1 + nu) * math.log(2.0))
    assert ring_on_ring_stress(f, h, *ROR_ARGS) == pytest.approx(c1499, rel=1e-14)
    # equibiaxial inside the load ring; free edge; continuous at both rings
    sr, st = ring_on_ring_stress_field([0.0, 2e-3, b], *ROR_ARGS)
    assert np.allclose(sr, 1.0) and np.allclose(st, 1.0)
    assert ring_on_ring_stress_field(big_r, *ROR_ARGS)[0] == pytest.approx(0.0, abs=1e-14)
    for r0 in (b, a):
        lo = ring_on_ring_stress_field(r0 * (1 - 1e-9), *ROR_ARGS)
        hi = ring_on_ring_stress_field(r0 * (1 + 1e-9), *ROR_ARGS)
        assert np.allclose(lo, hi, atol=1e-7)
    # Kirchhoff plate: equilibrium d(r M_r)/dr − M_θ = r Q (r Q = −2 M_nom/s between the
    # rings, 0 elsewhere) and compatibility d[r (M_θ − ν M_r)]/dr = M_r − ν M_θ
    eps = 1e-8
    for r0, rq in ((5e-3, -2.0 / s), (7e-3, -2.0 / s), (9e-3, 0.0), (2e-3, 0.0)):
        (sr0, st0), (srp, stp), (srm, stm) = (ring_on_ring_stress_field(r, *ROR_ARGS)
                                              for r in (r0, r0 + eps, r0 - eps))
        d_eq = ((r0 + eps) * srp - (r0 - eps) * srm) / (2 * eps) - st0
        d_comp = ((r0 + eps) * (stp - nu * srp) - (r0 - eps) * (stm - nu * srm)) / (2 * eps)
        assert d_eq == pytest.approx(rq, abs=1e-6)
        assert d_comp == pytest.approx(sr0 - nu * st0, abs=1e-6)


def test_ring_on_ring_effective_area_limits():
    b = 4e-3
    disc = math.pi * b * b
    s = 1.2 * math.log(2.0) + 0.8 * 48e-6 / 200e-6
    for m in (1000.0, 4000.0):
        a = ring_on_ring_effective_area(m, *ROR_ARGS)
        # Laplace: the hoop stress falls at d(σ_θ/σ_nom)/dr = −2ν/(b s) beyond the load ring
        assert (a - disc) == pytest.approx(disc * s / (0.2 * m), rel=0.02)
        pia = ring_on_ring_effective_area(m, *ROR_ARGS, criterion="pia")
        # σ_r falls at −2/(b s): the radial term adds disc (1 + s/m)
        assert pia - a == pytest.approx(disc * (1 + s / m), rel=1e-3)
    areas = [ring_on_ring_effective_area(m, *ROR_ARGS) for m in (3, 5, 10, 20)]
    assert all(x > y for x, y in zip(areas, areas[1:]))


def test_side_compression_field_is_the_thin_ring_solution():
    d_o, t = 11.6e-3, 1.1e-3
    r = (d_o - t) / 2
    phi = np.linspace(0.0, math.pi / 2, 20001)
    inner = side_compression_stress_field(phi, d_o, t, "inner")
    outer = side_compression_stress_field(phi, d_o, t, "outer")
    bending = (inner - outer) / 2
    mu = math.pi * t / (12 * r)
    # Roark / Timoshenko: M = 0.3183 P R under the load, −0.1817 P R at the sides
    assert bending[0] == pytest.approx(1.0) and bending[-1] * 0.31831 == pytest.approx(
        -0.18169, rel=1e-4)
    # Castigliano: no rotation of the symmetric sections, ∫ M dφ = 0 over a quarter
    assert np.trapezoid(bending, phi) == pytest.approx(0.0, abs=1e-8)
    assert outer[-1] == pytest.approx(math.pi / 2 - 1 - mu)   # hoop compression P/2 at sides
    sigma = side_compression_stress(100.0, d_o, t, 0.02)
    assert sigma == pytest.approx(6 * 100.0 * r / (math.pi * 0.02 * t * t))


@pytest.mark.parametrize("surface", ["inner", "outer"])
@pytest.mark.parametrize("m", [5.0, 7.0, 12.0])
def test_side_compression_effective_area_against_integrating_the_field(m, surface):
    d_o, t, length = 11.6e-3, 1.1e-3, 0.03
    n_phi, n_z = 40000, 3
    phi = (np.arange(n_phi) + 0.5) * 2 * math.pi / n_phi
    radius = d_o / 2 - (t if surface == "inner" else 0.0)
    s = np.repeat(side_compression_stress_field(phi, d_o, t, surface), n_z)
    area = np.full(s.size, radius * 2 * math.pi / n_phi * length / n_z)
    brute = effective_area(s, area, m) * s.max() ** m          # relative to σ_nom, not σ_max
    got = side_compression_effective_area(m, d_o, t, length, surface=surface)
    assert got == pytest.approx(brute, rel=1e-6)
    if surface == "inner":   # Laplace: two load lines, σ falls as 1 − (π/2 + μ)|φ|
        big = side_compression_effective_area(3000.0, d_o, t, length)
        c = math.pi / 2 + math.pi * t / (12 * (d_o - t) / 2)
        assert big == pytest.approx(4 * length * (d_o / 2 - t) / (c * 3000.0), rel=2e-3)


def test_burst_effective_area_is_the_lame_field_over_the_surface():
    d_o, t, length, m = 11.6e-3, 1.1e-3, 0.04, 7.0
    r_o, r_i = d_o / 2, d_o / 2 - t
    p = 10e6
    hoop_in = burst_stress(p, d_o, t)
    assert hoop_in == pytest.approx(p * (r_o ** 2 + r_i ** 2) / (r_o ** 2 - r_i ** 2))
    assert burst_effective_area(m, d_o, t, length) == pytest.approx(2 * math.pi * r_i * length)
    hoop_out = 2 * p * r_i ** 2 / (r_o ** 2 - r_i ** 2)
    axial = p * r_i ** 2 / (r_o ** 2 - r_i ** 2)
    area = np.full(10, 2 * math.pi * r_o * length / 10)
    ps = np.tile([hoop_out, axial], (10, 1))
    brute = effective_area(None, area, m, principal_stresses=ps) * (hoop_out / hoop_in) ** m
    assert burst_effective_area(m, d_o, t, length, surface="outer", closed_ends=True,
                                criterion="pia") == pytest.approx(brute, rel=1e-12)
    assert burst_effective_area(m, d_o, t, length, surface="outer") == pytest.approx(
        2 * math.pi * r_o * length * (hoop_out / hoop_in) ** m)


def test_scaling_to_the_reference_area_reproduces_the_test():
    """σ_0 from the fit gives the fitted failure probability of the test specimen back."""
    x, c = read_strength_csv(EXAMPLE)
    geometry = {k + "_m" if k != "poisson_ratio" else k: v for k, v in ROR.items()}
    f = fit_strength(x, c, test="ring-on-ring", geometry=geometry)
    ss = f.to_surface_strength(1e-4)
    assert ss.weibull_modulus == f.m_unbiased
    a_eff = ring_on_ring_effective_area(f.m_unbiased, *ROR_ARGS)
    assert f.effective_area_m2 == pytest.approx(a_eff, rel=1e-12)
    # P of a specimen at σ_nom = σ_θ is 1 − 1/e with the material's parameters
    assert -math.expm1(-(a_eff / ss.reference_area) * (f.sigma_theta_Pa
                                                       / ss.characteristic_strength)
                       ** ss.weibull_modulus) == pytest.approx(1 - math.exp(-1))
    assert "ASTM C1239" in ss.source and "ring-on-ring" in ss.source


# --- bad input -------------------------------------------------------------------------------

@pytest.mark.parametrize("strength, censored, field", [
    ([150e6], None, "strength_Pa"),
    ([150e6, 140e6, 130e6], [0, 1, 1], "strength_Pa"),
    ([150e6, -140e6, 130e6], None, "strength_Pa[1]"),
    ([150e6, float("nan"), 130e6], None, "strength_Pa[1]"),
    ([150e6, 140e6, 130e6], [0, 2, 0], "censored[1]"),
    ([150e6, 150e6, 150e6], None, "strength_Pa"),
])
def test_bad_strength_data_is_refused_naming_the_field(strength, censored, field):
    with pytest.raises(InvalidParameterError, match=field.replace("[", r"\[")):
        fit_strength(strength, censored)


@pytest.mark.parametrize("call, field", [
    (lambda: ring_on_ring_effective_area(0.0, *ROR_ARGS), "weibull_modulus"),
    (lambda: side_compression_effective_area(-1.0, 0.01, 0.001, 0.02), "weibull_modulus"),
    (lambda: burst_effective_area(float("nan"), 0.01, 0.001, 0.02), "weibull_modulus"),
    (lambda: ring_on_ring_effective_area(7.0, 16e-3, 8e-3, 20e-3), "load_ring_diameter"),
    (lambda: side_compression_effective_area(7.0, 0.01, 0.006, 0.02), "wall_thickness"),
    (lambda: effective_area_of_test("four-point", 7.0, {}), "test"),
    (lambda: effective_area_of_test("burst", 7.0, {"outer_diameter_m": 0.01}), "length_m"),
    (lambda: fit_strength([1e8, 2e8, 3e8], test="brazilian"), "test"),
    (lambda: fit_strength([1e8, 2e8, 3e8], surface="middle"), "surface"),
    (lambda: fit_strength([1e8, 2e8, 3e8], confidence=1.5), "confidence"),
    (lambda: SurfaceStrength(0.0, 1e8, 1e-4), "weibull_modulus"),
])
def test_bad_parameters_are_refused_naming_the_field(call, field):
    with pytest.raises(InvalidParameterError, match=field):
        call()


def test_bad_csv_files_are_refused_naming_file_line_and_column(tmp_path):
    p = tmp_path / "d.csv"
    p.write_text("specimen,strength\n1,100\n")
    with pytest.raises(InvalidParameterError, match="d.csv.*strength_Pa, failure_stress_MPa"):
        read_strength_csv(p)
    p.write_text("# comment\nstrength_Pa,censored\n1e8,0\n-2e8,0\n")
    with pytest.raises(InvalidParameterError, match=r"d.csv, line 4: strength_Pa = '-2e8'"):
        read_strength_csv(p)
    p.write_text("failure_stress_MPa,censored\n100,0\n120,yes\n")
    with pytest.raises(InvalidParameterError, match="line 3: censored = 'yes'"):
        read_strength_csv(p)
    with pytest.raises(DemfemIOError, match="missing.csv"):
        read_strength_csv(tmp_path / "missing.csv")
    p.write_text("failure_stress_MPa\n100\n120\n")
    assert read_strength_csv(p)[0] == pytest.approx([100e6, 120e6])


def test_bad_strength_files_are_refused_naming_file_and_field(tmp_path):
    f = fit_strength([1e8, 1.2e8, 1.4e8, 0.9e8], n_simulations=500)
    p = write_strength_file(tmp_path / "s.json", f)
    doc = json.loads(p.read_text())
    p.write_text(p.read_text()[:-40])
    with pytest.raises(DemfemIOError, match="s.json"):
        load_strength_file(p)
    for key, value, field in (("weibull_modulus", -3.0, "surfaces.outer.weibull_modulus"),
                              ("characteristic_strength_Pa", None,
                               "surfaces.outer.characteristic_strength_Pa"),
                              ("source", "", "surfaces.outer.source")):
        bad = json.loads(json.dumps(doc))
        bad["surfaces"]["outer"][key] = value
        p.write_text(json.dumps(bad))
        with pytest.raises(InvalidParameterError, match=f"s.json.*{field}"):
            load_strength_file(p)
    p.write_text(json.dumps({**doc, "format": "other"}))
    with pytest.raises(InvalidParameterError, match="s.json.*format"):
        load_strength_file(p)


# --- the command and the file ----------------------------------------------------------------

def test_strength_fit_command_writes_a_file_the_loader_reads_back(tmp_path, capsys):
    out = tmp_path / "strength.json"
    argv = ["strength-fit", str(EXAMPLE), "--test", "ring-on-ring", "--load-ring-diameter",
            "0.008", "--support-ring-diameter", "0.016", "--specimen-diameter", "0.020",
            "--surface", "outer", "--out", str(out)]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "32 specimens" in printed and "2 censored" in printed
    loaded = load_strength_file(out)
    x, c = read_strength_csv(EXAMPLE)
    fit = fit_strength(x, c, test="ring-on-ring", source=EXAMPLE.name, geometry={
        "load_ring_diameter_m": 0.008, "support_ring_diameter_m": 0.016,
        "specimen_diameter_m": 0.020, "poisson_ratio": 0.2})
    assert loaded["outer"] == fit.to_surface_strength()
    assert loaded["measured"] == ("outer",)
    assert loaded["inner"].source.startswith("planning assumption")
    assert "strength_data.csv" in loaded["source"] and "inner: default" in loaded["source"]
    # a second fit for the inner surface, merged into the same file
    assert main(["strength-fit", str(EXAMPLE), "--surface", "inner", "--out", str(out),
                 "--merge", "--simulations", "1000"]) == 0
    both = load_strength_file(out)
    assert both["measured"] == ("inner", "outer") and both["outer"] == loaded["outer"]
    assert both["inner"].weibull_modulus == pytest.approx(fit.m_unbiased, rel=0.02)


def test_strength_fit_command_reports_bad_input_in_one_line(tmp_path, capsys):
    assert main(["strength-fit", str(EXAMPLE), "--test", "ring-on-ring",
                 "--load-ring-diameter", "0.008", "--out", str(tmp_path / "s.json")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("demfem: error:") and "--support-ring-diameter" in err
    assert not (tmp_path / "s.json").exists()


def test_assess_uses_the_users_strength_file(tmp_path):
    """``demfem assess --strength FILE``: the file's Weibull parameters replace the planning
    assumptions in the probabilities, and the report and risk.json name the source."""
    import json

    import numpy as np

    from demfem.assess import assess
    from demfem.cli import main
    from demfem.scenes.table import AccumulationTable

    strength = tmp_path / "strength.json"
    assert main(["strength-fit", "examples/strength_data.csv", "--test", "ring-on-ring",
                 "--load-ring-diameter", "0.008", "--support-ring-diameter", "0.016",
                 "--specimen-diameter", "0.020", "--surface", "outer",
                 "--out", str(strength)]) == 0
    small = AccumulationTable(width=0.1, length=0.1, tilted_wall_length=0.05, n_spheres=30)
    # every event at one place, so that each row's sigma and area are the whole of its P
    # (with the default mix P is the expectation over places: test_assess_places.py)
    kw = dict(duration=0.12, sample_interval=0.01, log=lambda _: None, place="body")
    base = assess(small, out=tmp_path / "a", **kw)
    mine = assess(small, out=tmp_path / "b", strength=strength, **kw)
    assert "strength.json" in mine["strength"]["source"] and mine["strength"]["measured"]
    assert "strength.json" in (tmp_path / "b" / "report.html").read_text()
    doc = json.loads((tmp_path / "b" / "risk.json").read_text())
    outer = doc["settings"]["outer_surface"]
    fitted = json.loads(strength.read_text())["surfaces"]["outer"]
    assert outer["weibull_modulus"] == fitted["weibull_modulus"]
    assert outer["characteristic_strength"] == fitted["characteristic_strength_Pa"]
    # the outer probabilities are the fitted surface's, on the events' own stresses and areas
    from demfem.assess.risk_stage import equivalent_stress, surface_probability
    from demfem.assess.tables import load_assessment
    from demfem.risk import SCG_BOROSILICATE, SurfaceStrength

    ev = load_assessment(tmp_path / "b").events
    surface = SurfaceStrength(fitted["weibull_modulus"], fitted["characteristic_strength_Pa"],
                              fitted["reference_area_m2"])
    s_eq = equivalent_stress(ev["sigma_outer_Pa"].to_numpy(), ev["duration_s"].to_numpy(),
                             SCG_BOROSILICATE)
    expect = surface_probability(surface, s_eq, ev["area_outer_m2"].to_numpy())
    assert np.allclose(ev["p_outer"].to_numpy(), expect, rtol=1e-9, atol=0)
    assert base["strength"]["measured"] == []
