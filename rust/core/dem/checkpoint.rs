//! Checkpoint and restart: the dynamic state of a simulation (time, kinematics, alive flags,
//! Verlet lists with their tangential-spring history and contact flags, rebuild references)
//! in a little-endian binary file with a versioned header. A run restored into a simulation
//! built from the same scene continues bitwise identically to an uninterrupted one.
//!
//! The static scene (particles' radii, materials, walls, effects, dt) is not stored; a
//! fingerprint of it is, and loading into a simulation whose scene differs is refused.
//! Records (frames, onsets, logged events) are outputs and are not stored; the accumulators
//! of the contacts still open are (version 3), so a resumed run logs the same events.
//!
//! Files are written atomically: to `<path>.tmp`, fsync, rename over `<path>`.

use std::io::Write;
use std::path::Path;

use crate::dem::simulation::{EventAcc, PairContact, Simulation, WallContact};
use crate::error::{DemfemError, Result};
use crate::geometry::Vec3;

const MAGIC: &[u8; 8] = b"DEMFEMCK";
/// Version of the checkpoint format.
pub const CHECKPOINT_VERSION: u32 = 3;
/// The oldest version this build still reads (version 2: no event accumulators).
const OLDEST_VERSION: u32 = 2;

struct Writer(Vec<u8>);
impl Writer {
    fn u8(&mut self, v: u8) {
        self.0.push(v);
    }
    fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_bits().to_le_bytes());
    }
    fn vec3(&mut self, v: Vec3) {
        self.f64(v.x);
        self.f64(v.y);
        self.f64(v.z);
    }
    fn event(&mut self, a: &EventAcc) {
        self.u8(a.open as u8);
        self.u64(a.start_step);
        for v in [
            a.normal_speed,
            a.tangential_speed,
            a.peak_normal_force,
            a.normal_impulse,
            a.peak_tangential_force,
            a.max_overlap,
        ] {
            self.f64(v);
        }
        self.vec3(a.position);
        self.vec3(a.partner_position);
    }
}

