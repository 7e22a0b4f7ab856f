//! Normal contact laws of the paper (Boso et al., eqs. 1–15) as functions of the overlap,
//! the restitution damping of Hertz contacts, and the time scales that bound a stable step.
//!
//! This is the one implementation: `demfem.contact` validates its inputs by name and
//! computes through the bindings; the Python tests check it against closed forms and against
//! independent scipy computations (`tests/python/contact_oracles.py`).

use crate::error::{check_open, check_positive, DemfemError, Result};

/// 2 ∫₀¹ (1 − x^{5/2})^{-1/2} dx = (4/5) B(2/5, 1/2): the Hertz contact time in units of
/// δ_max / v (Johnson, *Contact Mechanics*, §11.4); (4/5) Γ(2/5) Γ(1/2) / Γ(9/10), which
/// scipy's `beta` and a quadrature of the integral both give to 1e-15 (the value used before,
/// 2.943275179…, was 1.8e-9 low).
pub const HERTZ_DURATION_FACTOR: f64 = 2.943_275_184_324_705;

/// Effective modulus E* of two bodies (eq. 4), Pa. `e2 = inf` models a rigid partner.
pub fn effective_modulus(e1: f64, nu1: f64, e2: f64, nu2: f64) -> Result<f64> {
    check_positive("E1", e1)?;
    check_open("nu1", nu1, -1.0, 0.5)?;
    if !(e2 > 0.0) || e2.is_nan() {
        return Err(DemfemError::invalid(
            "E2",
            e2,
            "> 0 (inf for a rigid partner)",
        ));
    }
    check_open("nu2", nu2, -1.0, 0.5)?;
    let c2 = if e2.is_infinite() {
        0.0
    } else {
        (1.0 - nu2 * nu2) / e2
    };
    Ok(1.0 / ((1.0 - nu1 * nu1) / e1 + c2))
}

/// Effective radius R* (eq. 3), m. `r2 = inf` models a plane.
pub fn effective_radius(r1: f64, r2: f64) -> Result<f64> {
    check_positive("R1", r1)?;
    if !(r2 > 0.0) || r2.is_nan() {
        return Err(DemfemError::invalid("R2", r2, "> 0 (inf for a plane)"));
    }
    Ok(if r2.is_infinite() {
        r1
    } else {
        1.0 / (1.0 / r1 + 1.0 / r2)
    })
}

/// Effective mass m* (eq. 9), kg. `m2 = inf` models an immovable partner.
pub fn effective_mass(m1: f64, m2: f64) -> Result<f64> {
    check_positive("m1", m1)?;
    if !(m2 > 0.0) || m2.is_nan() {
        return Err(DemfemError::invalid(
            "m2",
            m2,
            "> 0 (inf for an immovable partner)",
        ));
    }
    Ok(if m2.is_infinite() {
        m1
    } else {
        1.0 / (1.0 / m1 + 1.0 / m2)
    })
}

/// Hertz stiffness k_H = 4/3 √R* E* (eq. 2), N/m^{3/2}.
pub fn hertz_stiffness(r_star: f64, e_star: f64) -> Result<f64> {
    check_positive("R_star", r_star)?;
    check_positive("E_star", e_star)?;
    Ok(4.0 / 3.0 * r_star.sqrt() * e_star)
}

/// Reissner point-load stiffness of a thin shallow shell, k_R = 4/√(3(1−ν²)) E t²/R (eq. 6), N/m.
///
/// `t` is the wall thickness and `r` the mid-surface radius of curvature; `t < r` is required.
pub fn reissner_stiffness(e: f64, nu: f64, t: f64, r: f64) -> Result<f64> {
    check_positive("E", e)?;
    check_open("nu", nu, -1.0, 0.5)?;
    check_positive("t", t)?;
    check_positive("R", r)?;
    if t >= r {
        return Err(DemfemError::invalid("t", t, &format!("< R = {r}")));
    }
    Ok(4.0 / (3.0 * (1.0 - nu * nu)).sqrt() * e * t * t / r)
}

/// Series stiffness of two Reissner shells, 1/k = 1/k_R1 + 1/k_R2 (eq. 12 and 15), N/m.
/// An infinite stiffness stands for a partner that does not bend (a wall).
pub fn series(k1: f64, k2: f64) -> f64 {
    1.0 / (1.0 / k1 + 1.0 / k2)
}

