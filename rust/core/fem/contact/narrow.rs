//! Narrow phase: the face a surface node is in contact with.
//!
//! **Solid faces** (one-sided): the node is behind the face's plane by d, 0 < d ≤ the
//! fraction `depth_fraction` of the element's height, and projects onto the face.
//!
//! **Shell faces** (two-sided, [`super::SurfaceFace::half_thickness`] > 0): with δ the
//! distance of the node from the nearest point q of the triangle (inside it, on an edge or
//! at a corner: the offset surface is rounded at edges, as OpenRadioss TYPE7's gap, so a
//! node meeting a convex ridge of a faceted tube head-on is caught) and h = t_node/2 +
//! t_face/2, the penetration is d = h − δ along the normal (p − q)/δ. Over the face's
//! inside that normal is σ n, σ = ±1 the side the node is on: σ is decided at first contact
//! and kept while the contact lasts (on a switch to another face of the same shell it is
//! carried over through the sign of the two normals' dot product); a node found on the
//! other side of the face's inside has crossed the mid-surface and is not in contact.

use rayon::prelude::*;

use super::vec3::{add, cross, dot, norm, scale, sub};
use super::{FemContact, RECENT_STEPS};

/// Faces per parallel work item of the per-step face geometry.
const FACE_CHUNK: usize = 1024;

/// A contact found: face, penetration (m), weights of the contact point on the face, side
/// σ (±1; 1 for solids), unit contact normal pointing towards the node.
pub(super) type Found = (usize, f64, [f64; 3], f64, [f64; 3]);

