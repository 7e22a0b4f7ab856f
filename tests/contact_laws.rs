//! Closed-form checks of the normal contact laws (Boso et al. eqs. 1–15) in the core: each
//! law integrated through an impact must reproduce the analytical maximum force, overlap,
//! duration and restitution.

use demfem::contact::*;

/// Glass equivalent sphere of the default cartridge: m = 4.941 g, R = 8.085 mm, E = 45 GPa.
const MASS: f64 = 4.941e-3;
const RADIUS: f64 = 8.085e-3;
const E: f64 = 45e9;
const NU: f64 = 0.22;

struct Impact {
    max_force: f64,
    max_overlap: f64,
    duration: f64,
    exit_speed: f64,
}

/// Integrate a head-on impact with velocity Verlet (tiny step: 1e-4 of the contact time),
/// independent of the closed forms it is compared with.
fn integrate(force: impl Fn(f64, f64) -> f64, m: f64, v0: f64, t_est: f64) -> Impact {
    let dt = t_est * 1e-5;
    let (mut x, mut v, mut t) = (0.0_f64, v0, 0.0_f64);
    let mut a = -force(x, v) / m;
    let (mut fmax, mut xmax) = (0.0_f64, 0.0_f64);
    loop {
        let v_half = v + 0.5 * dt * a;
        let x_new = x + dt * v_half;
        let a_new = -force(x_new, v_half) / m;
        let v_new = v_half + 0.5 * dt * a_new;
        t += dt;
        if x_new <= 0.0 {
            let frac = x / (x - x_new);
            return Impact {
                max_force: fmax,
                max_overlap: xmax,
                duration: t - dt + frac * dt,
                exit_speed: -(v + frac * (v_new - v)),
            };
        }
        x = x_new;
        v = v_new;
        a = a_new;
        fmax = fmax.max(-a * m);
        xmax = xmax.max(x);
        assert!(t < 100.0 * t_est, "impact never ended");
    }
}

fn pair_constants() -> (f64, f64) {
    let e_star = effective_modulus(E, NU, E, NU).unwrap();
    let r_star = effective_radius(RADIUS, RADIUS).unwrap();
    (
        hertz_stiffness(r_star, e_star).unwrap(),
        effective_mass(MASS, MASS).unwrap(),
    )
}

#[test]
fn hertz_impact_matches_closed_form() {
    let (k_h, m) = pair_constants();
    let law = NormalLaw::Hertz { k_h };
    for &v in &[1e-3, 0.2, 5.0] {
        let tc = hertz_contact_duration(k_h, m, v).unwrap();
        let imp = integrate(|x, _| law.force(x), m, v, tc);
        // Verlet with dt = 1e-5 t_c: errors O(dt²) ≈ 1e-9; 1e-6 leaves room for sampling
        assert!((imp.max_force / max_force_hertz(k_h, m, v) - 1.0).abs() < 1e-6);
        assert!((imp.max_overlap / hertz_max_overlap(k_h, m, v) - 1.0).abs() < 1e-6);
        assert!(
            (imp.duration / tc - 1.0).abs() < 1e-5,
            "{} vs {}",
            imp.duration,
            tc
        );
        assert!((imp.exit_speed / v - 1.0).abs() < 1e-6);
    }
}

#[test]
fn hertz_reissner_impact_matches_eq12() {
    let (k_h, m) = pair_constants();
    // two shells of the default cartridge body: t = 1.1 mm, R_mid = 5.25 mm
    let k_r1 = reissner_stiffness(E, NU, 1.1e-3, 5.25e-3).unwrap();
    let k_r = series(k_r1, k_r1);
    let law = NormalLaw::HertzReissner { k_h, k_r };
    for &v in &[0.05, 0.2, 2.0] {
        let f_theory = max_force_hertz_reissner(k_h, k_r, m, v);
        let tc = hertz_contact_duration(k_h, m, v).unwrap() * 3.0;
        let imp = integrate(|x, _| law.force(x), m, v, tc);
        assert!(
            (imp.max_force / f_theory - 1.0).abs() < 1e-6,
            "{} vs {f_theory}",
            imp.max_force
        );
        // the series law is softer than either law alone
        assert!(f_theory < max_force_hertz(k_h, m, v));
        assert!(f_theory < max_force_linear(k_r, m, v));
    }
}

#[test]
fn eq12_root_is_exact_over_the_whole_range() {
    // E from 1e6 to 1e12 Pa, v_rel from 1e-4 to 10 m/s
    for i in 0..=12 {
        let e = 10f64.powf(6.0 + 0.5 * i as f64);
        let e_star = effective_modulus(e, NU, e, NU).unwrap();
        let k_h = hertz_stiffness(effective_radius(RADIUS, RADIUS).unwrap(), e_star).unwrap();
        let k_r = series(
            reissner_stiffness(e, NU, 1.1e-3, 5.25e-3).unwrap(),
            reissner_stiffness(e, NU, 1.1e-3, 5.25e-3).unwrap(),
        );
        let m = effective_mass(MASS, MASS).unwrap();
        let mut last = 0.0;
        for j in 0..=10 {
            let v = 10f64.powf(-4.0 + 0.5 * j as f64);
            let f = max_force_hertz_reissner(k_h, k_r, m, v);
            let lhs = f * f / k_r + 0.8 * f.powf(5.0 / 3.0) / k_h.powf(2.0 / 3.0);
            assert!((lhs / (m * v * v) - 1.0).abs() < 1e-12, "E={e} v={v}");
            assert!(f > last, "monotonic in v");
            last = f;
        }
    }
}

