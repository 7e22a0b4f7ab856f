//! The pair kernel, one contact at a time (the reference the batched kernels reproduce bit
//! for bit): its read-only context ([`PairCtx`]), the arrays of a block it writes
//! ([`PairLists`]), the reach test and the wake bound of pairs out of contact, and the
//! kernel of one pair. [`super::chunk`] runs it over a block.

use super::law::{law_at, tangential_force, ContactConst};
use super::on;
use super::state::{Flips, PairContact, PairDetail, PairOut};
use crate::dem::effects::{Effect, EffectSet};
use crate::dem::material::{DemContactLaw, PairLaw};
use crate::geometry::Vec3;

/// Read-only context of the pair kernel; the wall kernels share it (see [`WallCtx`]).
///
/// [`WallCtx`]: super::wall::WallCtx
#[derive(Clone, Copy)]
pub(super) struct PairCtx<'a> {
    /// The law constants the contacts index (`Simulation::contact_table`).
    pub(super) table: &'a [ContactConst],
    pub(super) position: &'a [Vec3],
    pub(super) velocity: &'a [Vec3],
    pub(super) omega: &'a [Vec3],
    pub(super) radius: &'a [f64],
    pub(super) inertia: &'a [f64],
    pub(super) laws: &'a [PairLaw],
    pub(super) model: DemContactLaw,
    pub(super) effects: EffectSet,
    pub(super) clamp: bool,
    pub(super) dt: f64,
    /// Write the record-only values.
    pub(super) detail: bool,
    /// The CPU has AVX2 and the step uses it (the batched force pass runs four contacts per
    /// instruction).
    pub(super) avx2: bool,
    /// Evaluate contacts in batches.
    pub(super) batched: bool,
    /// Every pair follows the Hertz law ([`LawKind::Hertz`]), so with AVX2 the batched pair
    /// kernel copies the constants without testing the law of each.
    ///
    /// [`LawKind::Hertz`]: super::law::LawKind::Hertz
    pub(super) pairs_hertz: bool,
    /// Every pair indexes the same Hertz or Hertz–Reissner entry of `table` and every
    /// particle has the same radius (m): (entry, radius). The batched pair kernel then writes
    /// the constants and radii into its batch once per call instead of once per contact,
    /// and with AVX2 evaluates the law in its lanes.
    pub(super) pairs_uniform: Option<(u32, f64)>,
    /// The travel bound of this force evaluation, m (see [`Simulation::travel`]).
    pub(super) travel: f64,
    /// A pair is skipped only if half its gap exceeds this, m: `SKIP_STEPS` times the
    /// travel of the last step.
    pub(super) min_skip: f64,
}

/// The per-pair arrays of one block of the pair list that the pair kernels write, cut to
/// the block (index e = pair − block start).
pub(super) struct PairLists<'a> {
    /// In contact at the last force evaluation.
    pub(super) active: &'a mut [bool],
    /// The contact began at the last force evaluation.
    pub(super) onset: &'a mut [bool],
    /// See [`Simulation::pair_wake`].
    pub(super) wake: &'a mut [f64],
    pub(super) out: &'a mut [PairOut],
    pub(super) detail: &'a mut [PairDetail],
    pub(super) rolling: &'a mut [Vec3],
}

/// The centre distance x_j − x_i and its square when pair `p` touches; otherwise ends a
/// contact that was active (flags, history, the gather's overlap) and returns the squared
/// distance and whether a contact ended as the error. Shared by [`pair_kernel`] and the
/// batched kernel.
#[inline(always)]
pub(super) fn pair_in_reach(
    p: &mut PairContact,
    active: &mut bool,
    onset: &mut bool,
    out: &mut PairOut,
    position: &[Vec3],
    reach2: f64,
) -> std::result::Result<(Vec3, f64), (f64, bool)> {
    let d = position[p.j as usize] - position[p.i as usize];
    let dist2 = d.length_squared();
    if dist2 >= reach2 || dist2 == 0.0 {
        // an inactive pair has nothing to reset: its output slot already reads "no contact"
        // (onset is only ever set together with active)
        let ended = *active;
        if ended {
            *active = false;
            *onset = false;
            p.history = Vec3::ZERO;
            out.overlap = 0.0;
        }
        return Err((dist2, ended));
    }
    Ok((d, dist2))
}

