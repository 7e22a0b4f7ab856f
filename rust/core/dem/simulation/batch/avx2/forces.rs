//! The force pass on four contacts ([`forces4`]): the normal law (Hertz, or Hertz–Reissner
//! through the lanes' root [`hertz_reissner_root4`]), damping and clamp, the Mindlin spring
//! with the Coulomb cap, and the batch's force pass built on it ([`contact_forces`]).

use super::*;
use crate::contact;

/// ⌊x / 3⌋ of four u64 lanes below 2⁶³ (AVX2 has no 64-bit division or high multiply):
/// x = h 2³² + l, ⌊x/3⌋ = ⌊h/3⌋ 2³² + r_h ⌊2³²/3⌋ + ⌊l/3⌋ + ⌊(r_h + r_l)/3⌋, with r_h, r_l
/// the remainders (2³² = 3 ⌊2³²/3⌋ + 1) and ⌊a/3⌋ = (a · 0xAAAAAAAB) >> 33 for a < 2³².
#[inline(always)]
unsafe fn div3_u64(x: __m256i) -> __m256i {
    let magic = _mm256_set1_epi64x(0xAAAA_AAAB);
    let div3_32 = |a: __m256i| _mm256_srli_epi64::<33>(_mm256_mul_epu32(a, magic));
    let times3 = |a: __m256i| _mm256_add_epi64(_mm256_slli_epi64::<1>(a), a);
    let hi = _mm256_srli_epi64::<32>(x);
    let lo = _mm256_and_si256(x, _mm256_set1_epi64x(0xFFFF_FFFF));
    let (q_hi, q_lo) = (div3_32(hi), div3_32(lo));
    let r_hi = _mm256_sub_epi64(hi, times3(q_hi));
    let r_lo = _mm256_sub_epi64(lo, times3(q_lo));
    // r_h + r_l ≤ 4: its third is 1 from 3 up
    let carry = _mm256_srli_epi64::<63>(_mm256_cmpgt_epi64(
        _mm256_add_epi64(r_hi, r_lo),
        _mm256_set1_epi64x(2),
    ));
    let low = _mm256_add_epi64(
        _mm256_add_epi64(
            _mm256_mul_epu32(r_hi, _mm256_set1_epi64x(0x5555_5555)),
            q_lo,
        ),
        carry,
    );
    _mm256_add_epi64(_mm256_slli_epi64::<32>(q_hi), low)
}

/// [`contact::hertz_reissner_root`] of four lanes, its operations in its order (bitwise
/// its results); a lane whose s is 1e45 or more (the asymptote's branch, never met by
/// physical overlaps) is solved by the scalar function.
#[inline(always)]
unsafe fn hertz_reissner_root4(s: __m256d) -> __m256d {
    let zero = _mm256_setzero_pd();
    let r2 = _mm256_sqrt_pd(s);
    let bits = _mm256_castpd_si256(s);
    let r3 = _mm256_castsi256_pd(_mm256_add_epi64(
        div3_u64(bits),
        _mm256_set1_epi64x(0x2A9F_7893_782D_A1CE),
    ));
    // r2.min((r3 − 1/3).max(0.75 r3)) (all finite and > 0 here, where min and max
    // agree with f64's), or r2 for s ≤ 0.17
    let far = _mm256_min_pd(
        r2,
        _mm256_max_pd(
            _mm256_sub_pd(r3, _mm256_set1_pd(1.0 / 3.0)),
            _mm256_mul_pd(_mm256_set1_pd(0.75), r3),
        ),
    );
    let small = _mm256_cmp_pd::<_CMP_LE_OQ>(s, _mm256_set1_pd(0.17));
    let m = _mm256_blendv_pd(far, r2, small);
    let one = _mm256_set1_pd(1.0);
    let mut u = _mm256_sqrt_pd(_mm256_div_pd(s, _mm256_add_pd(one, m)));
    for _ in 0..2 {
        let g = _mm256_sub_pd(_mm256_mul_pd(_mm256_mul_pd(u, u), _mm256_add_pd(u, one)), s);
        let d1 = _mm256_mul_pd(
            u,
            _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(3.0), u), _mm256_set1_pd(2.0)),
        );
        let d2 = _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(6.0), u), _mm256_set1_pd(2.0));
        let den = _mm256_sub_pd(
            _mm256_mul_pd(d1, d1),
            _mm256_mul_pd(_mm256_mul_pd(_mm256_set1_pd(0.5), g), d2),
        );
        u = _mm256_sub_pd(u, _mm256_div_pd(_mm256_mul_pd(g, d1), den));
    }
    // !(s > 0) (NaN included) → 0
    let positive = _mm256_cmp_pd::<_CMP_GT_OQ>(s, zero);
    u = _mm256_and_pd(u, positive);
    let huge = _mm256_cmp_pd::<_CMP_GE_OQ>(s, _mm256_set1_pd(1e45));
    if _mm256_movemask_pd(huge) != 0 {
        let (mut sl, mut ul) = ([0.0; 4], [0.0; 4]);
        _mm256_storeu_pd(sl.as_mut_ptr(), s);
        _mm256_storeu_pd(ul.as_mut_ptr(), u);
        for (u, &s) in ul.iter_mut().zip(&sl) {
            if s >= 1e45 {
                *u = contact::hertz_reissner_root(s);
            }
        }
        u = _mm256_loadu_pd(ul.as_ptr());
    }
    u
}