/// Whether the normalised constants (k_R/k_H)², k_H²/k_R² and k_R³/k_H² of
/// [`HertzReissnerScaled`] are normal finite doubles (k_H, k_R > 0 finite): outside, about
/// 1e-102 < k_R/k_H < 1e102 for stiffnesses near 1, the scaled law gives NaN or 0
/// (k_R = 1e-300 N/m with k_H = 1 gave NaN) and [`hertz_reissner_direct`] is used instead.
pub fn reissner_scaling_representable(k_h: f64, k_r: f64) -> bool {
    let q = k_r / k_h;
    let q2 = q * q;
    let ok = |x: f64| x.is_normal() && x > 0.0;
    ok(q2) && ok(1.0 / q2) && ok(k_r * q2)
}

/// The Hertz–Reissner law δ = (F/k_H)^{2/3} + F/k_R solved without the normalised
/// constants, for stiffness ratios where they under- or overflow: the force is bracketed
/// by [0, min(k_H δ^{3/2}, k_R δ)] and found by bisection on the overlap residual (in
/// ratios, so nothing overflows); returns (F, dF/dδ), dF/dδ = 1/(dδ_H/dF + 1/k_R).
pub fn hertz_reissner_direct(overlap: f64, k_h: f64, k_r: f64) -> (f64, f64) {
    if !(overlap > 0.0) {
        return (0.0, 0.0);
    }
    let hi = (k_h * overlap * overlap.sqrt()).min(k_r * overlap);
    // residual of x = F/hi in [0, 1]: ((x hi/k_H)^{2/3} + x hi/k_R)/δ − 1, increasing in x
    let g = |x: f64| ((x * hi / k_h).powf(2.0 / 3.0) + x * hi / k_r) / overlap - 1.0;
    let (mut a, mut b) = (0.0_f64, 1.0_f64);
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if g(m) > 0.0 {
            b = m;
        } else {
            a = m;
        }
        if b - a <= 1e-16 * b {
            break;
        }
    }
    let f = hi * 0.5 * (a + b);
    // dδ_H/dF = (2/3) F^{-1/3} k_H^{-2/3} = (2/3) δ_H / F
    let dh = if f > 0.0 {
        (2.0 / 3.0) * (f / k_h).powf(2.0 / 3.0) / f
    } else {
        f64::INFINITY
    };
    (f, 1.0 / (dh + 1.0 / k_r))
}

/// Largest Tsuji damping parameter ζ for which [`tsuji_restitution`] integrates the impact
/// (checked against an adaptive DOP853 integration to 1e-9 up to here; at ζ = 1e6 the
/// fixed smallest step gave a restitution off by six orders of magnitude, and at 1e20 a
/// negative one). Beyond it the overdamped limit is returned: clamped, the bodies stop at
/// X_m = (5/(4ζ))^{4/5} and leave along the slow manifold X' = −X^{5/4}/ζ, so
/// e = X_m^{5/4}/ζ = 1.25/ζ² (within 3e-5 of the integration at ζ = 1e3); unclamped, the
/// attraction holds them together (e = 0, as integrated from ζ ≈ 2.5 on).
pub const MAX_TSUJI_ZETA: f64 = 1e3;

/// Check ζ for [`tsuji_restitution`]: finite and >= 0; names `zeta`.
pub fn check_tsuji_zeta(zeta: f64) -> Result<f64> {
    if zeta.is_finite() && zeta >= 0.0 {
        Ok(zeta)
    } else {
        Err(DemfemError::InvalidParameter {
            field: "zeta".into(),
            value: format!("{zeta:e}"),
            allowed: "finite and >= 0".into(),
        })
    }
}

/// A normal contact law: force as a function of the overlap δ ≥ 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NormalLaw {
    /// F = k_H δ^{3/2} (eq. 1); `k_h` in N/m^{3/2}.
    Hertz {
        /// Hertz stiffness, N/m^{3/2}.
        k_h: f64,
    },
    /// F = k δ: a linear spring (Reissner shells alone, eq. 5, or the linearised law, eq. 15).
    Linear {
        /// Spring stiffness, N/m.
        k: f64,
    },
    /// Hertz indentation in series with shell deflection: δ = (F/k_H)^{2/3} + F/k_R (eq. 12).
    HertzReissner {
        /// Hertz stiffness, N/m^{3/2}.
        k_h: f64,
        /// Series Reissner stiffness of both shells, N/m.
        k_r: f64,
    },
}

