//! Whole-contact event records ([`ContactEvent`]), on when the scene sets
//! [`Scene::record_events`](crate::dem::Scene::record_events) and at no cost otherwise.
//!
//! Each candidate pair and each wall slot carries an [`EventAcc`] beside its contact state.
//! After every force phase ([`Simulation::accumulate_events`]) a contact that began opens its
//! accumulator with the onset's speeds and positions; every step in contact adds F_n Δt to the
//! impulse and raises the peaks; a contact that ended is written to the event log. The step
//! then writes the normal forces of every contact (its "detail" values) on every step, not
//! only the last of a [`Simulation::step`] call: that, and one pass over the pair flags and
//! the wall slots, is the whole cost. The accumulators travel with the pairs and slots
//! through the neighbour-list rebuilds and are part of a checkpoint, so a resumed run logs
//! the same events as an uninterrupted one.

use super::{Simulation, NO_WALL};
use crate::dem::record::{ContactEvent, Partner};
use crate::geometry::Vec3;

/// What a contact has done so far (see the module docs).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct EventAcc {
    /// The contact is open (a wall slot's own flag; for pairs `pair_listed` says it).
    pub(crate) open: bool,
    /// Step of the first force evaluation in contact.
    pub(crate) start_step: u64,
    pub(crate) normal_speed: f64,
    pub(crate) tangential_speed: f64,
    pub(crate) position: Vec3,
    pub(crate) partner_position: Vec3,
    pub(crate) peak_normal_force: f64,
    pub(crate) normal_impulse: f64,
    pub(crate) peak_tangential_force: f64,
    pub(crate) max_overlap: f64,
}

impl EventAcc {
    /// Add one step in contact: normal force `f_n` (N), tangential force magnitude `f_t`
    /// (N), overlap (m), step `dt` (s).
    #[inline]
    fn add(&mut self, f_n: f64, f_t: f64, overlap: f64, dt: f64) {
        self.peak_normal_force = self.peak_normal_force.max(f_n);
        self.peak_tangential_force = self.peak_tangential_force.max(f_t);
        self.max_overlap = self.max_overlap.max(overlap);
        self.normal_impulse += f_n * dt;
    }

    fn event(
        &self,
        particle: u32,
        partner: Partner,
        end_step: u64,
        dt: f64,
        complete: bool,
    ) -> ContactEvent {
        ContactEvent {
            time: self.start_step as f64 * dt,
            duration: end_step.saturating_sub(self.start_step) as f64 * dt,
            particle,
            partner,
            normal_speed: self.normal_speed,
            tangential_speed: self.tangential_speed,
            position: self.position,
            partner_position: self.partner_position,
            peak_normal_force: self.peak_normal_force,
            normal_impulse: self.normal_impulse,
            peak_tangential_force: self.peak_tangential_force,
            max_overlap: self.max_overlap,
            complete,
        }
    }
}

impl Simulation {
    /// After a force phase, before the gather lists are brought in step with `pair_active`
    /// (so `pair_listed` still says which pairs were in contact before it): open, add to and
    /// close the accumulators of the contacts.
    pub(super) fn accumulate_events(&mut self) {
        let (step, dt) = (self.steps, self.dt);
        for (e, p) in self.pairs.iter().enumerate() {
            let acc = &mut self.pair_event[e];
            if self.pair_active[e] {
                let (out, d) = (&self.pair_out[e], &self.pair_detail[e]);
                if !self.pair_listed[e] {
                    *acc = EventAcc {
                        open: true,
                        start_step: step,
                        normal_speed: d.onset_normal_speed,
                        tangential_speed: d.onset_tangential_speed,
                        position: self.position[p.i as usize],
                        partner_position: self.position[p.j as usize],
                        ..Default::default()
                    };
                }
                let f_t = (out.force + d.normal_force * d.normal).length();
                acc.add(d.normal_force, f_t, out.overlap, dt);
            } else if self.pair_listed[e] && acc.open {
                self.events
                    .push(acc.event(p.i, Partner::Particle(p.j), step, dt, true));
                acc.open = false;
            }
        }
        let stride = self.wall_stride;
        for (k, s) in self.wall_slots.iter().enumerate() {
            if s.wall == NO_WALL {
                continue;
            }
            let acc = &mut self.wall_event[k];
            if s.active {
                let (out, d) = (&self.wall_out[k], &self.wall_detail[k]);
                if !acc.open {
                    *acc = EventAcc {
                        open: true,
                        start_step: step,
                        normal_speed: d.onset_normal_speed,
                        tangential_speed: d.onset_tangential_speed,
                        position: self.position[k / stride],
                        partner_position: d.point,
                        ..Default::default()
                    };
                }
                let f_t = (out.force + d.normal_force * d.normal).length();
                acc.add(d.normal_force, f_t, d.overlap, dt);
            } else if acc.open {
                let i = (k / stride) as u32;
                self.events
                    .push(acc.event(i, Partner::Wall(s.wall), step, dt, true));
                acc.open = false;
            }
        }
    }

    /// An open contact whose pair or slot the rebuild drops (a removed particle): logged as
    /// cut short at the current step.
    pub(super) fn close_dropped(&mut self, acc: &EventAcc, particle: u32, partner: Partner) {
        if acc.open {
            let ev = acc.event(particle, partner, self.steps, self.dt, false);
            self.events.push(ev);
        }
    }

    /// The contacts open now, as events so far (`complete` = false; duration to now). The
    /// log is not changed: a run that goes on logs them when they end.
    pub fn open_events(&self) -> Vec<ContactEvent> {
        let (step, dt) = (self.steps, self.dt);
        let mut out = Vec::new();
        if !self.record_events {
            return out;
        }
        for ((p, acc), &listed) in self
            .pairs
            .iter()
            .zip(&self.pair_event)
            .zip(&self.pair_listed)
        {
            if listed && acc.open {
                out.push(acc.event(p.i, Partner::Particle(p.j), step, dt, false));
            }
        }
        for (k, (s, acc)) in self.wall_slots.iter().zip(&self.wall_event).enumerate() {
            if s.wall != NO_WALL && acc.open {
                let i = (k / self.wall_stride) as u32;
                out.push(acc.event(i, Partner::Wall(s.wall), step, dt, false));
            }
        }
        out
    }

    /// The logged events (contacts that ended), in the order they ended.
    pub fn events(&self) -> &[ContactEvent] {
        &self.events
    }
}
