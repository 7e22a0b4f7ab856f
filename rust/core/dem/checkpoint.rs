//! Checkpoint and restart of a DEM simulation, in the one checkpoint format of demfem
//! ([`crate::state_io`], kind `dem`). A run restored into a simulation built from the same
//! scene continues bitwise identically to an uninterrupted one.
//!
//! The static scene (particles' radii, materials, walls, effects, dt) is not stored; a
//! fingerprint of it is, and loading into a simulation whose scene differs is refused.
//! Records (frames, onsets, logged events) are outputs and are not stored; the accumulators
//! of the contacts still open are, so a resumed run logs the same events.
//!
//! Sections, in order (n particles, W walls, P listed pairs, S = n × stride wall slots):
//!
//! | section | entries | content |
//! |---|---|---|
//! | `kind` | 3 | the bytes `dem` |
//! | `scene_fingerprint` | 1 | u64, [`Simulation::scene_fingerprint`] |
//! | `time` | 1 | f64, simulated time, s |
//! | `steps`, `rebuilds` | 1 each | u64, steps taken, neighbour-list rebuilds |
//! | `needs_rebuild` | 1 | flag: the lists are rebuilt before the next step |
//! | `position`, `velocity`, `omega` | n | 3-vectors: m, m/s, rad/s |
//! | `reference_position` | n | 3-vectors, m: positions at the last rebuild |
//! | `alive` | n | flags |
//! | `reference_wall_offset`, `reference_wall_angle` | W | 3-vectors, m; f64, rad: walls at the last rebuild |
//! | `pair.i`, `pair.j` | P | u32: the Verlet list, i < j |
//! | `pair.active`, `pair.history` | P | flag: in contact; 3-vector, m: tangential spring ξ |
//! | `wall_stride` | 1 | u64: slots per particle |
//! | `slot.wall`, `slot.triangle` | S | u32: wall (u32::MAX: empty slot), triangle of a mesh wall |
//! | `slot.active`, `slot.history` | S | flag; 3-vector, m, as for pairs |
//! | `record_events` | 1 | flag: the accumulators follow |
//! | `event.*` | P + S | when recorded, pairs then slots: `open` (flag), `start_step` (u64), `normal_speed`, `tangential_speed` (m/s), `peak_normal_force`, `peak_tangential_force` (N), `normal_impulse` (N s), `max_overlap` (m), `position`, `partner_position` (3-vectors, m) |
//!
//! Files are written atomically ([`crate::state_io::write_file_atomic`]). Checkpoints of
//! earlier demfem versions (magic `DEMFEMCK`) are refused: rerun those from the start.

use std::path::Path;

use crate::dem::simulation::{EventAcc, PairContact, Simulation, WallContact};
use crate::error::{DemfemError, Result};
use crate::state_io::{read_file, write_file_atomic, StateKind, StateReader, StateWriter};

fn bad(detail: String) -> DemfemError {
    DemfemError::ShapeMismatch {
        field: "saved state".into(),
        detail,
    }
}

fn write_events(w: &mut StateWriter, accs: &[&EventAcc]) {
    let f64s = |f: fn(&EventAcc) -> f64| accs.iter().map(|a| f(a)).collect::<Vec<_>>();
    w.bools(
        "event.open",
        &accs.iter().map(|a| a.open).collect::<Vec<_>>(),
    );
    let start: Vec<u64> = accs.iter().map(|a| a.start_step).collect();
    w.u64s("event.start_step", &start);
    w.f64s("event.normal_speed", &f64s(|a| a.normal_speed));
    w.f64s("event.tangential_speed", &f64s(|a| a.tangential_speed));
    w.f64s("event.peak_normal_force", &f64s(|a| a.peak_normal_force));
    w.f64s(
        "event.peak_tangential_force",
        &f64s(|a| a.peak_tangential_force),
    );
    w.f64s("event.normal_impulse", &f64s(|a| a.normal_impulse));
    w.f64s("event.max_overlap", &f64s(|a| a.max_overlap));
    let pos: Vec<_> = accs.iter().map(|a| a.position).collect();
    w.vectors("event.position", &pos);
    let partner: Vec<_> = accs.iter().map(|a| a.partner_position).collect();
    w.vectors("event.partner_position", &partner);
}

fn read_events(r: &mut StateReader<'_>, n: usize) -> Result<Vec<EventAcc>> {
    let open = r.bools("event.open", Some(n))?;
    let start_step = r.u64s("event.start_step", Some(n))?;
    let normal_speed = r.f64s("event.normal_speed", Some(n))?;
    let tangential_speed = r.f64s("event.tangential_speed", Some(n))?;
    let peak_normal_force = r.f64s("event.peak_normal_force", Some(n))?;
    let peak_tangential_force = r.f64s("event.peak_tangential_force", Some(n))?;
    let normal_impulse = r.f64s("event.normal_impulse", Some(n))?;
    let max_overlap = r.f64s("event.max_overlap", Some(n))?;
    let position = r.vectors("event.position", Some(n))?;
    let partner_position = r.vectors("event.partner_position", Some(n))?;
    Ok((0..n)
        .map(|k| EventAcc {
            open: open[k],
            start_step: start_step[k],
            normal_speed: normal_speed[k],
            tangential_speed: tangential_speed[k],
            peak_normal_force: peak_normal_force[k],
            normal_impulse: normal_impulse[k],
            peak_tangential_force: peak_tangential_force[k],
            max_overlap: max_overlap[k],
            position: position[k],
            partner_position: partner_position[k],
        })
        .collect())
}