impl NormalLaw {
    /// Build a law after validating its stiffnesses.
    pub fn validated(self) -> Result<Self> {
        match self {
            NormalLaw::Hertz { k_h } => {
                check_positive("k_H", k_h)?;
            }
            NormalLaw::Linear { k } => {
                check_positive("k", k)?;
            }
            NormalLaw::HertzReissner { k_h, k_r } => {
                check_positive("k_H", k_h)?;
                check_positive("k_R", k_r)?;
            }
        }
        Ok(self)
    }

    /// Elastic normal force F(δ), N, for overlap δ (m); zero for δ ≤ 0.
    #[inline]
    pub fn force(&self, overlap: f64) -> f64 {
        self.force_and_stiffness(overlap).0
    }

    /// Elastic normal force F(δ), N, and tangent stiffness dF/dδ, N/m.
    #[inline]
    pub fn force_and_stiffness(&self, overlap: f64) -> (f64, f64) {
        if overlap <= 0.0 {
            return match *self {
                NormalLaw::Linear { k } => (0.0, k),
                _ => (0.0, 0.0),
            };
        }
        match *self {
            NormalLaw::Hertz { k_h } => {
                let s = overlap.sqrt();
                (k_h * overlap * s, 1.5 * k_h * s)
            }
            NormalLaw::Linear { k } => (k * overlap, k),
            NormalLaw::HertzReissner { k_h, k_r } => {
                // the limits of an unvalidated law: no shell is Hertz, a rigid ball the spring
                if k_r.is_infinite() {
                    let s = overlap.sqrt();
                    return (k_h * overlap * s, 1.5 * k_h * s);
                }
                if k_h.is_infinite() {
                    return (k_r * overlap, k_r);
                }
                if !reissner_scaling_representable(k_h, k_r) {
                    return hertz_reissner_direct(overlap, k_h, k_r);
                }
                let (f, k, _) = HertzReissnerScaled::new_unchecked(k_h, k_r).evaluate(overlap);
                (f, k)
            }
        }
    }
}

/// Root u ≥ 0 of u³ + u² = s: the Hertz–Reissner law in normalised form.
///
/// With x = F^{1/3} and u = x k_H^{2/3}/k_R, δ = (F/k_H)^{2/3} + F/k_R becomes u³ + u² = s
/// with s = δ (k_H/k_R)² (see [`HertzReissnerScaled`]). Accurate to a few ulp for every
/// s ≥ 0 (tested against bisection over s = 1e-20 … 1e20 and beyond); 0 for s ≤ 0 or NaN.
///
/// Start: u = √(s/(1 + m)) is the exact root when m = u, so it is one step of a contracting
/// fixed-point iteration (factor ≤ u/(2(1+u)) < 1/2) from the asymptotics m = √s (s → 0,
/// where u = √s − s/2 + …) or m = ∛s − 1/3 (s → ∞, u = ∛s − 1/3 + …), floored at 0.75 ∛s
/// near s = 1; the start is within 2.4 % of the root for every s (2.2 % with an exact ∛s;
/// a seed to 3.2 % from the bits is used), and two Halley steps (cubic convergence, error
/// e → ≈ 0.45 e³: 2.4e-2 → 6e-6 → 1e-16) reach round-off. For s ≥ 1e45 the asymptote
/// ∛s − 1/3 is exact in double precision (the next term is 1/(9∛s), below 1e-16 ∛s) and is
/// returned directly, which also keeps the Halley step's u⁴ from overflowing.
#[inline(always)]
pub fn hertz_reissner_root(s: f64) -> f64 {
    if !(s > 0.0) {
        return 0.0;
    }
    if s >= 1e45 {
        return s.cbrt() - 1.0 / 3.0;
    }
    let r2 = s.sqrt();
    // √s ≤ 0.75 ∛s for s ≤ 0.75⁶ = 0.178: below that the min is √s and ∛s is not needed
    let m = if s <= 0.17 {
        r2
    } else {
        // ∛s to within 3.2 % from the bits (exponent and mantissa divided by 3, the classic
        // cube-root seed): enough, since the start only needs m to a few per cent
        // (the start stays within 2.4 % of the root), and much cheaper than `cbrt`
        let r3 = f64::from_bits(s.to_bits() / 3 + 0x2A9F_7893_782D_A1CE);
        r2.min((r3 - 1.0 / 3.0).max(0.75 * r3))
    };
    let mut u = (s / (1.0 + m)).sqrt();
    for _ in 0..2 {
        // Halley on g(u) = u²(u + 1) − s: u −= g g' / (g'² − g g''/2)
        let g = u * u * (u + 1.0) - s;
        let d1 = u * (3.0 * u + 2.0);
        let d2 = 6.0 * u + 2.0;
        u -= g * d1 / (d1 * d1 - 0.5 * g * d2);
    }
    u
}

