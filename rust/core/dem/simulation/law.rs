//! The contact laws as the kernels evaluate them: the per-contact constants derived once per
//! neighbour-list rebuild ([`ContactConst`], [`LawKind`]), the normal law at an overlap
//! ([`law_at`]) and the Mindlin–Coulomb tangential force ([`tangential_force`]).

use super::on;
use crate::contact;
use crate::dem::effects::{Effect, EffectSet};
use crate::dem::material::{DemContactLaw, PairLaw};
use crate::geometry::Vec3;

/// Constants of one contact (a pair or a particle–wall slot) derived from the pair law, the
/// reduced radius and the reduced mass once per neighbour-list rebuild, so the kernels do no
/// division and no law-table lookup per step. What `f_el`, `k_t` and `c_n` hold depends on
/// `kind`:
/// - [`LawKind::Hertz`] (Hertz–Mindlin, or Hertz–Reissner without shell), with s = √δ:
///   F_el = `f_el` s δ, k_t = `k_t` s, c_n = `c_n` √s, which equal 4/3 E* a δ, 8 G* a and
///   ζ √(2/3 m* 2E* a) for a = √(R* δ);
/// - [`LawKind::HertzReissner`], with u the root of u³ + u² = `s_scale` δ
///   ([`contact::hertz_reissner_root`]): F_el = `f_el` u³, k_t = `k_t` u,
///   c_n = `c_n` √(3u/(2 + 3u)), which equal F, 8 G* √(R* δ_H) with δ_H = (F/k_H)^{2/3}, and
///   ζ √(2/3 m* dF/dδ) (see [`contact::HertzReissnerScaled`]);
/// - [`LawKind::Linear`]: F_el = `f_el` δ, k_t = `k_t`, c_n = `c_n`.
#[derive(Debug, Clone, Copy, Default)]
#[repr(C)]
pub(crate) struct ContactConst {
    pub(super) r_star: f64,
    /// (k_H/k_R)², 1/m, for [`LawKind::HertzReissner`] (else 0): s = `s_scale` δ.
    pub(super) s_scale: f64,
    /// Hertz: 4/3 E* √R*; Hertz–Reissner: k_R³/k_H², N; linear: k_n, N/m.
    pub(super) f_el: f64,
    /// Hertz: 8 G* √R*; Hertz–Reissner: 8 G* √R* k_R/k_H, N/m; linear: k_t, N/m.
    pub(super) k_t: f64,
    /// Hertz: ζ √(4/3 m* E* √R*); Hertz–Reissner: ζ √(2/3 m* k_R); linear: 2β √(m* k_n)
    /// (the pair law's `linear_damping` = 2β); N·s/m times the powers of s or u above.
    pub(super) c_n: f64,
    /// c_t / c_n.
    pub(super) ct_ratio: f64,
    /// Coulomb friction μ.
    pub(super) mu: f64,
    /// Index of the pair law.
    pub(super) law: u32,
    /// Which closed form applies.
    pub(super) kind: LawKind,
}

/// The normal law of a contact, as far as its per-step evaluation goes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) enum LawKind {
    /// Hertz–Mindlin, or Hertz–Reissner–Mindlin without shell compliance.
    #[default]
    Hertz,
    /// Hertz in series with a Reissner shell, Mindlin on the Hertz indentation.
    HertzReissner,
    /// Linear spring–dashpot.
    Linear,
}

