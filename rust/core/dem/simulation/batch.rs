//! Batched contact kernels: the pairs of a block, or the wall slots of a block of particles,
//! evaluated up to [`BATCH`] at a time in short passes (find and gather, geometry, laws,
//! forces, scatter), the geometry and force passes four contacts per instruction with AVX2.
//! Every contact goes through the IEEE operations of the one-at-a-time kernels
//! ([`super::pair::pair_kernel`], [`super::wall::wall_kernel`]) in their order, so results
//! are bitwise theirs (`tests/dem_determinism.rs` checks it on both builds).

use super::law::{law_at, tangential_force, ContactConst, LawKind};
use super::pair::{pair_in_reach, wake_travel, PairCtx, PairLists};
use super::state::{Flips, PairContact, PairOut, WallContact, WallDetail, WallOut};
use super::wall::{wall_touch, BlockWalls, WallCtx, WallTouch};
use super::{on, PAIR_CHUNK};
use crate::dem::effects::Effect;
use crate::geometry::Vec3;

#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(target_arch = "x86_64")]
pub(super) use avx2::advance4;

/// Contacts handled together by the batched kernels ([`pair_chunk`], [`wall_chunk`]).
///
/// [`pair_chunk`]: super::pair::pair_chunk
/// [`wall_chunk`]: super::wall::wall_chunk
pub(super) const BATCH: usize = 64;

/// Three components of up to [`BATCH`] vectors, each in its own array, so the elementwise
/// loops over a batch compile to packed (SIMD) arithmetic.
#[derive(Clone, Copy)]
struct Lanes3 {
    x: [f64; BATCH],
    y: [f64; BATCH],
    z: [f64; BATCH],
}

impl Lanes3 {
    const ZERO: Self = Lanes3 {
        x: [0.0; BATCH],
        y: [0.0; BATCH],
        z: [0.0; BATCH],
    };

    #[inline(always)]
    fn get(&self, k: usize) -> Vec3 {
        Vec3::new(self.x[k], self.y[k], self.z[k])
    }

    #[inline(always)]
    fn set(&mut self, k: usize, v: Vec3) {
        self.x[k] = v.x;
        self.y[k] = v.y;
        self.z[k] = v.z;
    }
}

/// Up to [`BATCH`] contacts (pairs or wall slots) in flight. The batched kernels run in
/// passes over it: find the contacts and gather their inputs, evaluate the normal laws,
/// evaluate the forces ([`contact_forces`]), scatter the results. Each pass is a short loop
/// whose iterations are independent, so the processor overlaps many contacts (and the force
/// pass is packed SIMD), where the one-contact-at-a-time kernel is one long dependency chain
/// per contact. Every contact goes through the same IEEE operations in the same order as in
/// [`pair_kernel`] and [`wall_kernel`], so the results are bitwise theirs.
///
/// [`pair_kernel`]: super::pair::pair_kernel
/// [`wall_kernel`]: super::wall::wall_kernel
pub(super) struct Batch {
    len: usize,
    /// Index of the contact in its block (pair or slot).
    index: [u32; BATCH],
    /// Unit normal, from the particle (pair: i) towards the partner; for pairs, x_j − x_i
    /// until [`pair_geometry`] normalises it.
    n: Lanes3,
    /// Overlap δ, m; for pairs, |x_j − x_i|² until [`pair_geometry`].
    overlap: [f64; BATCH],
    /// Pairs: r_i + r_j, r_i, r_j (m), ω_i, ω_j (rad/s), from which [`pair_geometry`] makes
    /// the overlap, the normal and `spin`.
    r_sum: [f64; BATCH],
    r_i: [f64; BATCH],
    r_j: [f64; BATCH],
    omega_i: Lanes3,
    omega_j: Lanes3,
    /// Lever arm of the particle (walls), m.
    arm: [f64; BATCH],
    /// Relative translational velocity of the particle (pair: i) against the partner, m/s.
    v_rel: Lanes3,
    /// Σ arm ω (pair: arm_i ω_i + arm_j ω_j; wall: arm ω), m/s; its cross product with n is
    /// the rotational part of the relative velocity.
    spin: Lanes3,
    /// Mindlin spring ξ, m: read and written by the force pass.
    history: Lanes3,
    /// Law values at δ: elastic normal force (N), damping (N·s/m), tangential stiffness (N/m);
    /// for a Hertz contact whose `hertz` mask is set, the constants `f_el`, `c_n`, `k_t` of
    /// its [`ContactConst`] instead, and the AVX2 force pass evaluates the law.
    f_el: [f64; BATCH],
    c_n: [f64; BATCH],
    k_t: [f64; BATCH],
    ct_ratio: [f64; BATCH],
    mu: [f64; BATCH],
    /// All bits set where `f_el`, `c_n`, `k_t` hold Hertz constants, not law values.
    hertz: [u64; BATCH],
    /// (k_H/k_R)², 1/m, of a Hertz–Reissner contact ([`ContactConst`]), for the AVX2 force
    /// pass that evaluates that law in its lanes.
    s_scale: [f64; BATCH],
    // ---- results
    /// Force on the particle (pair: i), N.
    force: Lanes3,
    /// n × f_t (the torque per unit arm), N.
    torque_per_arm: Lanes3,
    /// Normal force, N (written on detail steps only).
    f_n: [f64; BATCH],
}

