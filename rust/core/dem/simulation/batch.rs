//! Batched contact kernels: the pairs of a block, or the wall slots of a block of particles,
//! evaluated up to [`BATCH`] at a time in short passes (find and gather, geometry, laws,
//! forces, scatter), the geometry and force passes four contacts per instruction with AVX2.
//! Every contact goes through the IEEE operations of the one-at-a-time kernels
//! ([`super::pair_kernel`], [`super::wall_kernel`]) in their order, so results are bitwise
//! theirs (`tests/dem_determinism.rs` checks it on both builds).

use super::*;

/// Contacts handled together by the batched kernels ([`pair_chunk`], [`wall_chunk`]).
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
#[inline(always)]
fn pair_geometry<const E: u16>(b: &mut Batch, c: &PairCtx<'_>) {
    #[cfg(target_arch = "x86_64")]
    if c.avx2 {
        // SAFETY: `avx2` is set only when the CPU reported AVX2.
        unsafe { avx2_forces::pair_geometry::<E>(b, c) };
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
/// order (the scalar loop here, the AVX2 build in `avx2_forces` with selects for branches).
/// `all_hertz`: every lane's `hertz` mask is set (the AVX2 pass then skips the masks).
#[inline(always)]
fn contact_forces<const E: u16>(b: &mut Batch, c: &PairCtx<'_>, all_hertz: bool) {
    #[cfg(target_arch = "x86_64")]
    if c.avx2 {
        // SAFETY: `avx2` is set only when the CPU reported AVX2.
        unsafe {
            if all_hertz {
                avx2_forces::contact_forces::<E, true, false>(b, c)
            } else {
                avx2_forces::contact_forces::<E, false, false>(b, c)
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

#[cfg(target_arch = "x86_64")]
pub(super) use avx2_forces::advance4;

/// [`contact_forces`] on four contacts per instruction (AVX2), and the other lane kernels
/// (the plane pass, the four-particle update). The lanes past the batch's length compute on
/// stale values that nothing reads.
#[cfg(target_arch = "x86_64")]
mod avx2_forces {
    use super::*;
    use std::arch::x86_64::*;

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
        let (reference, inv_mass, inv_inertia) =
            (&reference[..4], &inv_mass[..4], &inv_inertia[..4]);
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

    /// A plane wall's constants broadcast to four lanes.
    struct PlaneLanes {
        point: V4,
        normal: V4,
        /// Wall offset (moving walls), m.
        offset: V4,
        /// Contact normal, −normal.
        n: V4,
        /// Velocity of the wall's material at a contact (`wall_touch`), m/s.
        wall_v: V4,
    }

    /// The lanes of wall `w` if it is a plane (`wall_touch`'s operations: its wall velocity
    /// is the same over the whole plane).
    #[inline(always)]
    unsafe fn plane_lanes<const E: u16>(c: &WallCtx<'_>, w: u32) -> Option<PlaneLanes> {
        let wall = c.walls.get(w as usize)?;
        let WallShape::Plane { point, normal } = wall.shape else {
            return None;
        };
        let moving = on::<E>(c.shared.effects, Effect::MovingWalls);
        let ws = if moving {
            c.wall_state[w as usize]
        } else {
            WallState::default()
        };
        let n = -normal;
        let wall_v = wall_velocity::<E>(wall, ws, n, c.shared.effects);
        let bc = |v: Vec3| V4 {
            x: _mm256_set1_pd(v.x),
            y: _mm256_set1_pd(v.y),
            z: _mm256_set1_pd(v.z),
        };
        Some(PlaneLanes {
            point: bc(point),
            normal: bc(normal),
            offset: bc(ws.offset),
            n: bc(n),
            wall_v: bc(wall_v),
        })
    }

    /// The plane-wall slots of a chunk of particles, four particles at a time: for each
    /// group of `lists.planes` (four consecutive alive particles and a slot column whose four
    /// slots hold the same plane with Hertz constants, listed and marked `planar_pass` by
    /// `Simulation::list_wall_slots`), the particles' state is loaded as lanes (no
    /// per-contact copies), the plane test, overlap, lever arm and relative velocity are
    /// computed four at a time into the batch, and the batch goes through
    /// [`contact_forces`]; the results are scattered as by [`wall_chunk_batched`]. Every
    /// lane runs the operations of `wall_touch` and `wall_kernel` in their order, so the
    /// results are bitwise theirs.
    /// `R`: the groups' law is Hertz–Reissner ([`BlockWalls::plane_reissner`]), else Hertz.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn plane_slots<const E: u16, const R: bool>(
        c: &WallCtx<'_>,
        first: usize,
        lists: BlockWalls<'_>,
        slots: &mut [WallContact],
        out: &mut [WallOut],
        detail: &mut [WallDetail],
        b: &mut Batch,
    ) {
        let stride = c.wall_stride;
        let n_slots = slots.len();
        let n_part = n_slots / stride;
        let (out, detail) = (&mut out[..n_slots], &mut detail[..n_slots]);
        let moving = on::<E>(c.shared.effects, Effect::MovingWalls);
        let rotation = on::<E>(c.shared.effects, Effect::Rotation);
        let position = &c.shared.position[first..first + n_part];
        let velocity = &c.shared.velocity[first..first + n_part];
        let omega = &c.shared.omega[first..first + n_part];
        let radius = &c.shared.radius[first..first + n_part];
        let zero = _mm256_setzero_pd();
        let all = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
        // groups in the batch: first particle (in the chunk), column, reach mask
        let mut groups = [(0u32, 0u32, 0u32); BATCH / 4];
        let mut n_groups = 0usize;
        // the lanes of the last wall seen (slot columns mostly hold the same wall)
        let mut plane: (u32, Option<PlaneLanes>) = (NO_WALL, None);
        b.len = 0;
        // one entry for every group: its constants written into the batch here, once
        let uniform = match lists
            .plane_const
            .and_then(|k| c.shared.table.get(k as usize))
        {
            Some(konst) => {
                b.fill_constants(konst);
                true
            }
            None => false,
        };
        for &(g, q) in lists.planes {
            let (g, q) = (g as usize, q as usize);
            if g + 4 > n_part || q >= stride {
                // not a group of this chunk (cannot happen: the lists are made for it)
                continue;
            }
            let s0 = g * stride + q;
            let w = slots[s0].wall;
            if w != plane.0 {
                plane = (w, plane_lanes::<E>(c, w));
            }
            let Some(pl) = plane.1.as_ref() else {
                continue;
            };
            // `wall_hit`: d = normal · (x − offset − point), in reach when d < r
            let mut x = load_aos4(position.as_ptr().add(g));
            if moving {
                x = sub(x, pl.offset);
            }
            let d = dot(pl.normal, sub(x, pl.point));
            let r = _mm256_loadu_pd(radius.as_ptr().add(g));
            let reach = _mm256_cmp_pd::<_CMP_LT_OQ>(d, r);
            let m = _mm256_movemask_pd(reach) as u32;
            if m != 0b1111 {
                // out of reach: `wall_touch`'s reset
                for l in 0..4 {
                    if m >> l & 1 == 0 {
                        end_wall_contact(&mut slots[s0 + l * stride]);
                    }
                }
                if m == 0 {
                    continue;
                }
            }
            let k = 4 * n_groups;
            let overlap = _mm256_sub_pd(r, d);
            let arm = _mm256_max_pd(d, zero);
            let v_rel = sub(load_aos4(velocity.as_ptr().add(g)), pl.wall_v);
            let spin = if rotation {
                scale(arm, load_aos4(omega.as_ptr().add(g)))
            } else {
                v_rel
            };
            let sp = |l: usize| &slots[s0 + l * stride];
            let mut src = [std::ptr::null(); 4];
            for (l, r) in src.iter_mut().enumerate() {
                *r = &sp(l).history.x as *const f64;
            }
            let history = load_rows3(src);
            // the group's constants in lanes k..k + 4 (every lane holds them already when
            // all groups share one entry)
            if !uniform {
                plane_constants(c, sp, k, b, all);
            }
            if m == 0b1111 && !c.shared.detail && (0..4).all(|l| sp(l).active) {
                // four contacts that go on, the common case: forces and scatter (that of
                // `plane_scatter`) from the lanes, without the batch; the lanes k..k + 4
                // are not claimed, so the next group reuses them
                let f = forces4::<E, true, R>(b, &c.shared, k, pl.n, v_rel, spin, overlap, history);
                plane_out_rows(out, g, q, stride, f.force, scale(arm, f.torque_per_arm));
                plane_spring_rows(slots, g, q, stride, f.history);
                continue;
            }
            store(&mut b.n, k, pl.n);
            st(&mut b.overlap, k, overlap);
            st(&mut b.arm, k, arm);
            store(&mut b.v_rel, k, v_rel);
            if rotation {
                store(&mut b.spin, k, spin);
            }
            store(&mut b.history, k, history);
            groups[n_groups] = (g as u32, q as u32, m);
            n_groups += 1;
            b.len = 4 * n_groups;
            if n_groups == BATCH / 4 {
                plane_scatter::<E, R>(c, first, &groups[..n_groups], slots, out, detail, b);
                n_groups = 0;
                b.len = 0;
            }
        }
        if n_groups > 0 {
            plane_scatter::<E, R>(c, first, &groups[..n_groups], slots, out, detail, b);
        }
        b.len = 0;
    }

    /// The outputs of the plane group of particles `g..g + 4`, slot column `q`, as rows:
    /// force `f` and torque `t`, 6 f64 each.
    #[inline(always)]
    unsafe fn plane_out_rows(out: &mut [WallOut], g: usize, q: usize, stride: usize, f: V4, t: V4) {
        let (fxy, fz_tx) = (lane_pairs(f.x, f.y), lane_pairs(f.z, t.x));
        let tyz = lane_pairs(t.y, t.z);
        for l in 0..4 {
            let dst = &mut out[(g + l) * stride + q] as *mut WallOut as *mut f64;
            _mm_storeu_pd(dst, lane_pair(fxy, l));
            _mm_storeu_pd(dst.add(2), lane_pair(fz_tx, l));
            _mm_storeu_pd(dst.add(4), lane_pair(tyz, l));
        }
    }

    /// The springs of a plane group of four contacts that go on (see [`plane_out_rows`]),
    /// as rows, and their onsets cleared.
    #[inline(always)]
    unsafe fn plane_spring_rows(
        slots: &mut [WallContact],
        g: usize,
        q: usize,
        stride: usize,
        history: V4,
    ) {
        let mut dst = [std::ptr::null_mut(); 4];
        for (l, d) in dst.iter_mut().enumerate() {
            let s = &mut slots[(g + l) * stride + q];
            // (cleared only where set: a store to every slot costs more than the test)
            if s.onset {
                s.onset = false;
            }
            *d = &mut s.history.x as *mut f64;
        }
        store_rows3(history, dst);
    }

    /// The constants of one group of [`plane_slots`] (slot of lane l: `sp(l)`) into lanes
    /// `k..k + 4` of the batch, Hertz mask `all` set.
    #[inline(always)]
    unsafe fn plane_constants<'s>(
        c: &WallCtx<'_>,
        sp: impl Fn(usize) -> &'s WallContact,
        k: usize,
        b: &mut Batch,
        all: __m256d,
    ) {
        // f_el, k_t, c_n, c_t/c_n are 32 contiguous bytes of a `ContactConst`
        let kp = |l: usize| &c.shared.table[sp(l).k as usize];
        let krow = |l: usize| _mm256_loadu_pd(&kp(l).f_el);
        let [f_el, k_t, c_n, ct_ratio] = transpose(krow(0), krow(1), krow(2), krow(3));
        st(&mut b.f_el, k, f_el);
        st(&mut b.k_t, k, k_t);
        st(&mut b.c_n, k, c_n);
        st(&mut b.ct_ratio, k, ct_ratio);
        st(
            &mut b.mu,
            k,
            _mm256_setr_pd(kp(0).mu, kp(1).mu, kp(2).mu, kp(3).mu),
        );
        st(
            &mut b.s_scale,
            k,
            _mm256_setr_pd(kp(0).s_scale, kp(1).s_scale, kp(2).s_scale, kp(3).s_scale),
        );
        _mm256_storeu_si256(
            b.hertz.as_mut_ptr().add(k) as *mut __m256i,
            _mm256_castpd_si256(all),
        );
    }

    /// Forces of the groups of [`plane_slots`] in the batch, and their scatter (that of
    /// [`wall_chunk_batched`]).
    #[inline(always)]
    unsafe fn plane_scatter<const E: u16, const R: bool>(
        c: &WallCtx<'_>,
        first: usize,
        groups: &[(u32, u32, u32)],
        slots: &mut [WallContact],
        out: &mut [WallOut],
        detail: &mut [WallDetail],
        b: &mut Batch,
    ) {
        // every lane of a plane group holds the constants of the groups' law
        contact_forces::<E, true, R>(b, &c.shared);
        let stride = c.wall_stride;
        let moving = on::<E>(c.shared.effects, Effect::MovingWalls);
        for (gi, &(g, q, m)) in groups.iter().enumerate() {
            // (four contacts that go on, on a step without records, never get here:
            // `plane_slots` scatters them from the lanes)
            let full = m == 0b1111;
            if full {
                let k = 4 * gi;
                let t = scale(ld(&b.arm, k), load(&b.torque_per_arm, k));
                plane_out_rows(out, g as usize, q as usize, stride, load(&b.force, k), t);
            }
            for l in 0..4 {
                if m >> l & 1 == 0 {
                    continue;
                }
                let k = 4 * gi + l;
                let i = g as usize + l;
                let slot = i * stride + q as usize;
                let s = &mut slots[slot];
                let onset = !s.active;
                let d = &mut detail[slot];
                if onset || c.shared.detail {
                    // recorded at onset and on detail steps
                    let wall = &c.walls[s.wall as usize];
                    let offset = moving.then(|| c.wall_state[s.wall as usize].offset);
                    let x = c.shared.position[first + i];
                    if let Some((point, _, _)) =
                        wall_hit(wall, x, offset, c.shared.radius[first + i])
                    {
                        d.point = point;
                    }
                }
                let o = (!full).then(|| &mut out[slot]);
                scatter_wall_lane::<E>(b, k, s, o, d, &c.shared);
            }
        }
    }

    /// The scatter of four pairs of a batch (lanes `k..k + 4`) that were in contact and go
    /// on, on a step without records: their springs, their outputs and their cleared onsets,
    /// written as rows from the lanes (that of `pair_chunk_batched`'s scatter, whose
    /// remaining writes are all for onsets and records).
    #[target_feature(enable = "avx2")]
    #[inline]
    pub(super) unsafe fn pair_rows(
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
    pub(super) unsafe fn uniform_pairs<const E: u16, const R: bool>(
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
            if !c.detail && k + 4 <= len && going_on(0) && going_on(1) && going_on(2) && going_on(3)
            {
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
    pub(super) unsafe fn pair_geometry<const E: u16>(b: &mut Batch, c: &PairCtx<'_>) {
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
    struct Forces4 {
        force: V4,
        torque_per_arm: V4,
        history: V4,
        f_n: __m256d,
    }

    /// The force pass on four contacts: `n`, `v_rel`, `spin` (with rotation), `overlap`
    /// and the spring `history` as lanes, the law constants from lanes `k..k + 4` of the
    /// batch.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    unsafe fn forces4<const E: u16, const H: bool, const R: bool>(
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
    unsafe fn store_forces<const E: u16>(b: &mut Batch, c: &PairCtx<'_>, k: usize, f: &Forces4) {
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
    pub(super) unsafe fn contact_forces<const E: u16, const H: bool, const R: bool>(
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
                    avx2_forces::uniform_pairs::<E, true>(b, c, chunk, active, onset_flags, out)
                } else {
                    avx2_forces::uniform_pairs::<E, false>(b, c, chunk, active, onset_flags, out)
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
                unsafe { avx2_forces::pair_rows(b, k, chunk, onset_flags, out) };
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
                avx2_forces::plane_slots::<E, true>(c, first, lists, slots, out, detail, b)
            } else {
                avx2_forces::plane_slots::<E, false>(c, first, lists, slots, out, detail, b)
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
