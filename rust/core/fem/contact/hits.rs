//! The contacts of one step (narrow phase and friction): every surface node against the
//! faces of the other bodies ([`FemContact::face_hit`]) and against every rigid surface
//! ([`FemContact::rigid_hits`], in `rigid`), in parallel over fixed chunks of surface
//! nodes and gathered in node order, so the list is the same for any number of threads.
//! Forces in N, lengths in m, energies in J.

use rayon::prelude::*;

use super::friction::friction_update;
use super::surface::SurfaceFace;
use super::vec3::{add, dot, scale, sub};
use super::{FemContact, NODE_CHUNK, RECENT_STEPS};

/// One contact found in a step.
#[derive(Debug, Clone, Copy)]
pub(super) struct Hit {
    pub(super) slave: u32,
    /// Face index, or the index of the rigid surface when `rigid`.
    pub(super) partner: u32,
    pub(super) rigid: bool,
    pub(super) weights: [f64; 3],
    pub(super) normal_force: [f64; 3],
    pub(super) tangential_force: [f64; 3],
    pub(super) stiffness: f64,
    pub(super) penetration: f64,
    /// Depth subtracted from `penetration` in the force (see `FemContact::offset`), m.
    pub(super) offset: f64,
    /// Side of a shell face (±1; 1 for solids and rigid surfaces).
    pub(super) side: f64,
    pub(super) elastic: f64,
    pub(super) dissipated: f64,
    pub(super) rigid_work: f64,
}

impl FemContact {
    /// The contacts of this step at node velocities `v` (m/s), time `t` (s) and step `dt`
    /// (s): for each surface node in order, its contact with a face of another body (if
    /// any), then its contacts with the rigid surfaces in their order.
    pub(super) fn find_hits(&self, v: &[[f64; 3]], t: f64, dt: f64) -> Vec<Hit> {
        let ns = self.surface.nodes.len();
        (0..ns.div_ceil(NODE_CHUNK))
            .into_par_iter()
            .flat_map_iter(|c| {
                let k0 = c * NODE_CHUNK;
                let k1 = (k0 + NODE_CHUNK).min(ns);
                let mut out = Vec::new();
                for k in k0..k1 {
                    if let Some(h) = self.face_hit(k, v, dt) {
                        out.push(h);
                    }
                    self.rigid_hits(k, v, t, dt, &mut out);
                }
                out
            })
            .collect()
    }

    /// The velocity (m/s) of the point of `face` with barycentric weights `w`.
    fn face_velocity(&self, face: &SurfaceFace, w: [f64; 3], v: &[[f64; 3]]) -> [f64; 3] {
        add(
            add(scale(v[face.nodes[0]], w[0]), scale(v[face.nodes[1]], w[1])),
            scale(v[face.nodes[2]], w[2]),
        )
    }

    /// The contact of surface node `k` with the face of another body it is behind (see
    /// `narrow`), with its friction: `None` when it touches none, or when it is deeper than
    /// a touch could be.
    fn face_hit(&self, k: usize, v: &[[f64; 3]], dt: f64) -> Option<Hit> {
        let i = self.surface.nodes[k];
        let (f, d, w, side, n) = self.closest_face(k, 0.5)?;
        let face = &self.surface.faces[f];
        let vf = self.face_velocity(face, w, v);
        let vrel = sub(v[i], vf);
        // A node in contact within the last few steps may come back at any depth the face
        // takes (it lost the face for a step at an edge); a fresh contact is only as deep as
        // the node and the face closed in one step, with a margin. Deeper is not a touch (and
        // a sudden deep spring would inject energy).
        let last = self.last_contact[k];
        let recent = last != u64::MAX && self.steps - last <= RECENT_STEPS;
        let closing = 2.0 * (-dot(vrel, n)).max(0.0) * dt;
        let margin = 1e-6 * face.depth;
        let offset = if !recent {
            (d <= closing + margin).then_some(0.0)
        } else if self.contact_face[k] == f as u32 {
            Some(self.offset[k].min(d))
        } else {
            // Onto another face: no deeper than the last contact plus what the node and the
            // face closed since.
            let since = (self.steps - last) as f64;
            let allowed = self.last_depth[k] + since * closing + margin;
            Some((d - allowed).max(0.0))
        }?;
        let h = friction_update(
            self.stick[k],
            n,
            vrel,
            [0.0; 3],
            d - offset,
            face.stiffness,
            self.settings.friction,
            dt,
        );
        Some(Hit {
            slave: k as u32,
            partner: f as u32,
            rigid: false,
            weights: w,
            normal_force: h.0,
            tangential_force: h.1,
            stiffness: face.stiffness,
            penetration: d,
            offset,
            side,
            elastic: h.2,
            dissipated: h.3,
            rigid_work: 0.0,
        })
    }
}