#[test]
fn series_law_limits() {
    let (k_h, k_r) = (2.5e10, 1.2e7);
    for &d in &[1e-9, 1e-7, 1e-6, 1e-4] {
        let hr = hertz_reissner_force(d, k_h, k_r);
        assert!(hr < k_h * d.powf(1.5) && hr < k_r * d);
        // k_R → ∞ gives Hertz, k_H → ∞ gives the linear spring
        let h = hertz_reissner_force(d, k_h, 1e30);
        assert!((h / (k_h * d.powf(1.5)) - 1.0).abs() < 1e-12);
        let l = hertz_reissner_force(d, 1e40, k_r);
        assert!((l / (k_r * d) - 1.0).abs() < 1e-9);
    }
}

#[test]
fn linearized_force_is_sqrt_four_fifths_of_hertz() {
    let (k_h, m) = pair_constants();
    let r_star = effective_radius(RADIUS, RADIUS).unwrap();
    let e_star = effective_modulus(E, NU, E, NU).unwrap();
    for &v in &[1e-3, 0.2, 3.0] {
        let k_lin = linearized_hertz_stiffness(r_star, e_star, m, v);
        let ratio = max_force_linear(k_lin, m, v) / max_force_hertz(k_h, m, v);
        assert!((ratio - (0.8f64).sqrt()).abs() < 1e-12, "{ratio}");
    }
}

#[test]
fn tsuji_damping_realises_restitution_in_dimensional_impacts() {
    let (k_h, m) = pair_constants();
    for &clamp in &[ForceClamp::None, ForceClamp::NonNegative] {
        for &e in &[0.1, 0.3, 0.5, 0.7, 0.9] {
            let zeta = tsuji_damping_for_restitution(e, clamp).unwrap();
            let c = zeta * (m * k_h).sqrt();
            for &v in &[0.01, 0.5] {
                let tc = hertz_contact_duration(k_h, m, v).unwrap();
                let force = |x: f64, xd: f64| {
                    let f = k_h * x.max(0.0).powf(1.5) + c * x.max(0.0).powf(0.25) * xd;
                    match clamp {
                        ForceClamp::None => f,
                        ForceClamp::NonNegative => f.max(0.0),
                    }
                };
                let imp = integrate(force, m, v, tc);
                // with clamping the bodies separate when the force vanishes, before x = 0:
                // the exit speed is then constant, so x = 0 measures it as well
                let e_real = imp.exit_speed / v;
                assert!(
                    (e_real - e).abs() < 2e-4,
                    "e={e} clamp={clamp:?} v={v}: {e_real}"
                );
            }
        }
    }
}

#[test]
fn clamping_raises_the_realised_restitution() {
    for &e in &[0.2, 0.5, 0.8] {
        let zeta = tsuji_damping_for_restitution(e, ForceClamp::None).unwrap();
        let clamped = tsuji_restitution(zeta, ForceClamp::NonNegative);
        assert!(clamped > e + 1e-3, "e={e}: clamped {clamped}");
    }
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    assert!(reissner_stiffness(-1.0, 0.2, 1e-3, 5e-3).is_err());
    assert!(reissner_stiffness(1e9, 0.5, 1e-3, 5e-3).is_err());
    assert!(reissner_stiffness(1e9, 0.2, 6e-3, 5e-3).is_err());
    assert!(reissner_stiffness(1e9, 0.2, f64::NAN, 5e-3).is_err());
    assert!(effective_modulus(f64::INFINITY, 0.2, 1e9, 0.2).is_err());
    assert!(tsuji_damping_for_restitution(0.0, ForceClamp::None).is_err());
    assert!(tsuji_damping_for_restitution(f64::NAN, ForceClamp::None).is_err());
    assert!(rayleigh_time_step(1e-3, 2230.0, 45e9, -1.0).is_err());
    assert!(NormalLaw::Hertz { k_h: -1.0 }.validated().is_err());
}

