//! `contact_forces` on four contacts per instruction (AVX2), and the other lane kernels
//! (the plane pass, the four-particle update). The lanes past the batch's length compute on
//! stale values that nothing reads.
//!
//! The lane primitives ([`V4`] and its arithmetic, loads and stores of rows and lanes) and
//! the four-particle update ([`advance4`]) are here; the plane pass in `plane`, the pair
//! lanes in `pairs`, the force pass and the lanes' Hertz–Reissner root in `forces`.

use super::*;
use crate::dem::effects::EffectSet;
use std::arch::x86_64::*;

mod forces;
mod pairs;
mod plane;

pub(super) use forces::contact_forces;
pub(super) use pairs::{pair_geometry, pair_rows, uniform_pairs};
pub(super) use plane::plane_slots;

/// Three-component vectors of four lanes, with glam's formulas for the products.
#[derive(Clone, Copy)]
struct V4 {
    x: __m256d,
    y: __m256d,
    z: __m256d,
}

#[inline(always)]
unsafe fn zero4() -> V4 {
    let z = _mm256_setzero_pd();
    V4 { x: z, y: z, z }
}

#[inline(always)]
unsafe fn load(l: &Lanes3, k: usize) -> V4 {
    V4 {
        x: _mm256_loadu_pd(l.x.as_ptr().add(k)),
        y: _mm256_loadu_pd(l.y.as_ptr().add(k)),
        z: _mm256_loadu_pd(l.z.as_ptr().add(k)),
    }
}

#[inline(always)]
unsafe fn store(l: &mut Lanes3, k: usize, v: V4) {
    _mm256_storeu_pd(l.x.as_mut_ptr().add(k), v.x);
    _mm256_storeu_pd(l.y.as_mut_ptr().add(k), v.y);
    _mm256_storeu_pd(l.z.as_mut_ptr().add(k), v.z);
}

#[inline(always)]
unsafe fn ld(a: &[f64; BATCH], k: usize) -> __m256d {
    _mm256_loadu_pd(a.as_ptr().add(k))
}

#[inline(always)]
unsafe fn st(a: &mut [f64; BATCH], k: usize, v: __m256d) {
    _mm256_storeu_pd(a.as_mut_ptr().add(k), v)
}

#[inline(always)]
unsafe fn add(a: V4, b: V4) -> V4 {
    V4 {
        x: _mm256_add_pd(a.x, b.x),
        y: _mm256_add_pd(a.y, b.y),
        z: _mm256_add_pd(a.z, b.z),
    }
}

#[inline(always)]
unsafe fn sub(a: V4, b: V4) -> V4 {
    V4 {
        x: _mm256_sub_pd(a.x, b.x),
        y: _mm256_sub_pd(a.y, b.y),
        z: _mm256_sub_pd(a.z, b.z),
    }
}

/// s v (glam's `f64 * DVec3`).
#[inline(always)]
unsafe fn scale(s: __m256d, v: V4) -> V4 {
    V4 {
        x: _mm256_mul_pd(s, v.x),
        y: _mm256_mul_pd(s, v.y),
        z: _mm256_mul_pd(s, v.z),
    }
}

/// (a.x b.x + a.y b.y) + a.z b.z, glam's `dot`.
#[inline(always)]
unsafe fn dot(a: V4, b: V4) -> __m256d {
    _mm256_add_pd(
        _mm256_add_pd(_mm256_mul_pd(a.x, b.x), _mm256_mul_pd(a.y, b.y)),
        _mm256_mul_pd(a.z, b.z),
    )
}

/// glam's `cross`: (a.y b.z − b.y a.z, a.z b.x − b.z a.x, a.x b.y − b.x a.y).
#[inline(always)]
unsafe fn cross(a: V4, b: V4) -> V4 {
    V4 {
        x: _mm256_sub_pd(_mm256_mul_pd(a.y, b.z), _mm256_mul_pd(b.y, a.z)),
        y: _mm256_sub_pd(_mm256_mul_pd(a.z, b.x), _mm256_mul_pd(b.z, a.x)),
        z: _mm256_sub_pd(_mm256_mul_pd(a.x, b.y), _mm256_mul_pd(b.x, a.y)),
    }
}

/// `if m { a } else { b }` per lane and component.
#[inline(always)]
unsafe fn select(m: __m256d, a: V4, b: V4) -> V4 {
    V4 {
        x: _mm256_blendv_pd(b.x, a.x, m),
        y: _mm256_blendv_pd(b.y, a.y, m),
        z: _mm256_blendv_pd(b.z, a.z, m),
    }
}

