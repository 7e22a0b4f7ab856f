//! The contacts of a step applied: each contact's force on its node and, in the proportions
//! of the projection's barycentric weights, the opposite force on the face's nodes (so a
//! pair's forces sum to zero); the stick forces and the contact memory of every surface node
//! for the next step; the normal load behind the contact pressure; the friction work and the
//! work of the moving rigid surfaces. Forces in N, energies in J.

use rayon::prelude::*;

use super::hits::Hit;
use super::vec3::{add, norm, scale, sub};
use super::{FemContact, NODE_CHUNK};

impl FemContact {
    /// Apply `hits` in their order: `force` (N per node) is cleared and gets the contact
    /// forces. Returns the face each surface node touched (`u32::MAX` for none) and the
    /// elastic energy stored in the contact springs, J.
    pub(super) fn apply_hits(&mut self, hits: &[Hit], force: &mut [[f64; 3]]) -> (Vec<u32>, f64) {
        // Only surface and spring nodes ever carry a force.
        force
            .par_chunks_mut(NODE_CHUNK)
            .for_each(|c| c.fill([0.0; 3]));
        for s in self.stick.iter_mut() {
            *s = [0.0; 3];
        }
        for s in self.stick_rigid.iter_mut() {
            *s = [0.0; 3];
        }
        for l in self.normal_load.iter_mut() {
            *l = 0.0;
        }
        let nr = self.rigid.len();
        let mut elastic = 0.0;
        let mut new_last = vec![u32::MAX; self.surface.nodes.len()];
        for h in hits {
            let k = h.slave as usize;
            let i = self.surface.nodes[k];
            let total = add(h.normal_force, h.tangential_force);
            force[i] = add(force[i], total);
            let fnorm = norm(h.normal_force);
            self.normal_load[k] += fnorm;
            elastic += h.elastic;
            self.energy.friction_work += h.dissipated;
            self.energy.rigid_work += h.rigid_work;
            if h.rigid {
                self.stick_rigid[k * nr + h.partner as usize] = h.tangential_force;
            } else {
                let face = self.surface.faces[h.partner as usize];
                self.stick[k] = h.tangential_force;
                new_last[k] = h.partner;
                self.last_contact[k] = self.steps;
                self.contact_face[k] = h.partner;
                self.side[k] = h.side;
                self.last_depth[k] = h.penetration - h.offset;
                self.offset[k] = h.offset;
                for (j, &node) in face.nodes.iter().enumerate() {
                    force[node] = sub(force[node], scale(total, h.weights[j]));
                    let sl = self.surface.slot[node] as usize;
                    self.normal_load[sl] += fnorm * h.weights[j];
                }
            }
        }
        (new_last, elastic)
    }
}