/// The Hertz–Reissner law δ = (F/k_H)^{2/3} + F/k_R in normalised form, with every constant
/// precomputed so an evaluation is one [`hertz_reissner_root`] and a few products.
///
/// s = δ (k_H/k_R)², u³ + u² = s, then F = (k_R³/k_H²) u³, the Hertz part of the overlap
/// δ_H = (F/k_H)^{2/3} = (k_R/k_H)² u², and the tangent stiffness
/// dF/dδ = k_R · 3u/(2 + 3u) (dF/du = 3 (k_R³/k_H²) u², dδ/du = (k_R/k_H)² (2u + 3u²)).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct HertzReissnerScaled {
    /// (k_H/k_R)², 1/m: s = `s_per_overlap` δ.
    pub s_per_overlap: f64,
    /// k_R³/k_H², N: F = `force_scale` u³.
    pub force_scale: f64,
    /// (k_R/k_H)², m: δ_H = `hertz_overlap_scale` u².
    pub hertz_overlap_scale: f64,
    /// Series Reissner stiffness k_R, N/m.
    pub k_r: f64,
}

impl HertzReissnerScaled {
    /// Constants of the law with Hertz stiffness `k_h` (N/m^{3/2}) and Reissner stiffness
    /// `k_r` (N/m); both must be finite and > 0.
    pub fn new(k_h: f64, k_r: f64) -> Result<Self> {
        check_positive("k_H", k_h)?;
        check_positive("k_R", k_r)?;
        Ok(Self::new_unchecked(k_h, k_r))
    }

    /// As [`HertzReissnerScaled::new`] for stiffnesses already validated (> 0, finite).
    #[inline]
    pub(crate) fn new_unchecked(k_h: f64, k_r: f64) -> Self {
        let q = k_r / k_h; // (k_R/k_H); k_R³/k_H² = k_R q², without overflowing k_R³
        let q2 = q * q;
        HertzReissnerScaled {
            s_per_overlap: 1.0 / q2,
            force_scale: k_r * q2,
            hertz_overlap_scale: q2,
            k_r,
        }
    }

    /// Normalised root u at overlap δ (m); 0 for δ ≤ 0.
    #[inline(always)]
    pub fn root(&self, overlap: f64) -> f64 {
        hertz_reissner_root(self.s_per_overlap * overlap)
    }

    /// Force F (N), tangent stiffness dF/dδ (N/m) and Hertz indentation δ_H (m) at overlap
    /// δ (m); (0, 0, 0) for δ ≤ 0.
    #[inline(always)]
    pub fn evaluate(&self, overlap: f64) -> (f64, f64, f64) {
        let u = self.root(overlap);
        let f = self.force_scale * u * u * u;
        let k = self.k_r * (3.0 * u) / (2.0 + 3.0 * u);
        (f, k, self.hertz_overlap_scale * u * u)
    }
}

/// Solve δ = (F/k_H)^{2/3} + F/k_R for F ≥ 0 (Hertz in series with a linear spring), N;
/// 0 for δ ≤ 0. Normalised by [`HertzReissnerScaled`] and solved by [`hertz_reissner_root`].
pub fn hertz_reissner_force(overlap: f64, k_h: f64, k_r: f64) -> f64 {
    NormalLaw::HertzReissner { k_h, k_r }.force(overlap)
}

/// Maximum force of a Hertz impact, from m* v² = (4/5) F^{5/3} / k_H^{2/3} (eq. 12 with k_R → ∞), N.
pub fn max_force_hertz(k_h: f64, m_star: f64, v_rel: f64) -> f64 {
    k_h.powf(0.4) * (1.25 * m_star * v_rel * v_rel).powf(0.6)
}

/// Maximum force of a linear-spring impact, F = √(k m*) v (eq. 14), N.
pub fn max_force_linear(k: f64, m_star: f64, v_rel: f64) -> f64 {
    (k * m_star).sqrt() * v_rel
}