/// The point of triangle `t` nearest to `p` and its barycentric weights (Ericson,
/// *Real-Time Collision Detection*, 5.1.5).
pub(super) fn closest_point_on_triangle(p: [f64; 3], t: [[f64; 3]; 3]) -> ([f64; 3], [f64; 3]) {
    let [a, b, c] = t;
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (add(a, scale(ab, v)), [1.0 - v, v, 0.0]);
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (add(a, scale(ac, w)), [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (add(b, scale(sub(c, b), w)), [0.0, 1.0 - w, w]);
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    (add(a, add(scale(ab, v), scale(ac, w))), [1.0 - v - w, v, w])
}

/// A face's geometry at the current positions, computed once per step for all the nodes
/// that test it: the unit normal, twice the area, and a sphere about the centroid that
/// holds every point within the face's contact reach of it (a cheap first rejection).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct FaceGeom {
    normal: [f64; 3],
    area2: f64,
    centre: [f64; 3],
    radius2: f64,
}
use crate::error::DemfemError;

impl FemContact {
    /// Unit normal of face `f` now.
    pub(super) fn face_unit_normal(&self, f: usize) -> [f64; 3] {
        let face = &self.surface.faces[f];
        let [a, b, c] = face.nodes.map(|i| self.x[i]);
        let nrm = cross(sub(b, a), sub(c, a));
        scale(nrm, 1.0 / norm(nrm))
    }

    /// Recompute [`FaceGeom`] of every live face (in some node's candidate list; no other
    /// is read) from the current positions `x`. The reach is
    /// the whole element height behind a solid face (the initial-overlap check's depth
    /// fraction 1) and half the face's [`super::SurfaceFace::depth`] plus the largest node
    /// half thickness on a shell face, with 1 % and 1e-12 m to spare.
    pub(super) fn update_face_geometry(&mut self) {
        let hn_max = self
            .surface
            .node_half_thickness
            .par_iter()
            .cloned()
            .reduce(|| 0.0, f64::max);
        let mut geom = std::mem::take(&mut self.face_geom);
        geom.resize(self.surface.faces.len(), FaceGeom::default());
        let (x, faces) = (&self.x, &self.surface.faces);
        let live = &self.broad.live;
        let fresh: Vec<FaceGeom> = live
            .par_iter()
            .with_min_len(FACE_CHUNK)
            .map(|&f| {
                let face = &faces[f as usize];
                let [a, b, c] = face.nodes.map(|i| x[i]);
                let nrm = cross(sub(b, a), sub(c, a));
                let area2 = norm(nrm);
                let centre = scale(add(add(a, b), c), 1.0 / 3.0);
                let r = [a, b, c]
                    .iter()
                    .map(|&p| norm(sub(p, centre)))
                    .fold(0.0f64, f64::max);
                let reach = if face.half_thickness > 0.0 {
                    face.half_thickness + hn_max
                } else {
                    face.depth
                };
                let rr = 1.01 * (r + reach) + 1e-12;
                FaceGeom {
                    normal: scale(nrm, 1.0 / area2),
                    area2,
                    centre,
                    radius2: rr * rr,
                }
            })
            .collect();
        for (&f, g) in live.iter().zip(fresh) {
            geom[f as usize] = g;
        }
        self.face_geom = geom;
    }

    /// Whether surface node `k` was in contact with a face within the last few steps.
    pub(super) fn recent_contact(&self, k: usize) -> bool {
        let last = self.last_contact[k];
        last != u64::MAX && self.steps - last <= RECENT_STEPS
    }

    /// The face surface node `k` is in contact with: (face index, penetration, weights of
    /// the contact point, side σ, unit contact normal pointing towards the node).
    pub(super) fn closest_face(&self, k: usize, depth_fraction: f64) -> Option<Found> {
        let p = self.x[self.surface.nodes[k]];
        let hn = self.surface.node_half_thickness[k];
        let mut best: Option<Found> = None;
        for &f in self.broad.faces_of(k) {
            let geom = &self.face_geom[f as usize];
            let dc = sub(p, geom.centre);
            if dot(dc, dc) > geom.radius2 {
                continue;
            }
            let face = &self.surface.faces[f as usize];
            let [a, b, c] = face.nodes.map(|i| self.x[i]);
            let area2 = geom.area2;
            if !(area2 > 0.0) {
                continue;
            }
            let n = geom.normal;
            let g = dot(sub(p, a), n);
            let found = if face.half_thickness > 0.0 {
                match self.shell_contact(k, f as usize, p, [a, b, c], n, g, hn) {
                    Some(x) => x,
                    None => continue,
                }
            } else {
                // Half the element's height: a node deeper than that is nearer another face
                // of the body (or on the far side of a thin wall), not on this one.
                if !(g < 0.0) || -g > depth_fraction * face.depth {
                    continue;
                }
                let q = sub(p, scale(n, g));
                let w0 = dot(cross(sub(b, q), sub(c, q)), n) / area2;
                let w1 = dot(cross(sub(c, q), sub(a, q)), n) / area2;
                let w2 = 1.0 - w0 - w1;
                const EPS: f64 = -1e-9;
                if w0 < EPS || w1 < EPS || w2 < EPS {
                    continue;
                }
                (f as usize, -g, [w0, w1, w2], 1.0, n)
            };
            // The nearest face: the smallest penetration behind a solid face, the largest
            // (the nearest mid-surface) in front of a shell face.
            let better = match best {
                None => true,
                Some((_, bd, _, _, _)) => {
                    if face.half_thickness > 0.0 {
                        found.1 > bd
                    } else {
                        found.1 < bd
                    }
                }
            };
            if better {
                best = Some(found);
            }
        }
        best
    }

    /// Contact of surface node `k` at `p` (half thickness `hn`) with shell face `f` of
    /// corners `t`, unit normal `n`, signed distance `g` of `p` from its plane: the node's
    /// distance δ to the nearest point q of the triangle (inside, on an edge or a corner),
    /// penetration h − δ when δ < h, normal (p − q)/δ. A node whose nearest point is inside
    /// the face and which is on the other side of it than its kept side σ has crossed the
    /// mid-surface: no contact (the runaway check reports it).
    #[allow(clippy::too_many_arguments)]
    fn shell_contact(
        &self,
        k: usize,
        f: usize,
        p: [f64; 3],
        t: [[f64; 3]; 3],
        n: [f64; 3],
        g: f64,
        hn: f64,
    ) -> Option<Found> {
        let h = self.surface.faces[f].half_thickness + hn;
        let (q, w) = closest_point_on_triangle(p, t);
        let r = sub(p, q);
        let dist = norm(r);
        if !(dist < h) {
            return None;
        }
        let inside = w.iter().all(|&x| x > 0.0);
        let kept = self.shell_side(k, f, n, g);
        let (normal, side) = if inside || !(dist > 0.0) {
            let side = if g > 0.0 {
                1.0
            } else if g < 0.0 {
                -1.0
            } else {
                kept
            };
            if side != kept {
                return None;
            }
            (scale(n, side), side)
        } else {
            let nc = scale(r, 1.0 / dist);
            let s = dot(nc, n);
            (
                nc,
                if s > 0.0 {
                    1.0
                } else if s < 0.0 {
                    -1.0
                } else {
                    kept
                },
            )
        };
        Some((f, h - dist, w, side, normal))
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

impl FemContact {
    /// Whether the surface is a shell's (two-sided faces).
    pub fn is_shell(&self) -> bool {
        self.surface.faces.iter().any(|f| f.half_thickness > 0.0)
    }
}

impl FemContact {
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