/// FNV-1a, 64 bit: a stable hash for the scene fingerprint.
struct Fnv(u64);
impl Fnv {
    fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 ^= x as u64;
            self.0 = self.0.wrapping_mul(0x100000001b3);
        }
    }
    fn f64(&mut self, v: f64) {
        self.bytes(&v.to_bits().to_le_bytes());
    }
}

impl Simulation {
    /// Fingerprint of the static scene: what a checkpoint must match to be loaded.
    pub fn scene_fingerprint(&self) -> u64 {
        let mut h = Fnv(0xcbf29ce484222325);
        h.bytes(&(self.radius.len() as u64).to_le_bytes());
        for i in 0..self.radius.len() {
            h.f64(self.radius[i]);
            h.f64(self.mass[i]);
            h.bytes(&self.material[i].to_le_bytes());
        }
        h.bytes(format!("{:?}", self.walls).as_bytes());
        h.bytes(format!("{:?}{:?}", self.laws, self.model).as_bytes());
        h.bytes(&self.effects.bits().to_le_bytes());
        h.f64(self.gravity.x);
        h.f64(self.gravity.y);
        h.f64(self.gravity.z);
        h.f64(self.dt);
        h.f64(self.skin);
        h.bytes(&[self.clamp as u8]);
        h.bytes(format!("{:?}", self.removal_plane).as_bytes());
        h.0
    }

    /// The checkpoint as bytes.
    pub fn checkpoint_bytes(&self) -> Vec<u8> {
        let mut w = StateWriter::new(StateKind::Dem);
        w.u64("scene_fingerprint", self.scene_fingerprint());
        w.f64("time", self.time);
        w.u64("steps", self.steps);
        w.u64("rebuilds", self.rebuilds);
        w.bool("needs_rebuild", self.needs_rebuild);
        w.vectors("position", &self.position);
        w.vectors("velocity", &self.velocity);
        w.vectors("omega", &self.omega);
        w.vectors("reference_position", &self.reference_position);
        w.bools("alive", &self.alive);
        w.vectors("reference_wall_offset", &self.reference_wall_offset);
        w.f64s("reference_wall_angle", &self.reference_wall_angle);
        w.u32s(
            "pair.i",
            &self.pairs.iter().map(|p| p.i).collect::<Vec<_>>(),
        );
        w.u32s(
            "pair.j",
            &self.pairs.iter().map(|p| p.j).collect::<Vec<_>>(),
        );
        w.bools("pair.active", &self.pair_active);
        let history: Vec<_> = self.pairs.iter().map(|p| p.history).collect();
        w.vectors("pair.history", &history);
        w.u64("wall_stride", self.wall_stride as u64);
        let slots = &self.wall_slots;
        w.u32s(
            "slot.wall",
            &slots.iter().map(|s| s.wall).collect::<Vec<_>>(),
        );
        let triangle: Vec<_> = slots.iter().map(|s| s.triangle).collect();
        w.u32s("slot.triangle", &triangle);
        w.bools(
            "slot.active",
            &slots.iter().map(|s| s.active).collect::<Vec<_>>(),
        );
        let history: Vec<_> = slots.iter().map(|s| s.history).collect();
        w.vectors("slot.history", &history);
        w.bool("record_events", self.record_events);
        if self.record_events {
            let accs: Vec<&EventAcc> = self.pair_event.iter().chain(&self.wall_event).collect();
            write_events(&mut w, &accs);
        }
        w.finish()
    }

    /// Write a checkpoint atomically (temp file, fsync, rename).
    pub fn save_checkpoint(&self, path: &Path) -> Result<()> {
        write_file_atomic(path, &self.checkpoint_bytes())
    }

    /// Restore the state from checkpoint bytes; `path` only names the source in errors
    /// ([`DemfemError::Io`] naming it). Nothing changes unless the whole state fits.
    pub fn restore_checkpoint_bytes(&mut self, data: &[u8], path: &str) -> Result<()> {
        self.restore(data).map_err(|e| match e {
            DemfemError::ShapeMismatch { detail, .. } => DemfemError::Io {
                path: path.into(),
                detail,
            },
            e => e,
        })
    }

