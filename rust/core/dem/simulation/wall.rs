//! The particle–wall kernel, one slot at a time (the reference the batched kernels
//! reproduce bit for bit): its read-only context ([`WallCtx`]), a block's part of the wall
//! lists ([`BlockWalls`]), the wall test and the wall's velocity at a contact, and the
//! kernel of one slot. [`super::chunk`] runs it over the slots of a block.

use super::law::{law_at, tangential_force};
use super::on;
use super::pair::PairCtx;
use super::state::{WallContact, WallDetail, WallOut, WallState};
use crate::dem::effects::{Effect, EffectSet};
use crate::geometry::{rotate_about, Vec3, Wall, WallMotion, WallShape};

/// Read-only context of the wall kernels (run in the force phase, next to the pairs).
pub(super) struct WallCtx<'a> {
    /// State, laws and settings shared with the pair kernel.
    pub(super) shared: PairCtx<'a>,
    pub(super) alive: &'a [bool],
    pub(super) walls: &'a [Wall],
    pub(super) wall_state: &'a [WallState],
    pub(super) wall_stride: usize,
}

/// One block's part of the [`WallLists`].
///
/// [`WallLists`]: super::lists::WallLists
#[derive(Clone, Copy)]
pub(super) struct BlockWalls<'a> {
    pub(super) planes: &'a [(u32, u32)],
    pub(super) rest: &'a [(u32, u32)],
    /// [`WallLists::plane_const`].
    ///
    /// [`WallLists::plane_const`]: super::lists::WallLists::plane_const
    pub(super) plane_const: Option<u32>,
    /// [`WallLists::plane_reissner`].
    ///
    /// [`WallLists::plane_reissner`]: super::lists::WallLists::plane_reissner
    pub(super) plane_reissner: bool,
}

/// Where and how a particle of radius `r` at `x` touches the wall of slot `s`.
pub(super) struct WallTouch {
    /// Contact point on the wall, m.
    pub(super) point: Vec3,
    /// Unit normal from the particle towards the wall.
    pub(super) n: Vec3,
    /// Overlap, m.
    pub(super) overlap: f64,
    /// Lever arm of the particle, m.
    pub(super) arm: f64,
    /// Velocity of the wall's material at the contact (motion plus belt), m/s.
    pub(super) wall_v: Vec3,
}

/// The contact of slot `s` when the particle touches its wall; otherwise ends a contact that
/// was active and returns `None`. Shared by [`wall_kernel`] and the batched kernel.
#[inline(always)]
pub(super) fn wall_touch<const E: u16>(
    s: &mut WallContact,
    x: Vec3,
    r: f64,
    c: &WallCtx<'_>,
) -> Option<WallTouch> {
    let wall = &c.walls[s.wall as usize];
    // fixed walls (no moving_walls effect) sit at offset 0 with velocity 0: skip both
    let moving = on::<E>(c.shared.effects, Effect::MovingWalls);
    let ws = if moving {
        c.wall_state[s.wall as usize]
    } else {
        WallState::default()
    };
    let rotation = match wall.motion {
        WallMotion::Rotation {
            axis_point,
            axis,
            angular_velocity,
        } if moving => Some((axis_point, axis, angular_velocity)),
        _ => None,
    };
    let hit = match rotation {
        // in the wall's reference frame, then back
        Some((_, axis, _)) => wall_hit(wall, s.triangle, wall.motion.rotate(-ws.angle, x), None, r)
            .map(|(q, n, d)| {
                (
                    wall.motion.rotate(ws.angle, q),
                    rotate_about(axis, ws.angle, n),
                    d,
                )
            }),
        None => wall_hit(wall, s.triangle, x, moving.then_some(ws.offset), r),
    };
    let Some((point, out_normal, dist)) = hit else {
        end_wall_contact(s);
        return None;
    };
    let n = -out_normal; // from the particle towards the wall
    let mut wall_v = wall_velocity::<E>(wall, s.triangle, ws, n, c.shared.effects);
    if let Some((axis_point, axis, angular_velocity)) = rotation {
        // the wall's material point at the contact: ω × (q − c)
        wall_v += (axis * angular_velocity).cross(point - axis_point);
    }
    Some(WallTouch {
        point,
        n,
        overlap: r - dist,
        arm: dist.max(0.0),
        wall_v,
    })
}

/// Slot `s` out of reach of its wall: ends a contact that was active.
#[inline(always)]
pub(super) fn end_wall_contact(s: &mut WallContact) {
    if s.active {
        s.active = false;
        s.history = Vec3::ZERO;
    }
    s.onset = false;
}

