//! What the records read of a step: the onset log (pairs and wall slots whose contact
//! began), frames of the state, and the list of active contacts.

use super::{Simulation, NO_WALL, PAIR_CHUNK};
use crate::dem::record::{ContactOnset, ContactRecord, Frame, Partner};
use crate::geometry::Vec3;

impl Simulation {
    pub(super) fn log_onsets(&mut self, walls: bool) {
        let time = self.time;
        let step = self.steps;
        for (c, flips) in self.chunk_flips.iter().enumerate() {
            if flips.onsets == 0 {
                continue;
            }
            let end = ((c + 1) * PAIR_CHUNK).min(self.pairs.len());
            for ((p, d), &onset) in self.pairs[c * PAIR_CHUNK..end]
                .iter()
                .zip(&self.pair_detail[c * PAIR_CHUNK..end])
                .zip(&self.pair_onset[c * PAIR_CHUNK..end])
            {
                if onset {
                    self.onsets.push(ContactOnset {
                        time,
                        step,
                        particle: p.i,
                        partner: Partner::Particle(p.j),
                        normal_speed: d.onset_normal_speed,
                        tangential_speed: d.onset_tangential_speed,
                        position: self.position_at_force_pass(p.i as usize),
                        partner_position: self.position_at_force_pass(p.j as usize),
                    });
                }
            }
        }
        if walls {
            let stride = self.wall_stride;
            for (k, (s, d)) in self.wall_slots.iter().zip(&self.wall_detail).enumerate() {
                if s.wall != NO_WALL && s.onset {
                    let i = k / stride;
                    self.onsets.push(ContactOnset {
                        time,
                        step,
                        particle: i as u32,
                        partner: Partner::Wall(s.wall),
                        normal_speed: d.onset_normal_speed,
                        tangential_speed: d.onset_tangential_speed,
                        position: self.position_at_force_pass(i),
                        partner_position: d.point,
                    });
                }
            }
        }
    }

    /// Position at which the onset was detected: the force pass saw x(t), the particle phase
    /// has since moved it by v Δt, so step back.
    fn position_at_force_pass(&self, i: usize) -> Vec3 {
        self.position[i] - self.velocity[i] * self.dt
    }

    /// The current state as a [`Frame`].
    pub fn frame(&self) -> Frame {
        Frame {
            time: self.time,
            step: self.steps,
            position: self.position.clone(),
            velocity: self.velocity.clone(),
            angular_velocity: self.omega.clone(),
            contact_force_sum: self.contact_force_sum.clone(),
            coordination: self.coordination.clone(),
            wall_contacts: self.wall_coordination.clone(),
            alive: self.alive.clone(),
        }
    }

    /// Active contacts at the last force evaluation (empty right after a checkpoint restore,
    /// whose contacts have not been evaluated yet, apart from their flags).
    pub fn contacts(&self) -> Vec<ContactRecord> {
        let mut out = Vec::new();
        let pairs = self.pairs.iter().zip(&self.pair_active);
        for (((p, &active), o), d) in pairs.zip(&self.pair_out).zip(&self.pair_detail) {
            if active && o.overlap > 0.0 {
                let i = p.i as usize;
                let x_i = self.position[i] - self.velocity[i] * self.dt;
                out.push(ContactRecord {
                    particle: p.i,
                    partner: Partner::Particle(p.j),
                    normal: d.normal,
                    normal_force: d.normal_force,
                    tangential_force: o.force + d.normal_force * d.normal,
                    overlap: o.overlap,
                    point: x_i + (self.radius[i] - 0.5 * o.overlap) * d.normal,
                });
            }
        }
        for (k, ((s, o), d)) in self
            .wall_slots
            .iter()
            .zip(&self.wall_out)
            .zip(&self.wall_detail)
            .enumerate()
        {
            if s.wall != NO_WALL && s.active && d.overlap > 0.0 {
                out.push(ContactRecord {
                    particle: (k / self.wall_stride) as u32,
                    partner: Partner::Wall(s.wall),
                    normal: d.normal,
                    normal_force: d.normal_force,
                    tangential_force: o.force + d.normal_force * d.normal,
                    overlap: d.overlap,
                    point: d.point,
                });
            }
        }
        out
    }
}