struct Reader<'a> {
    data: &'a [u8],
    at: usize,
    path: &'a str,
}
impl Reader<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8]> {
        if self.at + n > self.data.len() {
            return Err(DemfemError::Io {
                path: self.path.into(),
                detail: "truncated checkpoint".into(),
            });
        }
        let s = &self.data[self.at..self.at + n];
        self.at += n;
        Ok(s)
    }
    fn u8(&mut self) -> Result<u8> {
        Ok(self.take(1)?[0])
    }
    fn u32(&mut self) -> Result<u32> {
        let mut b = [0u8; 4];
        b.copy_from_slice(self.take(4)?);
        Ok(u32::from_le_bytes(b))
    }
    fn u64(&mut self) -> Result<u64> {
        let mut b = [0u8; 8];
        b.copy_from_slice(self.take(8)?);
        Ok(u64::from_le_bytes(b))
    }
    fn f64(&mut self) -> Result<f64> {
        Ok(f64::from_bits(self.u64()?))
    }
    fn vec3(&mut self) -> Result<Vec3> {
        Ok(Vec3::new(self.f64()?, self.f64()?, self.f64()?))
    }
    fn event(&mut self) -> Result<EventAcc> {
        Ok(EventAcc {
            open: self.u8()? != 0,
            start_step: self.u64()?,
            normal_speed: self.f64()?,
            tangential_speed: self.f64()?,
            peak_normal_force: self.f64()?,
            normal_impulse: self.f64()?,
            peak_tangential_force: self.f64()?,
            max_overlap: self.f64()?,
            position: self.vec3()?,
            partner_position: self.vec3()?,
        })
    }
    fn count(&mut self, max: usize, what: &str) -> Result<usize> {
        let n = self.u64()?;
        if n > max as u64 {
            return Err(DemfemError::Io {
                path: self.path.into(),
                detail: format!("corrupt checkpoint: {what} count {n} > {max}"),
            });
        }
        Ok(n as usize)
    }
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
        let mut w = Writer(Vec::with_capacity(
            64 + self.position.len() * 100 + self.pairs.len() * 40,
        ));
        w.0.extend_from_slice(MAGIC);
        w.u32(CHECKPOINT_VERSION);
        w.u64(self.scene_fingerprint());
        w.u64(self.position.len() as u64);
        w.u64(self.walls.len() as u64);
        w.f64(self.time);
        w.u64(self.steps);
        w.u64(self.rebuilds);
        w.u8(self.needs_rebuild as u8);
        for i in 0..self.position.len() {
            w.vec3(self.position[i]);
            w.vec3(self.velocity[i]);
            w.vec3(self.omega[i]);
            w.vec3(self.reference_position[i]);
            w.u8(self.alive[i] as u8);
        }
        for v in &self.reference_wall_offset {
            w.vec3(*v);
        }
        for a in &self.reference_wall_angle {
            w.f64(*a);
        }
        w.u64(self.pairs.len() as u64);
        for (p, &active) in self.pairs.iter().zip(&self.pair_active) {
            w.u32(p.i);
            w.u32(p.j);
            w.u8(active as u8);
            w.vec3(p.history);
        }
        w.u64(self.wall_stride as u64);
        w.u64(self.wall_slots.len() as u64);
        for s in &self.wall_slots {
            w.u32(s.wall);
            w.u32(s.triangle);
            w.u8(s.active as u8);
            w.vec3(s.history);
        }
        w.u8(self.record_events as u8);
        if self.record_events {
            for a in self.pair_event.iter().chain(&self.wall_event) {
                w.event(a);
            }
        }
        w.0
    }

    /// Write a checkpoint atomically (temp file, fsync, rename).
    pub fn save_checkpoint(&self, path: &Path) -> Result<()> {
        let io = |e: std::io::Error| DemfemError::Io {
            path: path.display().to_string(),
            detail: e.to_string(),
        };
        let mut tmp = path.as_os_str().to_owned();
        tmp.push(".tmp");
        let tmp = std::path::PathBuf::from(tmp);
        {
            let mut f = std::fs::File::create(&tmp).map_err(io)?;
            f.write_all(&self.checkpoint_bytes()).map_err(io)?;
            f.sync_all().map_err(io)?;
        }
        std::fs::rename(&tmp, path).map_err(io)?;
        if let Some(dir) = path.parent() {
            // make the rename itself durable; not every platform can open a directory
            if let Ok(d) = std::fs::File::open(if dir.as_os_str().is_empty() {
                Path::new(".")
            } else {
                dir
            }) {
                let _ = d.sync_all();
            }
        }
        Ok(())
    }

    /// Restore the state from checkpoint bytes; `path` only names the source in errors.
    pub fn restore_checkpoint_bytes(&mut self, data: &[u8], path: &str) -> Result<()> {
        let mut r = Reader { data, at: 0, path };
        let bad = |detail: String| DemfemError::Io {
            path: path.into(),
            detail,
        };
        if r.take(8)? != MAGIC {
            return Err(bad("not a demfem checkpoint (bad magic)".into()));
        }
        let version = r.u32()?;
        if !(OLDEST_VERSION..=CHECKPOINT_VERSION).contains(&version) {
            return Err(bad(format!(
                "checkpoint version {version}, this build reads {OLDEST_VERSION} to \
                 {CHECKPOINT_VERSION}"
            )));
        }
        let fp = r.u64()?;
        if fp != self.scene_fingerprint() {
            return Err(bad(
                "checkpoint was written by a different scene (fingerprint mismatch)".into(),
            ));
        }
        let n = self.position.len();
        if r.u64()? != n as u64 || r.u64()? != self.walls.len() as u64 {
            return Err(bad("particle or wall count differs from the scene".into()));
        }
        let time = r.f64()?;
        let steps = r.u64()?;
        let rebuilds = r.u64()?;
        let needs_rebuild = r.u8()? != 0;
        let mut position = Vec::with_capacity(n);
        let mut velocity = Vec::with_capacity(n);
        let mut omega = Vec::with_capacity(n);
        let mut reference = Vec::with_capacity(n);
        let mut alive = Vec::with_capacity(n);
        for _ in 0..n {
            position.push(r.vec3()?);
            velocity.push(r.vec3()?);
            omega.push(r.vec3()?);
            reference.push(r.vec3()?);
            alive.push(r.u8()? != 0);
        }
        let mut wall_ref = Vec::with_capacity(self.walls.len());
        for _ in 0..self.walls.len() {
            wall_ref.push(r.vec3()?);
        }
        let mut wall_angle = Vec::with_capacity(self.walls.len());
        for _ in 0..self.walls.len() {
            wall_angle.push(r.f64()?);
        }
        let n_pairs = r.count(data.len() / 33 + 1, "pair")?;
        let mut pairs = Vec::with_capacity(n_pairs);
        let mut pair_active = Vec::with_capacity(n_pairs);
        for _ in 0..n_pairs {
            let i = r.u32()?;
            let j = r.u32()?;
            if i >= j || j as usize >= n {
                return Err(bad(format!("corrupt checkpoint: pair ({i}, {j})")));
            }
            let active = r.u8()? != 0;
            let history = r.vec3()?;
            pairs.push(PairContact {
                i,
                j,
                history,
                ..Default::default()
            });
            pair_active.push(active);
        }
        let pair_onset = vec![false; n_pairs];
        // a mesh wall has a slot per triangle within reach
        let max_stride = self
            .walls
            .iter()
            .map(|w| w.mesh().map_or(1, |m| m.triangles().len()))
            .sum::<usize>();
        let stride = r.count(max_stride.max(1), "wall stride")?.max(1);
        let n_slots = r.count(n * stride, "wall slot")?;
        if n_slots != n * stride {
            return Err(bad("corrupt checkpoint: wall slot count".into()));
        }
        let mut slots = Vec::with_capacity(n_slots);
        for _ in 0..n_slots {
            let wall = r.u32()?;
            if wall != u32::MAX && wall as usize >= self.walls.len() {
                return Err(bad(format!("corrupt checkpoint: wall index {wall}")));
            }
            let triangle = r.u32()?;
            if wall != u32::MAX {
                let n_triangles = self.walls[wall as usize]
                    .mesh()
                    .map_or(1, |m| m.triangles().len());
                if triangle as usize >= n_triangles {
                    return Err(bad(format!(
                        "corrupt checkpoint: triangle index {triangle}"
                    )));
                }
            }
            let active = r.u8()? != 0;
            let history = r.vec3()?;
            slots.push(WallContact {
                wall,
                triangle,
                active,
                history,
                ..Default::default()
            });
        }
        // version 3: the event accumulators, when the writing run recorded events
        let saved_events = version >= 3 && r.u8()? != 0;
        let mut accs = Vec::new();
        if saved_events {
            for _ in 0..n_pairs + n_slots {
                accs.push(r.event()?);
            }
        }
        if r.at != data.len() {
            return Err(bad("trailing bytes after checkpoint".into()));
        }
        let (pair_event, wall_event) = if !self.record_events {
            (Vec::new(), Vec::new())
        } else if saved_events {
            let wall = accs.split_off(n_pairs);
            (accs, wall)
        } else {
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
        let data = std::fs::read(path).map_err(|e| DemfemError::Io {
            path: path.display().to_string(),
            detail: e.to_string(),
        })?;
        self.restore_checkpoint_bytes(&data, &path.display().to_string())
    }
}