/// The travel (see [`Simulation::pair_wake`]) below which a pair whose centres are
/// √`dist2` apart, `r_sum` (m) needed to touch, found so when the travel was `travel`,
/// cannot touch: each particle moves at most the travel's growth, so the gap closes at most
/// twice as fast. The margin (a relative 1e-9 of the gap and 64 ε r_sum) covers the rounding
/// of the distances, far below any physical length of a scene. A pair that could touch
/// within a few steps (half its gap below `min_skip`, m) is tested every step instead
/// (−∞): the kernel's skip test then follows a steady pattern the branch predictor learns,
/// rather than turning every few steps.
#[inline(always)]
pub(super) fn wake_travel(travel: f64, dist2: f64, r_sum: f64, min_skip: f64) -> f64 {
    // within r_sum + 2 min_skip the pair is tested every step: decided without the square
    // root (a pair at the border may go either way; both are exact)
    let near = r_sum + 2.0 * min_skip;
    if dist2 <= near * near {
        return f64::NEG_INFINITY;
    }
    let gap = dist2.sqrt() - r_sum;
    let half = 0.5 * (gap * (1.0 - 1e-9) - 64.0 * f64::EPSILON * r_sum);
    if half > min_skip {
        travel + half
    } else {
        f64::NEG_INFINITY
    }
}

/// Force of one candidate pair; returns whether a contact began.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn pair_kernel<const E: u16>(
    p: &mut PairContact,
    active: &mut bool,
    onset_flag: &mut bool,
    k: &ContactConst,
    out: &mut PairOut,
    detail: &mut PairDetail,
    rolling_torque: &mut Vec3,
    c: &PairCtx<'_>,
) -> Flips {
    let r_sum = c.radius[p.i as usize] + c.radius[p.j as usize];
    let (d, dist2) = match pair_in_reach(p, active, onset_flag, out, c.position, r_sum * r_sum) {
        Ok(hit) => hit,
        Err((_, ended)) => {
            return Flips {
                onsets: 0,
                ends: ended as u32,
            }
        }
    };
    let (i, j) = (p.i as usize, p.j as usize);
    let dist = dist2.sqrt();
    // rounding can give dist = r_sum for dist² just below r_sum²; keep the overlap positive,
    // the gather's activity test
    let overlap = (r_sum - dist).max(f64::MIN_POSITIVE);
    let n = d * (1.0 / dist); // one division instead of three
    let rotation = on::<E>(c.effects, Effect::Rotation);
    let mut v_rel = c.velocity[i] - c.velocity[j];
    if rotation {
        let arm_i = c.radius[i] - 0.5 * overlap;
        let arm_j = c.radius[j] - 0.5 * overlap;
        v_rel += (arm_i * c.omega[i] + arm_j * c.omega[j]).cross(n);
    }
    let v_n = v_rel.dot(n); // > 0 approaching
    let onset = !*active;
    *active = true;
    *onset_flag = onset;
    let v_t = v_rel - v_n * n;
    if onset {
        detail.onset_normal_speed = v_n;
        detail.onset_tangential_speed = v_t.length();
    }
    let (f_el, c_n, k_t) = law_at::<E>(k, c.model, c.laws, c.effects, overlap);
    let mut f_n = f_el + c_n * v_n;
    if c.clamp && f_n < 0.0 {
        f_n = 0.0;
    }
    let mut force = -f_n * n;
    let mut torque_per_arm = Vec3::ZERO;
    if on::<E>(c.effects, Effect::Friction) {
        let f_t = tangential_force(
            &mut p.history,
            n,
            v_t,
            k_t,
            c_n * k.ct_ratio,
            k.mu * f_n.max(0.0),
            c.dt,
        );
        force += f_t;
        if rotation {
            torque_per_arm = n.cross(f_t);
        }
    }
    if on::<E>(c.effects, Effect::RollingResistance) {
        let law = &c.laws[k.law as usize];
        let w_rel = c.omega[i] - c.omega[j];
        let w_roll = w_rel - w_rel.dot(n) * n;
        let w_mag = w_roll.length();
        if w_mag > 0.0 {
            let i_star = c.inertia[i] * c.inertia[j] / (c.inertia[i] + c.inertia[j]);
            // constant torque, but never more than what stops the relative rolling in one step
            let m = (law.rolling_friction * k.r_star * f_n.max(0.0)).min(i_star * w_mag / c.dt);
            *rolling_torque = -m / w_mag * w_roll;
        } else {
            *rolling_torque = Vec3::ZERO;
        }
    }
    if c.detail {
        detail.normal = n;
        detail.normal_force = f_n;
    }
    *out = PairOut {
        force,
        torque_per_arm,
        overlap,
    };
    Flips {
        onsets: onset as u32,
        ends: 0,
    }
}