thread_local! {
    /// Each thread's batch (16 kB), reused by every chunk it runs.
    pub(super) static BATCH_SCRATCH: std::cell::RefCell<Batch> = const { std::cell::RefCell::new(Batch::EMPTY) };
}

impl Batch {
    const EMPTY: Batch = Batch {
        len: 0,
        index: [0; BATCH],
        n: Lanes3::ZERO,
        overlap: [0.0; BATCH],
        r_sum: [0.0; BATCH],
        r_i: [0.0; BATCH],
        r_j: [0.0; BATCH],
        omega_i: Lanes3::ZERO,
        omega_j: Lanes3::ZERO,
        arm: [0.0; BATCH],
        v_rel: Lanes3::ZERO,
        spin: Lanes3::ZERO,
        history: Lanes3::ZERO,
        f_el: [0.0; BATCH],
        c_n: [0.0; BATCH],
        k_t: [0.0; BATCH],
        ct_ratio: [0.0; BATCH],
        mu: [0.0; BATCH],
        hertz: [0; BATCH],
        s_scale: [0.0; BATCH],
        force: Lanes3::ZERO,
        torque_per_arm: Lanes3::ZERO,
        f_n: [0.0; BATCH],
    };

    /// Constants of contact `k`, copied while its record is at hand: the Hertz constants
    /// where the AVX2 force pass evaluates the law; returns `true` where the law values are
    /// still to be set by [`Batch::set_law`] once the overlap is known.
    #[inline(always)]
    fn set_constants(&mut self, k: usize, konst: &ContactConst, c: &PairCtx<'_>) -> bool {
        let hertz = c.avx2 && konst.kind == LawKind::Hertz;
        self.copy_constants(k, konst, hertz);
        !hertz
    }

    /// The constants of contact `k`, with the `hertz` mask as given (see
    /// [`Batch::set_constants`]; a caller that knows the law skips its test).
    #[inline(always)]
    fn copy_constants(&mut self, k: usize, konst: &ContactConst, hertz: bool) {
        self.hertz[k] = if hertz { u64::MAX } else { 0 };
        self.f_el[k] = konst.f_el;
        self.c_n[k] = konst.c_n;
        self.k_t[k] = konst.k_t;
        self.ct_ratio[k] = konst.ct_ratio;
        self.mu[k] = konst.mu;
        self.s_scale[k] = konst.s_scale;
    }

    /// Every lane's Hertz constants set to `konst` (see [`WallLists::plane_const`]).
    ///
    /// [`WallLists::plane_const`]: super::lists::WallLists::plane_const
    #[inline(always)]
    fn fill_constants(&mut self, konst: &ContactConst) {
        for k in 0..BATCH {
            self.copy_constants(k, konst, true);
        }
    }

    /// Every lane's constants and radii set to those of a uniform pair list (see
    /// [`PairCtx::pairs_uniform`]): Hertz constants `konst`, radii `r` (r_sum = r + r).
    #[inline(always)]
    fn fill_uniform(&mut self, konst: &ContactConst, r: f64) {
        self.fill_constants(konst);
        for k in 0..BATCH {
            self.r_sum[k] = r + r;
            self.r_i[k] = r;
            self.r_j[k] = r;
        }
    }

    /// Normal n, normal relative speed v_n (m/s) and tangential relative velocity v_t (m/s)
    /// of contact `k` from the batch's inputs: the force pass's first operations.
    #[inline(always)]
    fn relative_velocity(&self, k: usize, rotation: bool) -> (Vec3, f64, Vec3) {
        let n = self.n.get(k);
        let mut v_rel = self.v_rel.get(k);
        if rotation {
            v_rel += self.spin.get(k).cross(n);
        }
        let v_n = v_rel.dot(n);
        (n, v_n, v_rel - v_n * n)
    }

