//! The plane pass: the slots of plane walls (the belt under every sphere) four particles at
//! a time, read as lanes straight from the particles' rows, and their scatter.

use super::forces::{contact_forces, forces4};
use super::*;
use crate::dem::simulation::state::WallState;
use crate::dem::simulation::wall::{end_wall_contact, wall_hit, wall_velocity};
use crate::dem::simulation::NO_WALL;
use crate::geometry::WallShape;

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
    let wall_v = wall_velocity::<E>(wall, 0, ws, n, c.shared.effects);
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
pub(in crate::dem::simulation::batch) unsafe fn plane_slots<const E: u16, const R: bool>(
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
                    wall_hit(wall, s.triangle, x, offset, c.shared.radius[first + i])
                {
                    d.point = point;
                }
            }
            let o = (!full).then(|| &mut out[slot]);
            scatter_wall_lane::<E>(b, k, s, o, d, &c.shared);
        }
    }
}