/// Maximum force of a Hertz–Reissner impact: the root of eq. 12,
/// m* v² = F²/k_R + (4/5) F^{5/3}/k_H^{2/3}, found by Newton in x = F^{1/3} from above
/// (the function is convex and increasing in x), N.
pub fn max_force_hertz_reissner(k_h: f64, k_r: f64, m_star: f64, v_rel: f64) -> f64 {
    if v_rel <= 0.0 {
        return 0.0;
    }
    let w = m_star * v_rel * v_rel;
    let kh23 = (k_h * k_h).cbrt();
    let x_h = max_force_hertz(k_h, m_star, v_rel).cbrt();
    let x_r = max_force_linear(k_r, m_star, v_rel).cbrt();
    let mut x = x_h.min(x_r);
    for _ in 0..200 {
        let x2 = x * x;
        let x5 = x2 * x2 * x;
        let g = x5 * x / k_r + 0.8 * x5 / kh23 - w;
        let dg = 6.0 * x5 / k_r + 4.0 * x2 * x2 / kh23;
        if dg <= 0.0 {
            break;
        }
        let step = g / dg;
        let next = x - step;
        if !(next > 0.0) {
            x *= 0.5;
            continue;
        }
        x = next;
        if step.abs() <= 4.0 * f64::EPSILON * x {
            break;
        }
    }
    x * x * x
}

/// Linearised Hertz stiffness (eq. 13),
/// k_lin = 4/3 (15/16)^{1/5} R*^{2/5} E*^{4/5} m*^{1/5} v^{2/5}, N/m.
pub fn linearized_hertz_stiffness(r_star: f64, e_star: f64, m_star: f64, v_rel: f64) -> f64 {
    4.0 / 3.0
        * (15.0_f64 / 16.0).powf(0.2)
        * r_star.powf(0.4)
        * e_star.powf(0.8)
        * m_star.powf(0.2)
        * v_rel.powf(0.4)
}

/// Maximum overlap of an undamped Hertz impact, δ_max = (5 m* v² / (4 k_H))^{2/5}, m.
pub fn hertz_max_overlap(k_h: f64, m_star: f64, v_rel: f64) -> f64 {
    (1.25 * m_star * v_rel * v_rel / k_h).powf(0.4)
}

/// Duration of an undamped Hertz impact, t_c = 2.9433 δ_max / v, s.
pub fn hertz_contact_duration(k_h: f64, m_star: f64, v_rel: f64) -> Result<f64> {
    check_positive("v_rel", v_rel)?;
    Ok(HERTZ_DURATION_FACTOR * hertz_max_overlap(k_h, m_star, v_rel) / v_rel)
}

/// Rayleigh time step Δt_R = π R √(ρ/G) / (0.1631 ν + 0.8766), s (Li, Xu & Thornton 2005).
pub fn rayleigh_time_step(radius: f64, density: f64, e: f64, nu: f64) -> Result<f64> {
    check_positive("radius", radius)?;
    check_positive("density", density)?;
    check_positive("E", e)?;
    check_open("nu", nu, -1.0, 0.5)?;
    let g = e / (2.0 * (1.0 + nu));
    let dt = std::f64::consts::PI * radius * (density / g).sqrt() / (0.1631 * nu + 0.8766);
    if !(g > 0.0 && dt.is_finite() && dt > 0.0) {
        // a subnormal E underflows G to 0 (the step was +inf)
        return Err(DemfemError::InvalidParameter {
            field: "E".into(),
            value: format!("{e:e} Pa"),
            allowed: "large enough that G = E/(2(1+nu)) > 0 and the step \
                      pi R sqrt(rho/G)/(0.1631 nu + 0.8766) is finite and > 0"
                .into(),
        });
    }
    Ok(dt)
}

/// How the damped normal force is treated when damping would make it attractive.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ForceClamp {
    /// The total normal force may become negative (attractive) near separation.
    None,
    /// The total normal force is clamped at ≥ 0; the realised restitution is then higher.
    NonNegative,
}

