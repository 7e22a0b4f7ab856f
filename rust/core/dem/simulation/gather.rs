//! The particle phase: the gather of each particle's pair and wall forces in the fixed order
//! of its lists ([`Gather`], summed in [`Sum3`]), and the leapfrog update, four particles per
//! instruction with AVX2 (`batch::advance4`), one at a time otherwise ([`particle_chunk`]).

use super::batch;
use super::state::{PairOut, WallContact, WallOut};
use super::{on, NO_WALL};
use crate::dem::effects::{Effect, EffectSet};
use crate::geometry::Vec3;

/// Read-only context of the particle phase.
pub(super) struct ParticleCtx<'a> {
    pub(super) pair_rolling: &'a [Vec3],
    pub(super) pair_out: &'a [PairOut],
    /// The gather lists (see [`Simulation::active_entry`]).
    pub(super) active_base: &'a [u32],
    pub(super) active_len: &'a [u32],
    pub(super) active_entry: &'a [u32],
    pub(super) radius: &'a [f64],
    pub(super) inv_mass: &'a [f64],
    pub(super) inv_inertia: &'a [f64],
    pub(super) alive: &'a [bool],
    pub(super) reference_position: &'a [Vec3],
    pub(super) effects: EffectSet,
    pub(super) gravity: Vec3,
    pub(super) dt: f64,
    pub(super) wall_stride: usize,
    /// Write the per-particle records (contact force sum, coordination numbers).
    pub(super) detail: bool,
    /// Advance four particles per AVX2 instruction (`batch::advance4`).
    pub(super) avx2: bool,
}

/// A running sum of vectors (glam's `+=`, component by component). On x86_64 it keeps x
/// and y in one SSE2 register and z apart: left to itself, LLVM packs the gather's force and
/// torque sums into 256-bit shapes that need a lane-crossing `vpermpd` per contact (3 µops
/// on first-generation Zen).
#[derive(Clone, Copy)]
struct Sum3 {
    #[cfg(target_arch = "x86_64")]
    xy: std::arch::x86_64::__m128d,
    #[cfg(not(target_arch = "x86_64"))]
    xy: (f64, f64),
    z: f64,
}

impl Sum3 {
    #[inline(always)]
    fn zero() -> Self {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: SSE2 is part of the x86_64 baseline.
        let xy = unsafe { std::arch::x86_64::_mm_setzero_pd() };
        #[cfg(not(target_arch = "x86_64"))]
        let xy = (0.0, 0.0);
        Sum3 { xy, z: 0.0 }
    }

    /// Adds s v, formed as glam's `v * s` (each component times s; the product commutes).
    #[inline(always)]
    fn add_scaled(&mut self, s: f64, v: Vec3) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: SSE2 is part of the x86_64 baseline.
        unsafe {
            use std::arch::x86_64::*;
            let p = _mm_mul_pd(_mm_setr_pd(v.x, v.y), _mm_set1_pd(s));
            self.xy = _mm_add_pd(self.xy, p);
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            self.xy = (self.xy.0 + v.x * s, self.xy.1 + v.y * s);
        }
        self.z += v.z * s;
    }

    /// Adds v with its sign bits flipped by `flip` (0 or the sign bit): bitwise v times +1.0
    /// or −1.0 (multiplying by ±1 is exact), without the multiply.
    #[inline(always)]
    fn add_flipped(&mut self, flip: u64, v: Vec3) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: SSE2 is part of the x86_64 baseline.
        unsafe {
            use std::arch::x86_64::*;
            let m = _mm_castsi128_pd(_mm_set1_epi64x(flip as i64));
            self.xy = _mm_add_pd(self.xy, _mm_xor_pd(_mm_setr_pd(v.x, v.y), m));
            self.z += _mm_cvtsd_f64(_mm_xor_pd(_mm_set_sd(v.z), m));
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let f = |x: f64| f64::from_bits(x.to_bits() ^ flip);
            self.xy = (self.xy.0 + f(v.x), self.xy.1 + f(v.y));
            self.z += f(v.z);
        }
    }

    /// Adds v.
    #[inline(always)]
    fn add(&mut self, v: Vec3) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: SSE2 is part of the x86_64 baseline.
        unsafe {
            use std::arch::x86_64::*;
            self.xy = _mm_add_pd(self.xy, _mm_setr_pd(v.x, v.y));
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            self.xy = (self.xy.0 + v.x, self.xy.1 + v.y);
        }
        self.z += v.z;
    }

    #[inline(always)]
    fn get(self) -> Vec3 {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: SSE2 is part of the x86_64 baseline.
        let (x, y) = unsafe {
            use std::arch::x86_64::*;
            (
                _mm_cvtsd_f64(self.xy),
                _mm_cvtsd_f64(_mm_unpackhi_pd(self.xy, self.xy)),
            )
        };
        #[cfg(not(target_arch = "x86_64"))]
        let (x, y) = self.xy;
        Vec3::new(x, y, self.z)
    }
}