    fn restore(&mut self, data: &[u8]) -> Result<()> {
        let mut r = StateReader::new(data, StateKind::Dem)?;
        if r.u64("scene_fingerprint")? != self.scene_fingerprint() {
            return Err(bad(
                "checkpoint written by a different scene (fingerprint mismatch)".into(),
            ));
        }
        let n = self.position.len();
        let n_walls = self.walls.len();
        let time = r.f64("time")?;
        let steps = r.u64("steps")?;
        let rebuilds = r.u64("rebuilds")?;
        let needs_rebuild = r.bool("needs_rebuild")?;
        let position = r.vectors("position", Some(n))?;
        let velocity = r.vectors("velocity", Some(n))?;
        let omega = r.vectors("omega", Some(n))?;
        let reference = r.vectors("reference_position", Some(n))?;
        let alive = r.bools("alive", Some(n))?;
        let wall_ref = r.vectors("reference_wall_offset", Some(n_walls))?;
        let wall_angle = r.f64s("reference_wall_angle", Some(n_walls))?;
        let pair_i = r.u32s("pair.i", None)?;
        let n_pairs = pair_i.len();
        let pair_j = r.u32s("pair.j", Some(n_pairs))?;
        let pair_active = r.bools("pair.active", Some(n_pairs))?;
        let pair_history = r.vectors("pair.history", Some(n_pairs))?;
        let mut pairs = Vec::with_capacity(n_pairs);
        for ((&i, &j), &history) in pair_i.iter().zip(&pair_j).zip(&pair_history) {
            if i >= j || j as usize >= n {
                return Err(bad(format!("corrupt checkpoint: pair ({i}, {j})")));
            }
            pairs.push(PairContact { i, j, history });
        }
        let pair_onset = vec![false; n_pairs];
        // a mesh wall has a slot per triangle within reach
        let triangles = |w: u32| {
            self.walls[w as usize]
                .mesh()
                .map_or(1, |m| m.triangles().len())
        };
        let max_stride = (0..n_walls as u32).map(triangles).sum::<usize>().max(1);
        let stride = r.u64("wall_stride")?;
        if stride > max_stride as u64 {
            return Err(bad(format!(
                "corrupt checkpoint: wall stride {stride} > {max_stride}"
            )));
        }
        let stride = (stride as usize).max(1);
        let n_slots = n * stride;
        let slot_wall = r.u32s("slot.wall", Some(n_slots))?;
        let slot_triangle = r.u32s("slot.triangle", Some(n_slots))?;
        let slot_active = r.bools("slot.active", Some(n_slots))?;
        let slot_history = r.vectors("slot.history", Some(n_slots))?;
        let mut slots = Vec::with_capacity(n_slots);
        for k in 0..n_slots {
            let (wall, triangle) = (slot_wall[k], slot_triangle[k]);
            if wall != u32::MAX {
                if wall as usize >= n_walls {
                    return Err(bad(format!("corrupt checkpoint: wall index {wall}")));
                }
                if triangle as usize >= triangles(wall) {
                    return Err(bad(format!(
                        "corrupt checkpoint: triangle index {triangle}"
                    )));
                }
            }
            slots.push(WallContact {
                wall,
                triangle,
                active: slot_active[k],
                history: slot_history[k],
                ..Default::default()
            });
        }
        let saved = if r.bool("record_events")? {
            Some(read_events(&mut r, n_pairs + n_slots)?)
        } else {
            None
        };
        r.finish()?;
        let (pair_event, wall_event) = match saved {
            _ if !self.record_events => (Vec::new(), Vec::new()),
            Some(mut accs) => {
                let wall = accs.split_off(n_pairs);
                (accs, wall)
            }
            None => {
                // a checkpoint without events: the contacts open now start their events here
                let open = |active: bool| EventAcc {
                    open: active,
                    start_step: steps,
                    ..Default::default()
                };
                (
                    pair_active.iter().map(|&a| open(a)).collect(),
                    slots.iter().map(|s| open(s.active)).collect(),
                )
            }
        };
        self.time = time;
        self.steps = steps;
        self.rebuilds = rebuilds;
        self.needs_rebuild = needs_rebuild;
        self.position = position;
        self.velocity = velocity;
        self.omega = omega;
        self.reference_position = reference;
        self.alive = alive;
        self.reference_wall_offset = wall_ref;
        self.reference_wall_angle = wall_angle;
        self.pairs = pairs;
        self.pair_active = pair_active;
        self.pair_onset = pair_onset;
        self.wall_stride = stride;
        self.wall_slots = slots;
        self.pair_event = pair_event;
        self.wall_event = wall_event;
        self.build_gather_lists();
        self.refresh_contact_constants();
        self.refresh_wall_state();
        Ok(())
    }

    /// Load a checkpoint written by [`Simulation::save_checkpoint`] from a simulation built
    /// from the same scene.
    pub fn load_checkpoint(&mut self, path: &Path) -> Result<()> {
        let data = read_file(path)?;
        self.restore_checkpoint_bytes(&data, &path.display().to_string())
    }
}
