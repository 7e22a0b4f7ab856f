//! The contact output. Per pair of parties (bodies, then rigid surfaces) and per region of
//! the lower-numbered party: the resultant normal and tangential force on that party (as
//! Abaqus's CFNM/CFSM), the contact area (the tributary areas of the nodes in contact, half
//! of both sides for body pairs) and the largest penetration, sampled every
//! `output_interval` steps; and the contact pressure of every node. N, m², m, Pa.

use super::hits::Hit;
use super::vec3::{add, norm, scale};
use super::FemContact;

/// Contact output of one channel at one sample.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ChannelSample {
    /// |Σ normal force on the lower-numbered party|, N.
    pub normal_force: f64,
    /// |Σ tangential force on the lower-numbered party|, N.
    pub tangential_force: f64,
    /// Contact area, m².
    pub area: f64,
    /// Largest penetration, m.
    pub max_penetration: f64,
}

fn pair_index(a: usize, b: usize, parties: usize) -> usize {
    // a < b; row-major upper triangle.
    a * parties - a * (a + 1) / 2 + (b - a - 1)
}

impl FemContact {
    /// Number of parties (bodies then rigid surfaces).
    pub fn parties(&self) -> usize {
        self.n_bodies + self.rigid.len()
    }
    /// Number of output regions.
    pub fn regions(&self) -> usize {
        self.n_regions
    }
    /// Output channels: (party a, party b, region of a) with a < b, in output order.
    pub fn channels(&self) -> Vec<(usize, usize, usize)> {
        let p = self.parties();
        let mut out = Vec::new();
        for a in 0..p {
            for b in a + 1..p {
                for r in 0..self.n_regions {
                    out.push((a, b, r));
                }
            }
        }
        out
    }

    /// Recorded output: rows of `1 + 4 × channels` values (time, then normal force, tangential
    /// force, area, largest penetration per channel).
    pub fn history(&self) -> &[f64] {
        &self.history
    }

    /// Contact pressure of each mesh node in the last step (normal force it carries over its
    /// tributary area), Pa; 0 off the surface.
    pub fn pressure(&self) -> Vec<f64> {
        let mut p = vec![0.0; self.reference.len()];
        for (k, &i) in self.surface.nodes.iter().enumerate() {
            p[i] = self.normal_load[k] / self.surface.node_area[k];
        }
        p
    }

    /// The last recorded sample, one entry per channel.
    pub fn last_sample(&self) -> &[ChannelSample] {
        &self.sample
    }

    /// This step's channel sums of `hits` (in order): the signed force sums (normal,
    /// tangential) on the lower-numbered party and the sample with area and penetration.
    pub(super) fn sample_hits(&self, hits: &[Hit]) -> (Vec<[[f64; 3]; 2]>, Vec<ChannelSample>) {
        let parties = self.parties();
        let n_channels = parties * parties.saturating_sub(1) / 2 * self.n_regions;
        let mut sums = vec![[[0.0f64; 3]; 2]; n_channels];
        let mut chan = vec![ChannelSample::default(); n_channels];
        for h in hits {
            let k = h.slave as usize;
            let i = self.surface.nodes[k];
            let body = self.surface.node_body[k] as usize;
            let (other, face_nodes) = if h.rigid {
                (self.n_bodies + h.partner as usize, None)
            } else {
                let face = self.surface.faces[h.partner as usize];
                (face.body as usize, Some(face))
            };
            // Output on the lower-numbered party, in its region.
            let (a, b, sign, region) = if body < other {
                (body, other, 1.0, self.region[i] as usize)
            } else {
                let face = face_nodes.map(|f| {
                    let j = (0..3)
                        .max_by(|&x, &y| h.weights[x].total_cmp(&h.weights[y]))
                        .unwrap_or(0);
                    f.nodes[j]
                });
                (
                    other,
                    body,
                    -1.0,
                    face.map_or(0, |n| self.region[n] as usize),
                )
            };
            let c = pair_index(a, b, parties) * self.n_regions + region;
            sums[c][0] = add(sums[c][0], scale(h.normal_force, sign));
            sums[c][1] = add(sums[c][1], scale(h.tangential_force, sign));
            let half = if face_nodes.is_some() { 0.5 } else { 1.0 };
            chan[c].area += half * self.surface.node_area[k];
            chan[c].max_penetration = chan[c].max_penetration.max(h.penetration);
        }
        (sums, chan)
    }

    /// Record the sample of time `t` (s) from the channel sums of [`Self::sample_hits`].
    pub(super) fn record_sample(
        &mut self,
        t: f64,
        sums: &[[[f64; 3]; 2]],
        mut chan: Vec<ChannelSample>,
    ) {
        self.history.push(t);
        for (c, s) in chan.iter_mut().enumerate() {
            s.normal_force = norm(sums[c][0]);
            s.tangential_force = norm(sums[c][1]);
            self.history.extend_from_slice(&[
                s.normal_force,
                s.tangential_force,
                s.area,
                s.max_penetration,
            ]);
        }
        self.sample = chan;
    }
}