/// What the particle phase reads to sum the forces on a particle (see [`Gather::particle`]).
struct Gather<'a> {
    c: &'a ParticleCtx<'a>,
    /// The chunk's slices (index k = particle − first).
    radius: &'a [f64],
    active_base: &'a [u32],
    active_len: &'a [u32],
    /// The pair arrays, cut to one length.
    pair_out: &'a [PairOut],
    pair_rolling: &'a [Vec3],
    slots: &'a [WallContact],
    wall_out: &'a [WallOut],
    stride: usize,
}

impl Gather<'_> {
    /// Force and torque on particle k of the chunk, its coordination numbers (pairs, walls)
    /// and its wall onsets: the pairs in list order, then the wall slots in slot order.
    #[inline(always)]
    fn particle<const E: u16>(&self, k: usize) -> (Vec3, Vec3, u32, u32, u32) {
        let Gather {
            c,
            radius,
            active_base,
            active_len,
            pair_out,
            pair_rolling,
            slots,
            wall_out,
            stride,
        } = *self;
        let rotation = on::<E>(c.effects, Effect::Rotation);
        let rolling = on::<E>(c.effects, Effect::RollingResistance);
        let planar = on::<E>(c.effects, Effect::Planar);
        let mut f = Sum3::zero();
        let mut t = Sum3::zero();
        // the pairs in contact in increasing index order (those where the particle is j
        // first, as their i is smaller); the force on i is +force, on j −force: added times
        // ±1, which is exactly the subtraction
        let start = active_base[k] as usize;
        let listed = c
            .active_entry
            .get(start..start + active_len[k] as usize)
            .unwrap_or(&[]);
        // every entry names a pair of `pair_out` (the lists are made from the pair list)
        let z = listed.len() as u32;
        let r = radius[k];
        for &a in listed {
            let e = (a >> 1) as usize;
            let Some(p) = pair_out.get(e) else {
                continue;
            };
            // + for the first particle (a even), − for the second (a odd): the sign bit
            // flipped
            let flip = u64::from(a) << 63;
            f.add_flipped(flip, p.force);
            if rotation {
                let arm = r - 0.5 * p.overlap;
                t.add_scaled(arm, p.torque_per_arm);
                if rolling {
                    t.add_flipped(flip, pair_rolling[e]);
                }
            }
        }
        if planar {
            // upright cartridges cannot climb on each other: particle forces act in the plane
            f.z = 0.0;
        }
        let mut zw = 0u32;
        let mut onsets = 0u32;
        let row = k * stride;
        let (own, out) = (&slots[row..row + stride], &wall_out[row..row + stride]);
        for q in 0..stride {
            let (s, o) = (&own[q], &out[q]);
            if s.wall == NO_WALL {
                break;
            }
            if s.active {
                zw += 1;
                if s.onset {
                    onsets += 1;
                }
                f.add(o.force);
                t.add(o.torque);
            }
        }
        (f.get(), t.get(), z, zw, onsets)
    }
}