    /// Normal and tangential relative speed of contact `k` (m/s), bitwise the force pass's
    /// values; for the onset record, made only at onsets (the force pass does not store them
    /// for every contact).
    #[inline(always)]
    fn onset_speeds(&self, k: usize, rotation: bool) -> (f64, f64) {
        let (_, v_n, v_t) = self.relative_velocity(k, rotation);
        (v_n, v_t.length())
    }

    /// Law values of the contacts whose law is pending (see [`Batch::set_constants`]).
    #[inline(always)]
    fn set_laws<const E: u16>(&mut self, c: &PairCtx<'_>, konst: impl Fn(usize) -> ContactConst) {
        for k in 0..self.len.min(BATCH) {
            if self.hertz[k] == 0 {
                let kk = konst(self.index[k] as usize);
                let (f_el, c_n, k_t) =
                    law_at::<E>(&kk, c.model, c.laws, c.effects, self.overlap[k]);
                self.f_el[k] = f_el;
                self.c_n[k] = c_n;
                self.k_t[k] = k_t;
            }
        }
    }
}

/// Overlap, unit normal and spin of the pairs of a batch from their centre distance: the
/// operations of [`pair_kernel`] in its order.
///
/// [`pair_kernel`]: super::pair::pair_kernel
#[inline(always)]
fn pair_geometry<const E: u16>(b: &mut Batch, c: &PairCtx<'_>) {
    #[cfg(target_arch = "x86_64")]
    if c.avx2 {
        // SAFETY: `avx2` is set only when the CPU reported AVX2.
        unsafe { avx2::pair_geometry::<E>(b, c) };
        return;
    }
    let rotation = on::<E>(c.effects, Effect::Rotation);
    for k in 0..b.len.min(BATCH) {
        let d = b.n.get(k);
        let dist = b.overlap[k].sqrt();
        // rounding can give dist = r_sum for dist² just below r_sum²; keep the overlap
        // positive, the gather's activity test
        let overlap = (b.r_sum[k] - dist).max(f64::MIN_POSITIVE);
        b.n.set(k, d * (1.0 / dist));
        b.overlap[k] = overlap;
        if rotation {
            let arm_i = b.r_i[k] - 0.5 * overlap;
            let arm_j = b.r_j[k] - 0.5 * overlap;
            b.spin
                .set(k, arm_i * b.omega_i.get(k) + arm_j * b.omega_j.get(k));
        }
    }
}

/// Force pass of a batch: normal force with damping and clamp, Mindlin tangential force with
/// the Coulomb cap, n × f_t; the operations of [`pair_kernel`] and [`wall_kernel`] in their
/// order (the scalar loop here, the AVX2 build in `avx2` with selects for branches).
/// `all_hertz`: every lane's `hertz` mask is set (the AVX2 pass then skips the masks).
///
/// [`pair_kernel`]: super::pair::pair_kernel
/// [`wall_kernel`]: super::wall::wall_kernel
#[inline(always)]
fn contact_forces<const E: u16>(b: &mut Batch, c: &PairCtx<'_>, all_hertz: bool) {
    #[cfg(target_arch = "x86_64")]
    if c.avx2 {
        // SAFETY: `avx2` is set only when the CPU reported AVX2.
        unsafe {
            if all_hertz {
                avx2::contact_forces::<E, true, false>(b, c)
            } else {
                avx2::contact_forces::<E, false, false>(b, c)
            }
        };
        return;
    }
    let _ = all_hertz;
    let rotation = on::<E>(c.effects, Effect::Rotation);
    let friction = on::<E>(c.effects, Effect::Friction);
    let (clamp, dt) = (c.clamp, c.dt);
    for k in 0..b.len.min(BATCH) {
        let (n, v_n, v_t) = b.relative_velocity(k, rotation);
        let c_n = b.c_n[k];
        let mut f_n = b.f_el[k] + c_n * v_n;
        if clamp && f_n < 0.0 {
            f_n = 0.0;
        }
        let mut force = -f_n * n;
        let mut torque_per_arm = Vec3::ZERO;
        if friction {
            let mut xi = b.history.get(k);
            let f_t = tangential_force(
                &mut xi,
                n,
                v_t,
                b.k_t[k],
                c_n * b.ct_ratio[k],
                b.mu[k] * f_n.max(0.0),
                dt,
            );
            b.history.set(k, xi);
            force += f_t;
            if rotation {
                torque_per_arm = n.cross(f_t);
            }
        }
        b.force.set(k, force);
        b.torque_per_arm.set(k, torque_per_arm);
        if c.detail {
            b.f_n[k] = f_n;
        }
    }
}