/// The upper 128 bits of `v`, through an instruction LLVM cannot merge with its
/// neighbours. Left to itself, it folds an extract with an insert, or two 128-bit stores
/// to adjacent addresses, into `vperm2f128`: first-generation Zen runs that as 8 µops
/// (3 cycles of throughput), against 1 µop for the extract and 2 for an insert.
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn hi(v: __m256d) -> __m128d {
    let r: __m128d;
    std::arch::asm!(
        "vextractf128 {r}, {v}, 1",
        v = in(ymm_reg) v,
        r = out(xmm_reg) r,
        options(pure, nomem, nostack, preserves_flags)
    );
    r
}

/// The lower 128 bits of `v` (no instruction).
#[inline(always)]
unsafe fn lo(v: __m256d) -> __m128d {
    _mm256_castpd256_pd128(v)
}

/// (l, h) as one vector: `l` in the lower half (one `vinsertf128`).
#[inline(always)]
unsafe fn join(l: __m128d, h: __m128d) -> __m256d {
    _mm256_insertf128_pd::<1>(_mm256_castpd128_pd256(l), h)
}

/// Four consecutive vectors from `p` (12 f64) as lanes: six 128-bit loads, three of them
/// into upper halves, and three in-lane shuffles (no shuffle across the halves).
#[inline(always)]
unsafe fn load_aos4(p: *const Vec3) -> V4 {
    let f = p as *const f64;
    let m1 = join(_mm_loadu_pd(f), _mm_loadu_pd(f.add(6))); // x0 y0 x2 y2
    let m2 = join(_mm_loadu_pd(f.add(2)), _mm_loadu_pd(f.add(8))); // z0 x1 z2 x3
    let m3 = join(_mm_loadu_pd(f.add(4)), _mm_loadu_pd(f.add(10))); // y1 z1 y3 z3
    V4 {
        x: _mm256_shuffle_pd::<0b1010>(m1, m2),
        y: _mm256_shuffle_pd::<0b0101>(m1, m3),
        z: _mm256_shuffle_pd::<0b1010>(m2, m3),
    }
}

/// Lanes back to four consecutive vectors at `p`: the inverse of [`load_aos4`].
#[inline(always)]
unsafe fn store_aos4(p: *mut Vec3, v: V4) {
    let f = p as *mut f64;
    let m1 = _mm256_unpacklo_pd(v.x, v.y); // x0 y0 x2 y2
    let m3 = _mm256_unpackhi_pd(v.y, v.z); // y1 z1 y3 z3
    let m2 = _mm256_shuffle_pd::<0b1010>(v.z, v.x); // z0 x1 z2 x3
    _mm256_storeu_pd(f, join(lo(m1), lo(m2)));
    _mm256_storeu_pd(f.add(4), _mm256_blend_pd::<0b1100>(m3, m1));
    _mm256_storeu_pd(f.add(8), join(hi(m2), hi(m3)));
}

/// Four vectors held in registers as lanes (in-lane shuffles and inserts only).
#[inline(always)]
unsafe fn lanes4(v: [Vec3; 4]) -> V4 {
    let xy = |l: usize| _mm_setr_pd(v[l].x, v[l].y);
    let (xy02, xy13) = (join(xy(0), xy(2)), join(xy(1), xy(3)));
    V4 {
        x: _mm256_unpacklo_pd(xy02, xy13),
        y: _mm256_unpackhi_pd(xy02, xy13),
        z: join(_mm_setr_pd(v[0].z, v[1].z), _mm_setr_pd(v[2].z, v[3].z)),
    }
}

/// Three f64 at each of `src[l]` as lane l (the inverse of [`store_rows3`]).
#[inline(always)]
unsafe fn load_rows3(src: [*const f64; 4]) -> V4 {
    let xy02 = join(_mm_loadu_pd(src[0]), _mm_loadu_pd(src[2]));
    let xy13 = join(_mm_loadu_pd(src[1]), _mm_loadu_pd(src[3]));
    let z02 = join(_mm_load_sd(src[0].add(2)), _mm_load_sd(src[2].add(2)));
    let z13 = join(_mm_load_sd(src[1].add(2)), _mm_load_sd(src[3].add(2)));
    V4 {
        x: _mm256_unpacklo_pd(xy02, xy13),
        y: _mm256_unpackhi_pd(xy02, xy13),
        z: _mm256_unpacklo_pd(z02, z13),
    }
}