/// Velocity of the wall's material at a contact with normal `n` (particle towards wall),
/// m/s: the wall's motion (`ws`, zero without `moving_walls`) plus the belt's surface velocity
/// tangent to the contact (on a mesh wall with belts, that of the slot's `triangle`).
#[inline(always)]
pub(super) fn wall_velocity<const E: u16>(
    wall: &Wall,
    triangle: u32,
    ws: WallState,
    n: Vec3,
    effects: EffectSet,
) -> Vec3 {
    let moving = on::<E>(effects, Effect::MovingWalls);
    let mut wall_v = ws.velocity;
    if on::<E>(effects, Effect::Belt) {
        let s_v = wall.surface_velocity_at(triangle);
        let belt = s_v - s_v.dot(n) * n;
        wall_v = if moving { wall_v + belt } else { belt };
    }
    wall_v
}

/// Closest point, unit normal (wall → x) and distance of a wall slot when the sphere of
/// radius r touches it. Half-spaces (the belt) by hand: one dot product, nothing else when
/// out of reach. On a mesh wall, the slot's `triangle` under the rule of
/// [`crate::geometry::mesh`] (each touching face, edge and vertex counted once).
/// `offset` is `None` for walls that do not move (no `moving_walls` effect).
#[inline(always)]
pub(super) fn wall_hit(
    wall: &Wall,
    triangle: u32,
    x: Vec3,
    offset: Option<Vec3>,
    r: f64,
) -> Option<(Vec3, Vec3, f64)> {
    match &wall.shape {
        WallShape::Plane { point, normal } => {
            let p = offset.map_or(x, |o| x - o);
            let d = normal.dot(p - *point);
            if d < r {
                let q = p - d * *normal;
                Some((offset.map_or(q, |o| q + o), *normal, d))
            } else {
                None
            }
        }
        WallShape::Mesh(mesh) => {
            let p = offset.map_or(x, |o| x - o);
            let (q, n, d) = mesh.contact(triangle, p, r)?;
            Some((offset.map_or(q, |o| q + o), n, d))
        }
        _ => match wall.closest_at(x, offset.unwrap_or(Vec3::ZERO)) {
            Some(h) if h.2 < r => Some(h),
            _ => None,
        },
    }
}

/// Force and torque of one particle–wall slot on particle i, stored in the slot with the
/// contact state; flags onset.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn wall_kernel<const E: u16>(
    s: &mut WallContact,
    o: &mut WallOut,
    detail: &mut WallDetail,
    i: usize,
    x: Vec3,
    v: Vec3,
    w: Vec3,
    c: &WallCtx<'_>,
) {
    let r = c.shared.radius[i];
    let Some(WallTouch {
        point,
        n,
        overlap,
        arm,
        wall_v,
    }) = wall_touch::<E>(s, x, r, c)
    else {
        return;
    };
    let rotation = on::<E>(c.shared.effects, Effect::Rotation);
    let mut v_rel = v - wall_v;
    if rotation {
        v_rel += (arm * w).cross(n);
    }
    let v_n = v_rel.dot(n);
    let onset = !s.active;
    s.active = true;
    s.onset = onset;
    let v_t = v_rel - v_n * n;
    if onset {
        detail.onset_normal_speed = v_n;
        detail.onset_tangential_speed = v_t.length();
        detail.point = point;
    }
    let kk = &c.shared.table[s.k as usize];
    let (f_el, c_n, k_t) =
        law_at::<E>(kk, c.shared.model, c.shared.laws, c.shared.effects, overlap);
    let (ct_ratio, mu, law) = (kk.ct_ratio, kk.mu, kk.law as usize);
    let mut f_n = f_el + c_n * v_n;
    if c.shared.clamp && f_n < 0.0 {
        f_n = 0.0;
    }
    let mut force = -f_n * n;
    let mut torque = Vec3::ZERO;
    if on::<E>(c.shared.effects, Effect::Friction) {
        let f_t = tangential_force(
            &mut s.history,
            n,
            v_t,
            k_t,
            c_n * ct_ratio,
            mu * f_n.max(0.0),
            c.shared.dt,
        );
        force += f_t;
        if rotation {
            torque = arm * n.cross(f_t);
        }
    }
    if on::<E>(c.shared.effects, Effect::RollingResistance) {
        let law = &c.shared.laws[law];
        let w_roll = w - w.dot(n) * n;
        let w_mag = w_roll.length();
        if w_mag > 0.0 {
            let m = (law.rolling_friction * r * f_n.max(0.0))
                .min(c.shared.inertia[i] * w_mag / c.shared.dt);
            torque -= m / w_mag * w_roll;
        }
    }
    *o = WallOut { force, torque };
    if c.shared.detail {
        *detail = WallDetail {
            normal: n,
            point,
            overlap,
            normal_force: f_n,
            ..*detail
        };
    }
}
