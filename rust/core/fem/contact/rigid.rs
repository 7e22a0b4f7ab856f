//! Rigid surfaces the FEM bodies can touch: a plane with a surface velocity (the belt),
//! a sphere and an infinite cylinder (for verification), each with its own Coulomb
//! friction coefficient. A rigid surface is a party of the contact output like a body.
//! [`FemContact::rigid_hits`] finds a surface node's contacts with them: F = k_node d
//! along the surface's normal, k_node = Σ k_f/3 over the node's faces, met half the node's
//! thickness early on a shell, with the stick spring against the surface's material.

use crate::error::{check_finite, check_non_negative, check_positive, DemfemError, Result};

use super::friction::friction_update;
use super::hits::Hit;
use super::vec3::{add, dot, norm, scale, sub};
use super::FemContact;

/// The shape of a rigid surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RigidShape {
    /// The half-space behind the plane through `point` with outward unit `normal`
    /// (bodies stay on the side the normal points to).
    Plane {
        /// A point of the plane, m.
        point: [f64; 3],
        /// Unit normal pointing out of the rigid half-space.
        normal: [f64; 3],
    },
    /// A solid sphere whose centre moves at a constant velocity.
    Sphere {
        /// Centre at t = 0, m.
        center: [f64; 3],
        /// Radius, m.
        radius: f64,
        /// Velocity of the centre, m/s.
        velocity: [f64; 3],
    },
    /// A solid infinite cylinder.
    Cylinder {
        /// A point of the axis, m.
        point: [f64; 3],
        /// Unit axis direction.
        axis: [f64; 3],
        /// Radius, m.
        radius: f64,
    },
}

/// A rigid surface with its surface velocity (a belt's motion within its plane; for the
/// sphere the velocity of its centre) and friction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidSurface {
    /// Geometry.
    pub shape: RigidShape,
    /// Velocity of the surface material, m/s (for a plane, its component along the normal
    /// is ignored: the plane itself does not move).
    pub surface_velocity: [f64; 3],
    /// Coulomb friction coefficient μ ≥ 0 against the bodies.
    pub friction: f64,
}

fn unit(field: &str, v: [f64; 3]) -> Result<[f64; 3]> {
    let n = norm(v);
    if !(n > 0.0) || !n.is_finite() {
        return Err(DemfemError::InvalidParameter {
            field: field.into(),
            value: format!("{v:?}"),
            allowed: "a finite non-zero vector".into(),
        });
    }
    Ok(scale(v, 1.0 / n))
}

impl RigidSurface {
    /// Check the values and normalise the directions.
    pub fn validated(mut self) -> Result<Self> {
        check_non_negative("friction", self.friction)?;
        check_finite("surface_velocity", &self.surface_velocity)?;
        self.shape = match self.shape {
            RigidShape::Plane { point, normal } => {
                check_finite("plane point", &point)?;
                RigidShape::Plane {
                    point,
                    normal: unit("plane normal", normal)?,
                }
            }
            RigidShape::Sphere {
                center,
                radius,
                velocity,
            } => {
                check_finite("sphere center", &center)?;
                check_finite("sphere velocity", &velocity)?;
                check_positive("sphere radius", radius)?;
                RigidShape::Sphere {
                    center,
                    radius,
                    velocity,
                }
            }
            RigidShape::Cylinder {
                point,
                axis,
                radius,
            } => {
                check_finite("cylinder point", &point)?;
                check_positive("cylinder radius", radius)?;
                RigidShape::Cylinder {
                    point,
                    axis: unit("cylinder axis", axis)?,
                    radius,
                }
            }
        };
        Ok(self)
    }

    /// Penetration d > 0, outward unit normal and surface velocity at `p` at time `t`, or
    /// `None` when `p` is outside the solid.
    pub fn probe(&self, p: [f64; 3], t: f64) -> Option<(f64, [f64; 3], [f64; 3])> {
        self.probe_offset(p, t, 0.0)
    }

    /// As [`Self::probe`] for a point whose contact surface lies `h` (m, ≥ 0) from it
    /// towards the solid (a shell node of half thickness h): penetration d + h when that is
    /// positive.
    pub fn probe_offset(&self, p: [f64; 3], t: f64, h: f64) -> Option<(f64, [f64; 3], [f64; 3])> {
        match self.shape {
            RigidShape::Plane { point, normal } => {
                let g = dot(sub(p, point), normal);
                if g < h {
                    let vs = sub(
                        self.surface_velocity,
                        scale(normal, dot(self.surface_velocity, normal)),
                    );
                    Some((h - g, normal, vs))
                } else {
                    None
                }
            }
            RigidShape::Sphere {
                center,
                radius,
                velocity,
            } => {
                let c = [
                    center[0] + velocity[0] * t,
                    center[1] + velocity[1] * t,
                    center[2] + velocity[2] * t,
                ];
                let r = sub(p, c);
                let l = norm(r);
                if l < radius + h && l > 0.0 {
                    Some((radius + h - l, scale(r, 1.0 / l), velocity))
                } else {
                    None
                }
            }
            RigidShape::Cylinder {
                point,
                axis,
                radius,
            } => {
                let r = sub(p, point);
                let radial = sub(r, scale(axis, dot(r, axis)));
                let l = norm(radial);
                if l < radius + h && l > 0.0 {
                    Some((
                        radius + h - l,
                        scale(radial, 1.0 / l),
                        self.surface_velocity,
                    ))
                } else {
                    None
                }
            }
        }
    }
}

impl FemContact {
    /// The contacts of surface node `k` with the rigid surfaces (in their order), with
    /// friction and the power the moving surface puts into the body, appended to `out`;
    /// node velocities `v` (m/s), time `t` (s), step `dt` (s).
    pub(super) fn rigid_hits(&self, k: usize, v: &[[f64; 3]], t: f64, dt: f64, out: &mut Vec<Hit>) {
        let i = self.surface.nodes[k];
        let nr = self.rigid.len();
        for (r, s) in self.rigid.iter().enumerate() {
            let hn = self.surface.node_half_thickness[k];
            if let Some((d, n, vs)) = s.probe_offset(self.x[i], t, hn) {
                let kn = self.surface.node_stiffness[k];
                let vrel = sub(v[i], vs);
                let h = friction_update(
                    self.stick_rigid[k * nr + r],
                    n,
                    vrel,
                    vs,
                    d,
                    kn,
                    s.friction,
                    dt,
                );
                // Power the moving surface puts into the body: F·v_s.
                let work = dot(add(h.0, h.1), vs) * dt;
                out.push(Hit {
                    slave: k as u32,
                    partner: r as u32,
                    rigid: true,
                    weights: [0.0; 3],
                    normal_force: h.0,
                    tangential_force: h.1,
                    stiffness: kn,
                    penetration: d,
                    offset: 0.0,
                    side: 1.0,
                    elastic: h.2,
                    dissipated: h.3,
                    rigid_work: work,
                });
            }
        }
    }
}