/// Restitution of one Hertz impact with Tsuji damping F = k_H δ^{3/2} + ζ √(m* k_H) δ^{1/4} δ̇.
///
/// In units δ = s X, t = T τ with T² = m*/(k_H s^{1/2}) and s chosen so that the impact
/// speed is 1, the equation becomes X'' = −X^{3/2} − ζ X^{1/4} X': the restitution depends
/// on ζ alone, not on speed, mass or stiffness. Integrated with classical RK4.
pub fn tsuji_restitution(zeta: f64, clamp: ForceClamp) -> f64 {
    if zeta > MAX_TSUJI_ZETA {
        return match clamp {
            ForceClamp::NonNegative => 1.25 / (zeta * zeta),
            ForceClamp::None => 0.0,
        };
    }
    let accel = |x: f64, v: f64| -> f64 {
        let xp = x.max(0.0);
        let f = xp * xp.sqrt() + zeta * xp.sqrt().sqrt() * v;
        match clamp {
            ForceClamp::None => -f,
            ForceClamp::NonNegative => -f.max(0.0),
        }
    };
    // X^{1/4} is not smooth at X = 0, at the start and at the end of the contact; there the
    // step shrinks with the overlap (h ≤ 2 % of the time to cross it), so RK4 keeps its
    // accuracy and the exit speed is resolved to ~1e-12.
    let h_max = 2e-4;
    let (mut x, mut v) = (0.0_f64, 1.0_f64);
    for _ in 0..10_000_000 {
        if x > 0.0 && x < 1e-13 && v < 0.0 {
            return -v;
        }
        let h = if v.abs() > 0.0 {
            (0.02 * x / v.abs()).clamp(1e-13, h_max)
        } else {
            h_max
        };
        let (k1x, k1v) = (v, accel(x, v));
        let (k2x, k2v) = (
            v + 0.5 * h * k1v,
            accel(x + 0.5 * h * k1x, v + 0.5 * h * k1v),
        );
        let (k3x, k3v) = (
            v + 0.5 * h * k2v,
            accel(x + 0.5 * h * k2x, v + 0.5 * h * k2v),
        );
        let (k4x, k4v) = (v + h * k3v, accel(x + h * k3x, v + h * k3v));
        let xn = x + h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        let vn = v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        if xn <= 0.0 {
            let frac = x / (x - xn);
            return -(v + frac * (vn - v));
        }
        if clamp == ForceClamp::NonNegative && vn < 0.0 {
            let f = xn * xn.sqrt() + zeta * xn.sqrt().sqrt() * vn;
            if f <= 0.0 {
                // the force vanished: from here on the bodies drift apart at constant speed
                let f_prev = x * x.sqrt() + zeta * x.sqrt().sqrt() * v;
                let frac = if f_prev > 0.0 {
                    f_prev / (f_prev - f)
                } else {
                    1.0
                };
                return -(v + frac * (vn - v));
            }
        }
        if vn >= 0.0 && v >= 0.0 && xn == x {
            // stalled: fully damped, the bodies never separate
            return 0.0;
        }
        x = xn;
        v = vn;
    }
    0.0
}

/// Tsuji damping parameter ζ that realises restitution `e` in a Hertz impact (bisection on
/// [`tsuji_restitution`]); e in (0, 1], ζ = 0 for e = 1.
pub fn tsuji_damping_for_restitution(e: f64, clamp: ForceClamp) -> Result<f64> {
    if !(e.is_finite() && e > 0.0 && e <= 1.0) {
        return Err(DemfemError::invalid(
            "restitution",
            e,
            "finite and in (0, 1]",
        ));
    }
    if e == 1.0 {
        return Ok(0.0);
    }
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    while tsuji_restitution(hi, clamp) > e {
        hi *= 2.0;
        if hi > 1e6 {
            return Err(DemfemError::invalid(
                "restitution",
                e,
                "reachable by Tsuji damping",
            ));
        }
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if tsuji_restitution(mid, clamp) > e {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-13 * hi {
            break;
        }
    }
    Ok(0.5 * (lo + hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn series_root_satisfies_equation() {
        let (k_h, k_r) = (1.2e10, 3.0e6);
        for &d in &[1e-9, 1e-7, 1e-5, 1e-3] {
            let f = hertz_reissner_force(d, k_h, k_r);
            let back = (f / k_h).powf(2.0 / 3.0) + f / k_r;
            assert!((back - d).abs() <= 1e-12 * d, "{back} vs {d}");
        }
    }

    #[test]
    fn elastic_restitution_is_one() {
        let e = tsuji_restitution(0.0, ForceClamp::None);
        assert!((e - 1.0).abs() < 1e-9, "{e}");
    }
}