/// u with u²(u + 1) = s by bisection in f64 on the monotone g(u) = u²(u + 1) − s, between
/// 0 and min(√s, ∛s) (u² < s and u³ < s), until the bracket is two adjacent doubles.
fn root_by_bisection(s: f64) -> f64 {
    let (mut lo, mut hi) = (0.0_f64, s.sqrt().min(s.cbrt()));
    loop {
        let mid = 0.5 * (lo + hi);
        if !(mid > lo && mid < hi) {
            break;
        }
        if mid * mid * (mid + 1.0) > s {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The normalised series root u³ + u² = s against bisection over s = 1e-20 … 1e20 (50
/// points per decade, shifted off round numbers) to 1e-13 relative — in fact to a few ulp,
/// as also checked on 100 000 random s in 1e-20 … 1e40 —
/// and against the asymptotic series beyond: u = √s − s/2 + 5/8 s^{3/2} for s → 0 and
/// u = ∛s − 1/3 + 1/(9∛s) for s → ∞.
#[test]
fn hertz_reissner_root_is_exact_over_forty_decades() {
    let mut worst = 0.0_f64;
    for i in -1000..=1000 {
        let s = 10f64.powf(i as f64 / 50.0) * 1.000_123_456_7;
        let u = hertz_reissner_root(s);
        let r = root_by_bisection(s);
        let err = (u - r).abs() / r;
        worst = worst.max(err);
        assert!(
            err <= 1e-13,
            "s = {s:e}: u = {u:e}, bisection {r:e}, error {err:e}"
        );
    }
    assert!(
        worst <= 8.0 * f64::EPSILON,
        "worst relative error {worst:e}"
    );
    // and densely: 100 000 log-uniform s in 1e-20 … 1e40 (the start's error varies within
    // each factor 8 of s through the cube-root seed)
    let mut state = 0x9E37_79B9_7F4A_7C15_u64;
    for _ in 0..100_000 {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let s = 10f64.powf(-20.0 + 60.0 * (state >> 11) as f64 / (1u64 << 53) as f64);
        let (u, r) = (hertz_reissner_root(s), root_by_bisection(s));
        assert!(
            (u - r).abs() <= 8.0 * f64::EPSILON * r,
            "s = {s:e}: {u:e} vs {r:e}"
        );
    }
    for &s in &[1e-300_f64, 1e-200, 1e-100, 1e-40, 1e-30] {
        let q = s.sqrt();
        let series = q - 0.5 * s + 0.625 * s * q;
        assert!(
            (hertz_reissner_root(s) / series - 1.0).abs() <= 4.0 * f64::EPSILON,
            "s = {s:e}"
        );
    }
    for &s in &[1e30_f64, 1e44, 1e45, 1e100, 1e200, 1e300, f64::MAX] {
        let t = s.cbrt();
        let series = t - 1.0 / 3.0 + 1.0 / (9.0 * t);
        assert!(
            (hertz_reissner_root(s) / series - 1.0).abs() <= 4.0 * f64::EPSILON,
            "s = {s:e}"
        );
    }
    assert_eq!(hertz_reissner_root(0.0), 0.0);
    assert_eq!(hertz_reissner_root(-1.0), 0.0);
    assert_eq!(hertz_reissner_root(f64::NAN), 0.0);
}

/// The scaled law returns F with δ = (F/k_H)^{2/3} + F/k_R, δ_H = (F/k_H)^{2/3} and
/// dF/dδ = 1 / ((2/3) F^{-1/3} k_H^{-2/3} + 1/k_R) (the derivative of eq. 12 by F), for the
/// pair constants of the default cartridge from 1e6 to 1e12 Pa and overlaps 1e-12 … 1e-2 m.
#[test]
fn scaled_hertz_reissner_law_satisfies_eq12() {
    for i in 0..=12 {
        let e = 10f64.powf(6.0 + 0.5 * i as f64);
        let e_star = effective_modulus(e, NU, e, NU).unwrap();
        let k_h = hertz_stiffness(effective_radius(RADIUS, RADIUS).unwrap(), e_star).unwrap();
        let k_r1 = reissner_stiffness(e, NU, 1.1e-3, 5.25e-3).unwrap();
        let k_r = series(k_r1, k_r1);
        let law = HertzReissnerScaled::new(k_h, k_r).unwrap();
        for j in 0..=40 {
            let d = 10f64.powf(-12.0 + 0.25 * j as f64);
            let (f, k, d_h) = law.evaluate(d);
            let back = (f / k_h).powf(2.0 / 3.0) + f / k_r;
            assert!((back / d - 1.0).abs() < 1e-13, "E={e} δ={d}: {back}");
            assert!(
                (d_h / (f / k_h).powf(2.0 / 3.0) - 1.0).abs() < 1e-13,
                "E={e} δ={d}"
            );
            let k_exact = 1.0 / (2.0 / 3.0 / (f * k_h * k_h).cbrt() + 1.0 / k_r);
            assert!(
                (k / k_exact - 1.0).abs() < 1e-13,
                "E={e} δ={d}: {k} vs {k_exact}"
            );
            assert_eq!(f, hertz_reissner_force(d, k_h, k_r));
        }
        assert_eq!(law.evaluate(0.0), (0.0, 0.0, 0.0));
        assert_eq!(law.evaluate(-1e-6), (0.0, 0.0, 0.0));
    }
    assert!(HertzReissnerScaled::new(0.0, 1.0).is_err());
    assert!(HertzReissnerScaled::new(1.0, f64::INFINITY).is_err());
}