impl ContactConst {
    pub(super) fn new(
        model: DemContactLaw,
        laws: &[PairLaw],
        law: usize,
        r_star: f64,
        m_star: f64,
    ) -> Self {
        let l = &laws[law];
        let sr = r_star.sqrt();
        let base = ContactConst {
            r_star,
            s_scale: 0.0,
            f_el: 4.0 / 3.0 * l.e_star * sr,
            k_t: 8.0 * l.g_star * sr,
            c_n: l.zeta * (2.0 / 3.0 * m_star * (2.0 * l.e_star * sr)).sqrt(),
            ct_ratio: l.tangential_damping_ratio,
            mu: l.friction,
            law: law as u32,
            kind: LawKind::Hertz,
        };
        match model {
            DemContactLaw::HertzMindlin => base,
            DemContactLaw::HertzReissnerMindlin if l.shell_stiffness.is_infinite() => base,
            DemContactLaw::HertzReissnerMindlin => {
                // the law's constants were validated (E*, R* > 0, k_R finite > 0)
                let k_h = base.f_el;
                let k_r = l.shell_stiffness;
                let hr = contact::HertzReissnerScaled::new_unchecked(k_h, k_r);
                ContactConst {
                    s_scale: hr.s_per_overlap,
                    f_el: hr.force_scale,
                    k_t: 8.0 * l.g_star * sr * (k_r / k_h),
                    c_n: l.zeta * (2.0 / 3.0 * m_star * k_r).sqrt(),
                    kind: LawKind::HertzReissner,
                    ..base
                }
            }
            DemContactLaw::LinearSpringDashpot {
                normal_stiffness,
                tangential_stiffness,
            } => ContactConst {
                f_el: normal_stiffness,
                k_t: tangential_stiffness,
                c_n: l.linear_damping * (m_star * normal_stiffness).sqrt(),
                kind: LawKind::Linear,
                ..base
            },
        }
    }
}

/// Elastic normal force, damping coefficient and tangential stiffness of a contact at
/// overlap δ from its precomputed constants (see [`ContactConst`] for the closed forms).
#[inline(always)]
pub(super) fn law_at<const E: u16>(
    k: &ContactConst,
    _model: DemContactLaw,
    _laws: &[PairLaw],
    effects: EffectSet,
    overlap: f64,
) -> (f64, f64, f64) {
    let damping = on::<E>(effects, Effect::Damping);
    match k.kind {
        LawKind::Hertz => {
            let s = overlap.sqrt();
            let c_n = if damping { k.c_n * s.sqrt() } else { 0.0 };
            (k.f_el * s * overlap, c_n, k.k_t * s)
        }
        LawKind::HertzReissner => {
            let u = contact::hertz_reissner_root(k.s_scale * overlap);
            // dF/dδ = k_R 3u/(2 + 3u), so c_n = ζ √(2/3 m* dF/dδ) = c_n √(3u/(2 + 3u))
            let c_n = if damping {
                let w = 3.0 * u;
                k.c_n * (w / (2.0 + w)).sqrt()
            } else {
                0.0
            };
            (k.f_el * (u * u * u), c_n, k.k_t * u)
        }
        LawKind::Linear => {
            let c_n = if damping { k.c_n } else { 0.0 };
            (k.f_el * overlap, c_n, k.k_t)
        }
    }
}

/// Tangential force with Mindlin history, rotated onto the current tangent plane, and the
/// Coulomb cap. Returns the force on the first body and updates `history`.
#[inline(always)]
pub(super) fn tangential_force(
    history: &mut Vec3,
    normal: Vec3,
    v_t: Vec3,
    k_t: f64,
    c_t: f64,
    cap: f64,
    dt: f64,
) -> Vec3 {
    // follow the contact plane: drop the spring's normal part. The length lost per step is
    // (Ω Δt)²/2 of it for a contact turning at rate Ω, negligible over a contact's life, and
    // saves a square root and a division per contact and step.
    let mut xi = *history;
    xi -= xi.dot(normal) * normal;
    xi += v_t * dt;
    let mut f_t = -k_t * xi - c_t * v_t;
    let f2 = f_t.length_squared();
    if f2 > cap * cap {
        // gross sliding: the force sits on the cone; the spring carries it all
        f_t *= cap / f2.sqrt();
        xi = if k_t > 0.0 {
            f_t * (-1.0 / k_t)
        } else {
            Vec3::ZERO
        };
    }
    *history = xi;
    f_t
}
