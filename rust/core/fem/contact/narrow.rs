//! Narrow phase: the face a surface node is in contact with.
//!
//! **Solid faces** (one-sided): the node is behind the face's plane by d, 0 < d ≤ the
//! fraction `depth_fraction` of the element's height, and projects onto the face.
//!
//! **Shell faces** (two-sided, [`super::SurfaceFace::half_thickness`] > 0): with g the
//! signed distance of the node from the face's mid-plane and h = t_node/2 + t_face/2, the
//! penetration is d = h − σ g, σ = ±1 the side of the face the node is on. σ is decided at
//! first contact (the side the node is on then) and kept while the contact lasts (a node
//! pushed towards the mid-surface stays on its side); on a switch to another face of the
//! same shell it is carried over through the sign of the two normals' dot product. The
//! contact holds while 0 < d ≤ h (the node has not crossed the mid-surface) and the node
//! projects onto the face. The contact normal is σ n.

use super::vec3::{cross, dot, norm, scale, sub};
use super::{ContactModel, RECENT_STEPS};
use crate::error::DemfemError;

impl ContactModel {
    /// Unit normal of face `f` now.
    pub(super) fn face_unit_normal(&self, f: usize) -> [f64; 3] {
        let face = &self.surface.faces[f];
        let [a, b, c] = face.nodes.map(|i| self.x[i]);
        let nrm = cross(sub(b, a), sub(c, a));
        scale(nrm, 1.0 / norm(nrm))
    }

    /// Whether surface node `k` was in contact with a face within the last few steps.
    pub(super) fn recent_contact(&self, k: usize) -> bool {
        let last = self.last_contact[k];
        last != u64::MAX && self.steps - last <= RECENT_STEPS
    }

    /// The face surface node `k` is in contact with: (face index, penetration, weights,
    /// side σ of the contact normal σ n; 1 for solid faces).
    pub(super) fn closest_face(
        &self,
        k: usize,
        depth_fraction: f64,
    ) -> Option<(usize, f64, [f64; 3], f64)> {
        let p = self.x[self.surface.nodes[k]];
        let hn = self.surface.node_half_thickness[k];
        let mut best: Option<(usize, f64, [f64; 3], f64)> = None;
        for &f in self.broad.faces_of(k) {
            let face = &self.surface.faces[f as usize];
            let [a, b, c] = face.nodes.map(|i| self.x[i]);
            let nrm = cross(sub(b, a), sub(c, a));
            let area2 = norm(nrm);
            if !(area2 > 0.0) {
                continue;
            }
            let n = scale(nrm, 1.0 / area2);
            let g = dot(sub(p, a), n);
            let (d, side) = if face.half_thickness > 0.0 {
                let h = face.half_thickness + hn;
                let side = self.shell_side(k, f as usize, n, g);
                let d = h - side * g;
                if !(d > 0.0) || d > h {
                    continue;
                }
                (d, side)
            } else {
                // Half the element's height: a node deeper than that is nearer another face
                // of the body (or on the far side of a thin wall), not on this one.
                if !(g < 0.0) || -g > depth_fraction * face.depth {
                    continue;
                }
                (-g, 1.0)
            };
            let q = sub(p, scale(n, g));
            let w0 = dot(cross(sub(b, q), sub(c, q)), n) / area2;
            let w1 = dot(cross(sub(c, q), sub(a, q)), n) / area2;
            let w2 = 1.0 - w0 - w1;
            const EPS: f64 = -1e-9;
            if w0 < EPS || w1 < EPS || w2 < EPS {
                continue;
            }
            // The nearest face plane: the smallest penetration behind a solid face, the
            // largest (the nearest mid-surface) in front of a shell face.
            let better = match best {
                None => true,
                Some((_, bd, _, _)) => {
                    if face.half_thickness > 0.0 {
                        d > bd
                    } else {
                        d < bd
                    }
                }
            };
            if better {
                best = Some((f as usize, d, [w0, w1, w2], side));
            }
        }
        best
    }

    /// Side σ of shell face `f` (unit normal `n`) for surface node `k` at signed distance
    /// `g`: kept from a recent contact with the face, carried over from a recent contact
    /// with another face, else the side the node is on.
    fn shell_side(&self, k: usize, f: usize, n: [f64; 3], g: f64) -> f64 {
        if self.recent_contact(k) {
            let last = self.contact_face[k] as usize;
            if last == f {
                return self.side[k];
            }
            if last < self.surface.faces.len() && self.surface.faces[last].half_thickness > 0.0 {
                let m = self.face_unit_normal(last);
                return if dot(m, n) >= 0.0 {
                    self.side[k]
                } else {
                    -self.side[k]
                };
            }
        }
        if g >= 0.0 {
            1.0
        } else {
            -1.0
        }
    }
}

impl ContactModel {
    /// Whether the surface is a shell's (two-sided faces).
    pub fn is_shell(&self) -> bool {
        self.surface.faces.iter().any(|f| f.half_thickness > 0.0)
    }
}

impl ContactModel {
    /// Keep a failure for a node that was on a face and lost it by going too deep: behind a
    /// solid face by more than half the element's height, or across a shell face's
    /// mid-surface by its reach (the contact ran away).
    pub(super) fn check_runaway(&mut self, new_last: &[u32], t: f64) {
        if self.failure.is_none() {
            for k in 0..self.surface.nodes.len() {
                let f = self.last_face[k];
                if f != u32::MAX && new_last[k] == u32::MAX {
                    let face = self.surface.faces[f as usize];
                    let p = self.x[self.surface.nodes[k]];
                    let [a, b, c] = face.nodes.map(|j| self.x[j]);
                    let nrm = cross(sub(b, a), sub(c, a));
                    let g = dot(sub(p, a), nrm) / norm(nrm);
                    if face.half_thickness > 0.0 {
                        // A shell node that crossed the face's mid-surface by its reach.
                        let h = face.half_thickness + self.surface.node_half_thickness[k];
                        if -(self.side[k] * g) > h {
                            self.failure = Some(DemfemError::Numerical(format!(
                            "contact ran away at t = {t:e} s: node {} of body {} crossed the mid-surface of a shell face of body {} by {:e} m (contact reach {h:e} m); lower the step or raise the penalty scale",
                            self.surface.nodes[k], self.surface.node_body[k], -(self.side[k] * g), face.body
                        )));
                            break;
                        }
                    } else if -g > 0.5 * face.depth {
                        self.failure = Some(DemfemError::Numerical(format!(
                        "contact ran away at t = {t:e} s: node {} of body {} is {:e} m behind a face of body {} (the element under it is {:e} m deep); lower the step or raise the penalty scale",
                        self.surface.nodes[k], self.surface.node_body[k], -g, face.body, face.depth
                    )));
                        break;
                    }
                }
            }
        }
    }
}