#[cfg(test)]
mod tests {
    use super::*;

    #[target_feature(enable = "avx2")]
    unsafe fn root_lanes(s: [f64; 4]) -> [f64; 4] {
        let mut u = [0.0; 4];
        _mm256_storeu_pd(
            u.as_mut_ptr(),
            hertz_reissner_root4(_mm256_loadu_pd(s.as_ptr())),
        );
        u
    }

    #[target_feature(enable = "avx2")]
    unsafe fn div3_lanes(x: [u64; 4]) -> [u64; 4] {
        let mut q = [0u64; 4];
        let v = div3_u64(_mm256_loadu_si256(x.as_ptr() as *const __m256i));
        _mm256_storeu_si256(q.as_mut_ptr() as *mut __m256i, v);
        q
    }

    /// xorshift64*: reproducible test values without a dependency.
    fn next(state: &mut u64) -> u64 {
        *state ^= *state >> 12;
        *state ^= *state << 25;
        *state ^= *state >> 27;
        state.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    #[test]
    fn lane_root_and_division_by_three_are_bitwise_the_scalar_ones() {
        if !is_x86_feature_detected!("avx2") {
            return;
        }
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        // ⌊x/3⌋ for x < 2⁶³: random bits, and the ends of every 32-bit half
        let mut xs: Vec<u64> = (0..40_000).map(|_| next(&mut state) >> 1).collect();
        for hi in [0u64, 1, 2, 3, 0x7FFF_FFFF, 0x7FFF_FFFE] {
            for lo in [
                0u64,
                1,
                2,
                3,
                4,
                0xFFFF_FFFC,
                0xFFFF_FFFD,
                0xFFFF_FFFE,
                0xFFFF_FFFF,
            ] {
                xs.push(hi << 32 | lo);
            }
        }
        for x in xs.chunks_exact(4) {
            let x = [x[0], x[1], x[2], x[3]];
            // SAFETY: the CPU has AVX2 (tested above).
            let q = unsafe { div3_lanes(x) };
            for l in 0..4 {
                assert_eq!(q[l], x[l] / 3, "x = {:#x}", x[l]);
            }
        }
        // the root: the branches' borders, the special values, log-uniform s over
        // 1e-300 … 1e60, and random positive doubles
        let mut ss = vec![
            0.0,
            -0.0,
            -1.0,
            f64::NAN,
            f64::INFINITY,
            f64::MIN_POSITIVE,
            5e-324,
            0.17,
            0.1700000000000001,
            0.16999999999999998,
            1.0,
            1e45,
            9.999999999999999e44,
            1e300,
            f64::MAX,
        ];
        for _ in 0..40_000 {
            let t = (next(&mut state) >> 11) as f64 / (1u64 << 53) as f64;
            ss.push(10f64.powf(-300.0 + 360.0 * t));
        }
        for _ in 0..4000 {
            ss.push(f64::from_bits(next(&mut state) >> 1));
        }
        while ss.len() % 4 != 0 {
            ss.push(1.0);
        }
        for s in ss.chunks_exact(4) {
            let s = [s[0], s[1], s[2], s[3]];
            // SAFETY: the CPU has AVX2 (tested above).
            let u = unsafe { root_lanes(s) };
            for l in 0..4 {
                let want = contact::hertz_reissner_root(s[l]);
                assert_eq!(u[l].to_bits(), want.to_bits(), "s = {:e}", s[l]);
            }
        }
    }
}

/// What [`forces4`] gives for four contacts: force on the particle (pair: i), N;
/// n × f_t, N; the new spring ξ, m; the normal force, N.
#[derive(Clone, Copy)]
pub(super) struct Forces4 {
    pub(super) force: V4,
    pub(super) torque_per_arm: V4,
    pub(super) history: V4,
    pub(super) f_n: __m256d,
}

/// The force pass on four contacts: `n`, `v_rel`, `spin` (with rotation), `overlap`
/// and the spring `history` as lanes, the law constants from lanes `k..k + 4` of the
/// batch.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) unsafe fn forces4<const E: u16, const H: bool, const R: bool>(
    b: &Batch,
    c: &PairCtx<'_>,
    k: usize,
    n: V4,
    mut v_rel: V4,
    spin: V4,
    overlap: __m256d,
    history: V4,
) -> Forces4 {
    let rotation = on::<E>(c.effects, Effect::Rotation);
    let friction = on::<E>(c.effects, Effect::Friction);
    let damping = on::<E>(c.effects, Effect::Damping);
    let zero = _mm256_setzero_pd();
    let sign = _mm256_set1_pd(-0.0);
    if rotation {
        v_rel = add(v_rel, cross(spin, n));
    }
    let v_n = dot(v_rel, n);
    let v_t = sub(v_rel, scale(v_n, n));
    let (f_el, c_n, k_t) = (ld(&b.f_el, k), ld(&b.c_n, k), ld(&b.k_t, k));
    let (hertz_f_el, hertz_c_n, hertz_k_t) = if R {
        // every lane follows the Hertz–Reissner law (`law_at`'s operations)
        let u = hertz_reissner_root4(_mm256_mul_pd(ld(&b.s_scale, k), overlap));
        let c_n = if damping {
            let w = _mm256_mul_pd(_mm256_set1_pd(3.0), u);
            let q = _mm256_div_pd(w, _mm256_add_pd(_mm256_set1_pd(2.0), w));
            _mm256_mul_pd(c_n, _mm256_sqrt_pd(q))
        } else {
            zero
        };
        let u3 = _mm256_mul_pd(_mm256_mul_pd(u, u), u);
        (_mm256_mul_pd(f_el, u3), c_n, _mm256_mul_pd(k_t, u))
    } else {
        // the Hertz law where the lanes hold its constants (`law_at`'s operations; with
        // `H`, every lane does)
        let sq = _mm256_sqrt_pd(overlap);
        let c_n = if damping {
            _mm256_mul_pd(c_n, _mm256_sqrt_pd(sq))
        } else {
            zero
        };
        (
            _mm256_mul_pd(_mm256_mul_pd(f_el, sq), overlap),
            c_n,
            _mm256_mul_pd(k_t, sq),
        )
    };
    let (f_el, c_n, k_t) = if H || R {
        (hertz_f_el, hertz_c_n, hertz_k_t)
    } else {
        let hertz =
            _mm256_castsi256_pd(_mm256_loadu_si256(b.hertz.as_ptr().add(k) as *const __m256i));
        (
            _mm256_blendv_pd(f_el, hertz_f_el, hertz),
            _mm256_blendv_pd(c_n, hertz_c_n, hertz),
            _mm256_blendv_pd(k_t, hertz_k_t, hertz),
        )
    };
    let mut f_n = _mm256_add_pd(f_el, _mm256_mul_pd(c_n, v_n));
    if c.clamp {
        // f_n < 0 → 0 (NaN stays)
        let neg = _mm256_cmp_pd::<_CMP_LT_OQ>(f_n, zero);
        f_n = _mm256_blendv_pd(f_n, zero, neg);
    }
    let mut force = scale(_mm256_xor_pd(f_n, sign), n);
    let mut torque_per_arm = V4 {
        x: zero,
        y: zero,
        z: zero,
    };
    let mut history = history;
    if friction {
        let c_t = _mm256_mul_pd(c_n, ld(&b.ct_ratio, k));
        // f64::max(f_n, 0): 0 for NaN, as maxpd returns its second operand then
        let cap = _mm256_mul_pd(ld(&b.mu, k), _mm256_max_pd(f_n, zero));
        let mut xi = history;
        xi = sub(xi, scale(dot(xi, n), n));
        xi = add(xi, scale(_mm256_set1_pd(c.dt), v_t));
        let f_stick = sub(scale(_mm256_xor_pd(k_t, sign), xi), scale(c_t, v_t));
        let f2 = dot(f_stick, f_stick);
        let sliding = _mm256_cmp_pd::<_CMP_GT_OQ>(f2, _mm256_mul_pd(cap, cap));
        let f_t = if _mm256_movemask_pd(sliding) == 0 {
            // no lane slides (the usual case between particles of a pack): the cone's
            // square root and two divisions are not needed
            history = xi;
            f_stick
        } else {
            let f_slide = scale(_mm256_div_pd(cap, _mm256_sqrt_pd(f2)), f_stick);
            let inv = _mm256_div_pd(_mm256_set1_pd(-1.0), k_t);
            let stiff = _mm256_cmp_pd::<_CMP_GT_OQ>(k_t, zero);
            let xi_slide = V4 {
                x: _mm256_and_pd(_mm256_mul_pd(f_slide.x, inv), stiff),
                y: _mm256_and_pd(_mm256_mul_pd(f_slide.y, inv), stiff),
                z: _mm256_and_pd(_mm256_mul_pd(f_slide.z, inv), stiff),
            };
            history = select(sliding, xi_slide, xi);
            select(sliding, f_slide, f_stick)
        };
        force = add(force, f_t);
        if rotation {
            torque_per_arm = cross(n, f_t);
        }
    }
    Forces4 {
        force,
        torque_per_arm,
        history,
        f_n,
    }
}