// The layouts `plane_slots` and `pair_rows` read and write whole rows of.
const _: () = {
    use std::mem::{offset_of, size_of};
    assert!(size_of::<Vec3>() == 24 && offset_of!(Vec3, y) == 8 && offset_of!(Vec3, z) == 16);
    assert!(offset_of!(ContactConst, k_t) == offset_of!(ContactConst, f_el) + 8);
    assert!(offset_of!(ContactConst, c_n) == offset_of!(ContactConst, f_el) + 16);
    assert!(offset_of!(ContactConst, ct_ratio) == offset_of!(ContactConst, f_el) + 24);
    assert!(size_of::<WallOut>() == 48 && offset_of!(WallOut, torque) == 24);
    assert!(size_of::<WallContact>() == 40 && size_of::<PairContact>() == 32);
    assert!(size_of::<PairOut>() == 64 && offset_of!(PairOut, force) == 0);
    assert!(offset_of!(PairOut, torque_per_arm) == 24 && offset_of!(PairOut, overlap) == 48);
};

/// The pairs of one block in batches (see [`Batch`]); onsets and ends are added to `flips`,
/// one entry per `PAIR_CHUNK` pairs of the block, which starts at a multiple of it. The
/// batches run on across those chunks: only the block's last batch is partial (with a call
/// per chunk of 256 pairs, each chunk ended in a partial batch, and a few groups of four
/// leave the processor little to overlap; one call per block ran 1.02–1.04× faster, stop 19).
/// `U`: the pairs are uniform ([`PairCtx::pairs_uniform`], with AVX2), so their constants
/// and radii are written into the batch once and their reach is one number.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn pair_chunk_batched<const E: u16, const U: bool>(
    chunk: &mut [PairContact],
    lists: PairLists<'_>,
    konst: &[u32],
    flips: &mut [Flips],
    c: &PairCtx<'_>,
    b: &mut Batch,
) {
    let rotation = on::<E>(c.effects, Effect::Rotation);
    // every pair's law is evaluated by the AVX2 force pass: no per-pair test of the law
    let hertz = c.avx2 && c.pairs_hertz;
    // one law entry and one radius for every pair: written into the batch once per call
    let mut uniform_r_sum = 0.0;
    // the uniform entry's law is Hertz–Reissner (else Hertz): the lanes evaluate that law
    let mut reissner = false;
    if U {
        if let Some((k, r)) = c.pairs_uniform {
            let konst = &c.table[k as usize];
            b.fill_uniform(konst, r);
            uniform_r_sum = r + r;
            reissner = konst.kind == LawKind::HertzReissner;
        }
    }
    let uniform_reach2 = uniform_r_sum * uniform_r_sum;
    let travel = c.travel;
    let len = chunk.len();
    let (active, onset_flags, wake, out, detail, konst) = (
        &mut lists.active[..len],
        &mut lists.onset[..len],
        &mut lists.wake[..len],
        &mut lists.out[..len],
        &mut lists.detail[..len],
        &konst[..len],
    );
    // the particle arrays cut to the positions' length: a pair that passed the reach test
    // has i, j below it, so reading its velocities, spins and radii needs no further test
    let n = c.position.len();
    let (velocity, omega, radius) = (&c.velocity[..n], &c.omega[..n], &c.radius[..n]);
    // the pairs to test, 64 at a time: bit b of `awake` is pair `base + b`, set unless the
    // pair is out of contact and cannot have closed its gap yet. Walking the set bits
    // replaces a branch per pair that goes either way at random in pair order (in the
    // anchors' packed table 40 % of the candidates sleep; callgrind's branch simulator
    // mispredicted 42 % of those branches, the step gained 1.2 % without them, stop 19)
    let (mut next, mut base, mut awake) = (0usize, 0usize, 0u64);
    while next < len || awake != 0 {
        // ---- find the pairs in contact (and end the contacts that stopped)
        // the batch's length, counted in a register (`b.len` is set after the loop)
        let mut m = 0usize;
        let mut pending = false;
        while m < BATCH {
            if awake == 0 {
                if next >= len {
                    break;
                }
                base = next;
                next = (base + 64).min(len);
                for (bit, &w) in wake[base..next].iter().enumerate() {
                    awake |= (u64::from(travel < w) ^ 1) << bit;
                }
                continue;
            }
            let e = base + awake.trailing_zeros() as usize;
            awake &= awake - 1;
            let p = &mut chunk[e];
            let r_sum = if U {
                uniform_r_sum
            } else {
                c.radius[p.i as usize] + c.radius[p.j as usize]
            };
            let reach2 = if U { uniform_reach2 } else { r_sum * r_sum };
            let (a, s) = (&mut active[e], &mut onset_flags[e]);
            let (d, dist2) = match pair_in_reach(p, a, s, &mut out[e], c.position, reach2) {
                Ok(hit) => hit,
                Err((dist2, ended)) => {
                    if ended {
                        if let Some(f) = flips.get_mut(e / PAIR_CHUNK) {
                            f.ends += 1;
                        }
                    }
                    wake[e] = wake_travel(travel, dist2, r_sum, c.min_skip);
                    continue;
                }
            };
            let (i, j) = (p.i as usize, p.j as usize);
            let k = m;
            m += 1;
            b.index[k] = e as u32;
            b.n.set(k, d);
            b.overlap[k] = dist2;
            if U {
                // the velocities, spins and springs are read by `uniform_pairs` straight
                // from their rows, four at a time: copies here, one f64 at a time, cost
                // fifteen stores a pair (1.04× the step without them, stop 22)
                continue;
            }
            b.v_rel.set(k, velocity[i] - velocity[j]);
            if rotation {
                b.omega_i.set(k, omega[i]);
                b.omega_j.set(k, omega[j]);
            }
            b.history.set(k, p.history);
            b.r_sum[k] = r_sum;
            if rotation {
                b.r_i[k] = radius[i];
                b.r_j[k] = radius[j];
            }
            if hertz {
                b.copy_constants(k, &c.table[konst[e] as usize], true);
            } else {
                pending |= b.set_constants(k, &c.table[konst[e] as usize], c);
            }
        }
        b.len = m;
        if U && m > 0 {
            // the last group's lanes past the batch read the rows of its first pair
            for k in m..m.div_ceil(4) * 4 {
                b.index[k] = b.index[0];
            }
        }
        // ---- overlaps and normals, laws, forces (uniform pairs: and the scatter of the
        // groups that go on, leaving the others to the loop below)
        let mut rest = u16::MAX;
        #[cfg(target_arch = "x86_64")]
        if U {
            // SAFETY: `U` is set only with `avx2`, which is set only when the CPU reported
            // AVX2.
            rest = unsafe {
                if reissner {
                    avx2::uniform_pairs::<E, true>(b, c, chunk, active, onset_flags, out)
                } else {
                    avx2::uniform_pairs::<E, false>(b, c, chunk, active, onset_flags, out)
                }
            };
        }
        if !U {
            pair_geometry::<E>(b, c);
            if pending {
                b.set_laws::<E>(c, |e| c.table[konst[e] as usize]);
            }
            contact_forces::<E>(b, c, hertz);
        }
        // ---- scatter
        let mut k = 0;
        while k < b.len {
            if rest >> (k / 4) & 1 == 0 {
                // scattered as rows by `uniform_pairs`
                k += 4;
                continue;
            }
            // (with `U`, `uniform_pairs` took every such group; a window here would start
            // inside a group it left)
            #[cfg(target_arch = "x86_64")]
            if !U
                && c.avx2
                && !c.detail
                && k + 4 <= b.len
                && (0..4).all(|l| active.get(b.index[k + l] as usize) == Some(&true))
            {
                // SAFETY: `avx2` is set only when the CPU reported AVX2.
                unsafe { avx2::pair_rows(b, k, chunk, onset_flags, out) };
                k += 4;
                continue;
            }
            let e = b.index[k] as usize;
            let p = &mut chunk[e];
            let onset = !active[e];
            active[e] = true;
            onset_flags[e] = onset;
            p.history = b.history.get(k);
            let d = &mut detail[e];
            if onset {
                if let Some(f) = flips.get_mut(e / PAIR_CHUNK) {
                    f.onsets += 1;
                }
                (d.onset_normal_speed, d.onset_tangential_speed) = b.onset_speeds(k, rotation);
            }
            if c.detail {
                d.normal = b.n.get(k);
                d.normal_force = b.f_n[k];
            }
            out[e] = PairOut {
                force: b.force.get(k),
                torque_per_arm: b.torque_per_arm.get(k),
                overlap: b.overlap[k],
            };
            k += 1;
        }
    }
}

