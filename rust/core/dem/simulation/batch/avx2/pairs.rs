//! The pair lanes: the geometry of four pairs, the uniform pairs' pass from the particles'
//! rows, and the scatter of four pairs that go on as rows.

use super::forces::{forces4, store_forces};
use super::*;

/// The scatter of four pairs of a batch (lanes `k..k + 4`) that were in contact and go
/// on, on a step without records: their springs, their outputs and their cleared onsets,
/// written as rows from the lanes (that of `pair_chunk_batched`'s scatter, whose
/// remaining writes are all for onsets and records).
#[target_feature(enable = "avx2")]
#[inline]
pub(in crate::dem::simulation::batch) unsafe fn pair_rows(
    b: &Batch,
    k: usize,
    chunk: &mut [PairContact],
    onset: &mut [bool],
    out: &mut [PairOut],
) {
    let (force, torque_per_arm) = (load(&b.force, k), load(&b.torque_per_arm, k));
    let (overlap, history) = (ld(&b.overlap, k), load(&b.history, k));
    rows4(
        b,
        k,
        force,
        torque_per_arm,
        overlap,
        history,
        chunk,
        onset,
        out,
    );
}

/// [`pair_rows`] from values in registers.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
unsafe fn rows4(
    b: &Batch,
    k: usize,
    f: V4,
    t: V4,
    overlap: __m256d,
    history: V4,
    chunk: &mut [PairContact],
    onset: &mut [bool],
    out: &mut [PairOut],
) {
    let (fxy, fz_tx) = (lane_pairs(f.x, f.y), lane_pairs(f.z, t.x));
    let (tyz, ov) = (lane_pairs(t.y, t.z), lane_pairs(overlap, overlap));
    // (a loop, not `array::map`: a closure passed on loses the AVX2 build)
    let mut dst = [std::ptr::null_mut(); 4];
    for (l, d) in dst.iter_mut().enumerate() {
        let e = b.index[k + l] as usize;
        // (cleared only where set: a store to every pair costs more than the test)
        if onset[e] {
            onset[e] = false;
        }
        let p = &mut chunk[e];
        // force, torque per arm, overlap: 7 f64 from the start of the row
        let o = &mut out[e] as *mut PairOut as *mut f64;
        _mm_storeu_pd(o, lane_pair(fxy, l));
        _mm_storeu_pd(o.add(2), lane_pair(fz_tx, l));
        _mm_storeu_pd(o.add(4), lane_pair(tyz, l));
        _mm_store_sd(o.add(6), lane_pair(ov, l));
        *d = &mut p.history.x as *mut f64;
    }
    store_rows3(history, dst);
}