/// The batch's results of [`forces4`] at lanes `k..k + 4`.
#[inline(always)]
pub(super) unsafe fn store_forces<const E: u16>(
    b: &mut Batch,
    c: &PairCtx<'_>,
    k: usize,
    f: &Forces4,
) {
    store(&mut b.force, k, f.force);
    store(&mut b.torque_per_arm, k, f.torque_per_arm);
    if on::<E>(c.effects, Effect::Friction) {
        store(&mut b.history, k, f.history);
    }
    if c.detail {
        st(&mut b.f_n, k, f.f_n);
    }
}

#[target_feature(enable = "avx2")]
pub(in crate::dem::simulation::batch) unsafe fn contact_forces<
    const E: u16,
    const H: bool,
    const R: bool,
>(
    b: &mut Batch,
    c: &PairCtx<'_>,
) {
    let rotation = on::<E>(c.effects, Effect::Rotation);
    let len = b.len.min(BATCH);
    let mut k = 0;
    while k < len {
        let spin = if rotation {
            load(&b.spin, k)
        } else {
            load(&b.n, k)
        };
        let f = forces4::<E, H, R>(
            b,
            c,
            k,
            load(&b.n, k),
            load(&b.v_rel, k),
            spin,
            ld(&b.overlap, k),
            load(&b.history, k),
        );
        store_forces::<E>(b, c, k, &f);
        k += 4;
    }
}