/// The wall slots of one chunk of particles starting at `first`, in batches (see [`Batch`]):
/// the plane groups of `lists` (AVX2), then its other slots; no scan of the chunk's slots.
#[inline(always)]
pub(super) fn wall_chunk_batched<const E: u16>(
    c: &WallCtx<'_>,
    first: usize,
    lists: BlockWalls<'_>,
    slots: &mut [WallContact],
    out: &mut [WallOut],
    detail: &mut [WallDetail],
    b: &mut Batch,
) {
    let rotation = on::<E>(c.shared.effects, Effect::Rotation);
    let n_slots = slots.len();
    // with AVX2, the plane groups four particles at a time first
    #[cfg(target_arch = "x86_64")]
    if c.shared.avx2 {
        // SAFETY: `avx2` is set only when the CPU reported AVX2.
        unsafe {
            if lists.plane_reissner {
                avx2::plane_slots::<E, true>(c, first, lists, slots, out, detail, b)
            } else {
                avx2::plane_slots::<E, false>(c, first, lists, slots, out, detail, b)
            }
        };
    }
    let (out, detail) = (&mut out[..n_slots], &mut detail[..n_slots]);
    let mut next = 0usize;
    while next < lists.rest.len() {
        // ---- the listed slots, up to a batch of them in contact
        b.len = 0;
        let mut pending = false;
        while next < lists.rest.len() && b.len < BATCH {
            let (i, q) = lists.rest[next];
            next += 1;
            let (i, q) = (first + i as usize, q as usize);
            let Some(s) = slots.get_mut(q) else {
                continue;
            };
            let (x, v, w) = (
                c.shared.position[i],
                c.shared.velocity[i],
                c.shared.omega[i],
            );
            let r = c.shared.radius[i];
            let Some(WallTouch {
                point,
                n,
                overlap,
                arm,
                wall_v,
            }) = wall_touch::<E>(s, x, r, c)
            else {
                continue;
            };
            let k = b.len;
            b.len += 1;
            b.index[k] = q as u32;
            b.n.set(k, n);
            b.overlap[k] = overlap;
            b.arm[k] = arm;
            b.v_rel.set(k, v - wall_v);
            if rotation {
                b.spin.set(k, arm * w);
            }
            b.history.set(k, s.history);
            pending |= b.set_constants(k, &c.shared.table[s.k as usize], &c.shared);
            if !s.active || c.shared.detail {
                // recorded at onset and on detail steps
                detail[q].point = point;
            }
        }
        // ---- laws, forces
        if pending {
            b.set_laws::<E>(&c.shared, |q| c.shared.table[slots[q].k as usize]);
        }
        contact_forces::<E>(b, &c.shared, false);
        // ---- scatter
        for k in 0..b.len {
            let q = b.index[k] as usize;
            let d = &mut detail[q];
            scatter_wall_lane::<E>(b, k, &mut slots[q], Some(&mut out[q]), d, &c.shared);
        }
    }
}

/// Lane `k` of a batch of wall slots back into its slot `s`: the contact state, the onset
/// speeds, the force and torque (unless `out` is `None`: the caller wrote them as rows) and,
/// on detail steps, the record values.
#[inline(always)]
fn scatter_wall_lane<const E: u16>(
    b: &Batch,
    k: usize,
    s: &mut WallContact,
    out: Option<&mut WallOut>,
    d: &mut WallDetail,
    c: &PairCtx<'_>,
) {
    let (detail, rotation) = (c.detail, on::<E>(c.effects, Effect::Rotation));
    let onset = !s.active;
    s.active = true;
    s.onset = onset;
    s.history = b.history.get(k);
    if onset {
        (d.onset_normal_speed, d.onset_tangential_speed) = b.onset_speeds(k, rotation);
    }
    if let Some(o) = out {
        let arm = b.arm[k];
        *o = WallOut {
            force: b.force.get(k),
            torque: arm * b.torque_per_arm.get(k),
        };
    }
    if detail {
        d.normal = b.n.get(k);
        d.overlap = b.overlap[k];
        d.normal_force = b.f_n[k];
    }
}