/// The pairs of a batch of uniform pairs ([`pair_chunk_batched`] with `U`) in one pass
/// over the lanes: the particles' velocities and spins and the pairs' springs read from
/// their rows (the batch holds only the pairs' indices, x_j − x_i and its square),
/// geometry, forces and, for four pairs that go on in contact on a step
/// without records, the scatter as rows ([`rows4`]), with no round trip through the
/// batch. The other groups' results go to the batch for the lane-by-lane scatter;
/// returns a bit per such group (group g: lanes 4g..4g + 4).
#[target_feature(enable = "avx2")]
pub(in crate::dem::simulation::batch) unsafe fn uniform_pairs<const E: u16, const R: bool>(
    b: &mut Batch,
    c: &PairCtx<'_>,
    chunk: &mut [PairContact],
    active: &[bool],
    onset: &mut [bool],
    out: &mut [PairOut],
) -> u16 {
    let rotation = on::<E>(c.effects, Effect::Rotation);
    let len = b.len.min(BATCH);
    let mut rest = 0u16;
    let mut k = 0;
    // the rows of particles `idx` of `a` as lanes
    let rows = |a: &[Vec3], idx: [usize; 4]| {
        let p = |l: usize| a.as_ptr().add(idx[l]) as *const f64;
        load_rows3([p(0), p(1), p(2), p(3)])
    };
    while k < len {
        // SAFETY (the unchecked reads): every lane of the group, the padded ones past
        // `len` too, names a pair of `chunk` (`pair_chunk_batched` pads them with the
        // batch's first pair), whose particles passed the reach test, so they index
        // the particle arrays, which are all as long as the positions.
        let pc = |l: usize| chunk.get_unchecked(b.index[k + l] as usize);
        let pi = [
            pc(0).i as usize,
            pc(1).i as usize,
            pc(2).i as usize,
            pc(3).i as usize,
        ];
        let pj = [
            pc(0).j as usize,
            pc(1).j as usize,
            pc(2).j as usize,
            pc(3).j as usize,
        ];
        let (omega_i, omega_j) = if rotation {
            (rows(c.omega, pi), rows(c.omega, pj))
        } else {
            (zero4(), zero4())
        };
        let (d, dist2) = (load(&b.n, k), ld(&b.overlap, k));
        let (n, overlap, spin) = geometry4_with::<E>(b, c, k, d, dist2, omega_i, omega_j);
        let v_rel = sub(rows(c.velocity, pi), rows(c.velocity, pj));
        let spring = |l: usize| &pc(l).history.x as *const f64;
        let history = load_rows3([spring(0), spring(1), spring(2), spring(3)]);
        let f = forces4::<E, true, R>(b, c, k, n, v_rel, spin, overlap, history);
        let going_on = |l: usize| active.get(b.index[k + l] as usize) == Some(&true);
        if !c.detail && k + 4 <= len && going_on(0) && going_on(1) && going_on(2) && going_on(3) {
            rows4(
                b,
                k,
                f.force,
                f.torque_per_arm,
                overlap,
                f.history,
                chunk,
                onset,
                out,
            );
        } else {
            store(&mut b.n, k, n);
            st(&mut b.overlap, k, overlap);
            store(&mut b.v_rel, k, v_rel);
            if rotation {
                store(&mut b.spin, k, spin);
            }
            store_forces::<E>(b, c, k, &f);
            // (without friction `store_forces` leaves the spring, which the scatter
            // writes back)
            store(&mut b.history, k, f.history);
            rest |= 1 << (k / 4);
        }
        k += 4;
    }
    rest
}

/// Overlap, unit normal and spin of the pairs in lanes `k..k + 4` (`pair_geometry`'s
/// operations).
#[inline(always)]
unsafe fn geometry4<const E: u16>(b: &Batch, c: &PairCtx<'_>, k: usize) -> (V4, __m256d, V4) {
    let rotation = on::<E>(c.effects, Effect::Rotation);
    let (omega_i, omega_j) = if rotation {
        (load(&b.omega_i, k), load(&b.omega_j, k))
    } else {
        (zero4(), zero4())
    };
    geometry4_with::<E>(b, c, k, load(&b.n, k), ld(&b.overlap, k), omega_i, omega_j)
}

/// [`geometry4`] with the spins ω_i, ω_j (rad/s) given as lanes.
#[inline(always)]
unsafe fn geometry4_with<const E: u16>(
    b: &Batch,
    c: &PairCtx<'_>,
    k: usize,
    d: V4,
    dist2: __m256d,
    omega_i: V4,
    omega_j: V4,
) -> (V4, __m256d, V4) {
    let rotation = on::<E>(c.effects, Effect::Rotation);
    let dist = _mm256_sqrt_pd(dist2);
    // f64::max(x, MIN_POSITIVE): maxpd returns its second operand for NaN, as max does
    let overlap = _mm256_max_pd(
        _mm256_sub_pd(ld(&b.r_sum, k), dist),
        _mm256_set1_pd(f64::MIN_POSITIVE),
    );
    let n = scale(_mm256_div_pd(_mm256_set1_pd(1.0), dist), d);
    let mut spin = n;
    if rotation {
        let h = _mm256_mul_pd(_mm256_set1_pd(0.5), overlap);
        let arm_i = _mm256_sub_pd(ld(&b.r_i, k), h);
        let arm_j = _mm256_sub_pd(ld(&b.r_j, k), h);
        spin = add(scale(arm_i, omega_i), scale(arm_j, omega_j));
    }
    (n, overlap, spin)
}

#[target_feature(enable = "avx2")]
pub(in crate::dem::simulation::batch) unsafe fn pair_geometry<const E: u16>(
    b: &mut Batch,
    c: &PairCtx<'_>,
) {
    let rotation = on::<E>(c.effects, Effect::Rotation);
    let len = b.len.min(BATCH);
    let mut k = 0;
    while k < len {
        let (n, overlap, spin) = geometry4::<E>(b, c, k);
        store(&mut b.n, k, n);
        st(&mut b.overlap, k, overlap);
        if rotation {
            store(&mut b.spin, k, spin);
        }
        k += 4;
    }
}
