//! Broad phase: a uniform cell grid over the surface faces' bounding boxes, inflated by a
//! travel margin. Each surface node gets the list of faces of other bodies whose inflated
//! box holds it and whose triangle is within the face's contact depth plus the margin of
//! it. The lists stay valid while no node has moved more than half the margin since they
//! were built (a node and every point of a face then close by at most the margin, and a
//! node in contact is within the depth of its face), so they are rebuilt only when that
//! happens. The faces in some list are the live faces: only their geometry is updated per
//! step.
//!
//! Cells are keyed by integer coordinates in a hash map, so far-apart bodies cost no
//! memory between them; a coordinate beyond ±2⁶² cells saturates instead of overflowing.

use std::collections::HashMap;

use rayon::prelude::*;

use super::narrow::closest_point_on_triangle;
use super::surface::Surface;

/// Candidate faces per surface node.
#[derive(Debug, Clone, Default)]
pub struct BroadPhase {
    /// `candidates[start[k]..start[k + 1]]` are the faces near surface node k.
    pub start: Vec<usize>,
    /// Face indices, ascending per node.
    pub candidates: Vec<u32>,
    /// Displacement of every surface node when the lists were built, m.
    pub built_at: Vec<[f64; 3]>,
    /// Number of builds so far.
    pub builds: u64,
    /// Faces in at least one list, ascending.
    pub live: Vec<u32>,
    /// Travel margin, m.
    pub margin: f64,
}

fn cell_of(x: f64, h: f64) -> i64 {
    let c = (x / h).floor();
    if c.is_nan() {
        0
    } else {
        c.clamp(-4.6e18, 4.6e18) as i64
    }
}

impl BroadPhase {
    /// Empty lists with the given travel margin (m).
    pub fn new(margin: f64) -> Self {
        Self {
            margin,
            ..Default::default()
        }
    }

    /// Whether some surface node has moved more than half the margin since the last build.
    pub fn needs_rebuild(&self, surface: &Surface, u: &[[f64; 3]]) -> bool {
        if self.builds == 0 {
            return true;
        }
        let lim = 0.25 * self.margin * self.margin;
        surface.nodes.par_iter().zip(&self.built_at).any(|(&i, b)| {
            let d = [u[i][0] - b[0], u[i][1] - b[1], u[i][2] - b[2]];
            !(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= lim)
        })
    }

    /// Rebuild the candidate lists for positions `x = X + u` (`x` per global node).
    pub fn rebuild(&mut self, surface: &Surface, x: &[[f64; 3]], u: &[[f64; 3]]) {
        let m = self.margin;
        let nf = surface.faces.len();
        let mut lo = vec![[0.0; 3]; nf];
        let mut hi = vec![[0.0; 3]; nf];
        let mut h: f64 = 0.0;
        for (f, face) in surface.faces.iter().enumerate() {
            let mut a = [f64::INFINITY; 3];
            let mut b = [f64::NEG_INFINITY; 3];
            for &i in &face.nodes {
                for d in 0..3 {
                    a[d] = a[d].min(x[i][d]);
                    b[d] = b[d].max(x[i][d]);
                }
            }
            for d in 0..3 {
                // The face's own element depth: a node may be up to that far behind it.
                a[d] -= m + face.depth;
                b[d] += m + face.depth;
                h = h.max(b[d] - a[d]);
            }
            lo[f] = a;
            hi[f] = b;
        }
        let h = if h > 0.0 && h.is_finite() { h } else { 1.0 };
        let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for f in 0..nf {
            let c0 = [
                cell_of(lo[f][0], h),
                cell_of(lo[f][1], h),
                cell_of(lo[f][2], h),
            ];
            let c1 = [
                cell_of(hi[f][0], h),
                cell_of(hi[f][1], h),
                cell_of(hi[f][2], h),
            ];
            // h is at least the box's extent, so a box spans at most two cells per axis.
            for i in c0[0]..=c1[0].min(c0[0] + 1) {
                for j in c0[1]..=c1[1].min(c0[1] + 1) {
                    for k in c0[2]..=c1[2].min(c0[2] + 1) {
                        grid.entry([i, j, k]).or_default().push(f as u32);
                    }
                }
            }
        }
        self.start.clear();
        self.candidates.clear();
        self.start.push(0);
        for (slot, &node) in surface.nodes.iter().enumerate() {
            let p = x[node];
            let body = surface.node_body[slot];
            let key = [cell_of(p[0], h), cell_of(p[1], h), cell_of(p[2], h)];
            if let Some(list) = grid.get(&key) {
                for &f in list {
                    let face = &surface.faces[f as usize];
                    if face.body == body {
                        continue;
                    }
                    let (a, b) = (lo[f as usize], hi[f as usize]);
                    if !(0..3).all(|d| p[d] >= a[d] && p[d] <= b[d]) {
                        continue;
                    }
                    // Within the face's depth (with a relative 1e-6 to spare for the
                    // narrow phase's edge tolerance) plus the margin of the triangle.
                    let (q, _) = closest_point_on_triangle(p, face.nodes.map(|i| x[i]));
                    let e = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
                    let reach = m + face.depth * (1.0 + 1e-6) + 1e-12;
                    if !(e[0] * e[0] + e[1] * e[1] + e[2] * e[2] > reach * reach) {
                        self.candidates.push(f);
                    }
                }
            }
            self.start.push(self.candidates.len());
        }
        self.built_at = surface.nodes.iter().map(|&i| u[i]).collect();
        self.builds += 1;
        self.refresh_live();
    }

    /// Recompute [`Self::live`] from the lists (after a rebuild or a restore).
    pub fn refresh_live(&mut self) {
        let mut live = self.candidates.clone();
        live.sort_unstable();
        live.dedup();
        self.live = live;
    }

    /// Candidate faces of surface node `k` (its position in `Surface::nodes`).
    pub fn faces_of(&self, k: usize) -> &[u32] {
        &self.candidates[self.start[k]..self.start[k + 1]]
    }
}