/// The leapfrog update of four consecutive alive particles, four per instruction: the
/// operations of the particle phase's update, in its order, on each lane. `fs`, `ts`:
/// the four forces (N) and torques (N·m), made into lanes in registers (a vector load
/// of values just stored one by one would wait for the stores). Returns the largest squared
/// displacement from `reference` (a NaN one is ignored, as by the scalar update) and the
/// finiteness probe (0, or NaN when a value is not finite).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(in crate::dem::simulation) unsafe fn advance4<const E: u16>(
    fs: [Vec3; 4],
    ts: [Vec3; 4],
    x: &mut [Vec3],
    v: &mut [Vec3],
    w: &mut [Vec3],
    reference: &[Vec3],
    inv_mass: &[f64],
    inv_inertia: &[f64],
    gravity: Vec3,
    dt: f64,
    effects: EffectSet,
) -> (f64, f64, f64) {
    let rotation = on::<E>(effects, Effect::Rotation);
    let planar = on::<E>(effects, Effect::Planar);
    let (x, v, w) = (&mut x[..4], &mut v[..4], &mut w[..4]);
    let (reference, inv_mass, inv_inertia) = (&reference[..4], &inv_mass[..4], &inv_inertia[..4]);
    let zero = _mm256_setzero_pd();
    let dt = _mm256_set1_pd(dt);
    let f = lanes4(fs);
    let g = V4 {
        x: _mm256_set1_pd(gravity.x),
        y: _mm256_set1_pd(gravity.y),
        z: _mm256_set1_pd(gravity.z),
    };
    // v + (f m⁻¹ + g) Δt, x + v Δt
    let a = add(scale(_mm256_loadu_pd(inv_mass.as_ptr()), f), g);
    let v_new = add(load_aos4(v.as_ptr()), scale(dt, a));
    let x_new = add(load_aos4(x.as_ptr()), scale(dt, v_new));
    store_aos4(v.as_mut_ptr(), v_new);
    store_aos4(x.as_mut_ptr(), x_new);
    let s = add(x_new, v_new);
    let mut probe = _mm256_mul_pd(_mm256_add_pd(_mm256_add_pd(s.x, s.y), s.z), zero);
    if rotation {
        let t = lanes4(ts);
        // ω + T (I⁻¹ Δt)
        let k = _mm256_mul_pd(_mm256_loadu_pd(inv_inertia.as_ptr()), dt);
        let mut w_new = add(load_aos4(w.as_ptr()), scale(k, t));
        if planar {
            w_new.x = zero;
            w_new.y = zero;
        }
        store_aos4(w.as_mut_ptr(), w_new);
        let sw = _mm256_add_pd(_mm256_add_pd(w_new.x, w_new.y), w_new.z);
        probe = _mm256_add_pd(probe, _mm256_mul_pd(sw, zero));
    }
    let d = sub(x_new, load_aos4(reference.as_ptr()));
    let disp2 = lanes(dot(d, d));
    let speed2 = lanes(dot(v_new, v_new));
    let p = lanes(probe);
    let mut max = 0.0;
    for q in disp2 {
        if q > max {
            max = q;
        }
    }
    let mut max_v2 = 0.0;
    for q in speed2 {
        if q > max_v2 {
            max_v2 = q;
        }
    }
    (max, max_v2, (p[0] + p[1]) + (p[2] + p[3]))
}

/// (a, c) of lanes 0 and 2, and of lanes 1 and 3: in-lane shuffles only (cheap where a
/// 256-bit operation runs as two 128-bit halves).
#[inline(always)]
unsafe fn lane_pairs(a: __m256d, c: __m256d) -> (__m256d, __m256d) {
    (_mm256_unpacklo_pd(a, c), _mm256_unpackhi_pd(a, c))
}

/// Lane l's two values (a_l, c_l) of `lane_pairs(a, c)`.
#[inline(always)]
unsafe fn lane_pair(v: (__m256d, __m256d), l: usize) -> __m128d {
    let v = if l & 1 == 0 { v.0 } else { v.1 };
    if l < 2 {
        lo(v)
    } else {
        hi(v)
    }
}

/// Lane l of `v` written as three f64 at `dst[l]` (a 16-byte and an 8-byte store).
#[inline(always)]
unsafe fn store_rows3(v: V4, dst: [*mut f64; 4]) {
    let (xy, zz) = (lane_pairs(v.x, v.y), lane_pairs(v.z, v.z));
    for (l, d) in dst.into_iter().enumerate() {
        _mm_storeu_pd(d, lane_pair(xy, l));
        _mm_store_sd(d.add(2), lane_pair(zz, l));
    }
}

/// The lanes of `v` as an array.
#[inline(always)]
unsafe fn lanes(v: __m256d) -> [f64; 4] {
    let mut a = [0.0; 4];
    _mm256_storeu_pd(a.as_mut_ptr(), v);
    a
}

/// 4×4 transpose: lane l of row k becomes lane k of row l.
#[inline(always)]
unsafe fn transpose(a: __m256d, b: __m256d, c: __m256d, d: __m256d) -> [__m256d; 4] {
    let t0 = _mm256_unpacklo_pd(a, b);
    let t1 = _mm256_unpackhi_pd(a, b);
    let t2 = _mm256_unpacklo_pd(c, d);
    let t3 = _mm256_unpackhi_pd(c, d);
    [
        join(lo(t0), lo(t2)),
        join(lo(t1), lo(t3)),
        join(hi(t0), hi(t2)),
        join(hi(t1), hi(t3)),
    ]
}