/// Particle phase on one chunk of particles starting at `first`. Returns (largest squared
/// displacement since the last rebuild (m²), largest squared new speed (m²/s²), any
/// non-finite value, wall onsets).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn particle_chunk<const E: u16>(
    c: &ParticleCtx<'_>,
    first: usize,
    position: &mut [Vec3],
    velocity: &mut [Vec3],
    omega: &mut [Vec3],
    force_sum: &mut [Vec3],
    coordination: &mut [u32],
    wall_coordination: &mut [u32],
    slots: &[WallContact],
    wall_out: &[WallOut],
) -> (f64, f64, bool, u32) {
    let rotation = on::<E>(c.effects, Effect::Rotation);
    let rolling = on::<E>(c.effects, Effect::RollingResistance);
    let planar = on::<E>(c.effects, Effect::Planar);
    let gravity = if on::<E>(c.effects, Effect::Gravity) {
        c.gravity
    } else {
        Vec3::ZERO
    };
    let mut max_disp2: f64 = 0.0;
    let mut max_v2: f64 = 0.0;
    // 0 × finite = 0 while 0 × (inf or NaN) = NaN: one multiply-add per particle instead of
    // nine finiteness tests, checked once per chunk
    let mut probe = Vec3::ZERO;
    let mut wall_onsets = 0u32;
    // every per-particle array cut to this chunk once, so the loop indexes by k < len
    // without further bounds checks
    let len = position.len();
    let last = first + len;
    let alive = &c.alive[first..last];
    let radius = &c.radius[first..last];
    let inv_mass = &c.inv_mass[first..last];
    let inv_inertia = &c.inv_inertia[first..last];
    let reference = &c.reference_position[first..last];
    let active_base = &c.active_base[first..last];
    let active_len = &c.active_len[first..last];
    let (velocity, omega) = (&mut velocity[..len], &mut omega[..len]);
    let (force_sum, coordination) = (&mut force_sum[..len], &mut coordination[..len]);
    let wall_coordination = &mut wall_coordination[..len];
    let n_pairs = c.pair_out.len();
    let pair_out = &c.pair_out[..n_pairs];
    let pair_rolling = if rolling {
        &c.pair_rolling[..n_pairs]
    } else {
        &[]
    };
    let stride = c.wall_stride;
    let (slots, wall_out) = (&slots[..len * stride], &wall_out[..len * stride]);
    let g = Gather {
        c,
        radius,
        active_base,
        active_len,
        pair_out,
        pair_rolling,
        slots,
        wall_out,
        stride,
    };
    let gather = |k: usize| g.particle::<E>(k);
    let mut k = 0;
    while k < len {
        #[cfg(target_arch = "x86_64")]
        if c.avx2 && k + 4 <= len && alive[k..k + 4].iter().all(|&a| a) {
            // four particles: gathered one by one, advanced four per instruction
            macro_rules! one {
                ($l:expr) => {{
                    let (f, t, z, zw, onsets) = gather(k + $l);
                    wall_onsets += onsets;
                    if c.detail {
                        force_sum[k + $l] = f;
                        coordination[k + $l] = z;
                        wall_coordination[k + $l] = zw;
                    }
                    (f, t)
                }};
            }
            // written out four times, not a loop over an array: the sums stay in registers
            // (an array filled in a loop goes through the stack, and its reload as lanes
            // waits on the stores)
            let ((f0, t0), (f1, t1)) = (one!(0), one!(1));
            let ((f2, t2), (f3, t3)) = (one!(2), one!(3));
            let (fs, ts) = ([f0, f1, f2, f3], [t0, t1, t2, t3]);
            // SAFETY: `avx2` is set only when the CPU reported AVX2.
            let (disp2, v2, p) = unsafe {
                batch::advance4::<E>(
                    fs,
                    ts,
                    &mut position[k..k + 4],
                    &mut velocity[k..k + 4],
                    &mut omega[k..k + 4],
                    &reference[k..k + 4],
                    &inv_mass[k..k + 4],
                    &inv_inertia[k..k + 4],
                    gravity,
                    c.dt,
                    c.effects,
                )
            };
            probe.x += p;
            if disp2 > max_disp2 {
                max_disp2 = disp2;
            }
            if v2 > max_v2 {
                max_v2 = v2;
            }
            k += 4;
            continue;
        }
        if !alive[k] {
            k += 1;
            continue;
        }
        let (f, t, z, zw, onsets) = gather(k);
        wall_onsets += onsets;
        let (x, v, w) = (position[k], velocity[k], omega[k]);
        if c.detail {
            force_sum[k] = f;
            coordination[k] = z;
            wall_coordination[k] = zw;
        }
        let v_new = v + (f * inv_mass[k] + gravity) * c.dt;
        let x_new = x + v_new * c.dt;
        velocity[k] = v_new;
        position[k] = x_new;
        if rotation {
            let mut w_new = w + t * (inv_inertia[k] * c.dt);
            if planar {
                w_new.x = 0.0;
                w_new.y = 0.0;
            }
            omega[k] = w_new;
            probe += w_new * 0.0;
        }
        probe += (x_new + v_new) * 0.0;
        // a NaN displacement is caught by the probe; no NaN-aware max needed
        let disp2 = (x_new - reference[k]).length_squared();
        if disp2 > max_disp2 {
            max_disp2 = disp2;
        }
        let v2 = v_new.length_squared();
        if v2 > max_v2 {
            max_v2 = v2;
        }
        k += 1;
    }
    (max_disp2, max_v2, !probe.is_finite(), wall_onsets)
}
