//! The one checkpoint format of demfem: a run's dynamic state as bytes, for exact restarts
//! of the DEM ([`crate::dem::Simulation::save_checkpoint`]) and of explicit FEM runs
//! ([`crate::fem::Explicit::save_state`]). The solver is rebuilt from the same inputs, its
//! state is restored, and the run continues bitwise as if it had never stopped.
//!
//! # Layout
//!
//! All numbers little-endian.
//!
//! | bytes | content |
//! |---|---|
//! | 8 | the magic `DEMFEMST` |
//! | 4 | the format, u32 ([`FORMAT`]) |
//! | … | sections, in the order the writer wrote them |
//!
//! A section is its name (u8 length + UTF-8 bytes), an element count (u64) and the
//! elements: u8 (flags are u8 0 or 1), u32, u64 or f64 (IEEE-754 bits, so NaN, ±0 and every
//! other value come back bit for bit); a `D`-vector is `D` f64 and counts as one element.
//! The first section is `kind`: the bytes `dem` or `fem` ([`StateKind`]). What the other
//! sections hold, with their units, is listed by their writers (`dem/checkpoint.rs`,
//! `fem/explicit/state.rs`, `fem/contact/state.rs`).
//!
//! # Reading
//!
//! The reader names every section it expects, with its count where the model fixes it, and
//! refuses with [`DemfemError::ShapeMismatch`] naming the section: another name, another
//! count (a state of another model), a count the file cannot hold, a flag other than 0 or
//! 1, a file that ends early, bytes after the last section. A state of the other kind (a DEM
//! checkpoint given to an FEM solver, or the reverse) is refused by its `kind`; a file of an
//! older format is refused by name ("written by an older demfem checkpoint format"), except
//! format 1, the FEM states written before the `kind` section, which read as kind `fem`.
//! Callers apply nothing before the whole state has been read.
//!
//! Files are written atomically by [`write_file_atomic`]: to `<path>.tmp`, fsync, rename
//! over `<path>`. (FEM states are written to files from Python, behind a header of their
//! own; see `demfem.fem.FemModel.save_state`.)

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::{DemfemError, Result};
use crate::geometry::Vec3;

const MAGIC: &[u8; 8] = b"DEMFEMST";
/// The magic of the DEM checkpoints of earlier demfem versions (and of the header Python
/// puts before an FEM state file): refused with a message that says so.
const OLD_MAGIC: &[u8; 8] = b"DEMFEMCK";
/// The format this build writes (and reads, with format 1 for FEM states).
pub const FORMAT: u32 = 2;

/// What a state belongs to: its first section, so that one solver never restores the
/// other's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StateKind {
    /// A DEM simulation ([`crate::dem::Simulation`]).
    Dem,
    /// An explicit FEM run ([`crate::fem::Explicit`]), tets or shells.
    Fem,
}

impl StateKind {
    const ALL: [StateKind; 2] = [StateKind::Dem, StateKind::Fem];

    /// The bytes of the `kind` section.
    pub fn tag(self) -> &'static str {
        match self {
            StateKind::Dem => "dem",
            StateKind::Fem => "fem",
        }
    }

    fn what(self) -> &'static str {
        match self {
            StateKind::Dem => "a DEM checkpoint",
            StateKind::Fem => "an FEM explicit-run state",
        }
    }
}

fn bad(detail: String) -> DemfemError {
    DemfemError::ShapeMismatch {
        field: "saved state".into(),
        detail,
    }
}

/// Writes named sections.
pub struct StateWriter {
    buf: Vec<u8>,
}

impl StateWriter {
    /// An empty state of `kind`: the header and the `kind` section.
    pub fn new(kind: StateKind) -> Self {
        let mut buf = Vec::with_capacity(1 << 16);
        buf.extend_from_slice(MAGIC);
        buf.extend_from_slice(&FORMAT.to_le_bytes());
        let mut w = Self { buf };
        w.u8s("kind", kind.tag().as_bytes());
        w
    }

    fn header(&mut self, name: &str, count: usize) {
        debug_assert!(name.len() < 256);
        self.buf.push(name.len() as u8);
        self.buf.extend_from_slice(name.as_bytes());
        self.buf.extend_from_slice(&(count as u64).to_le_bytes());
    }

    /// A section of bytes.
    pub fn u8s(&mut self, name: &str, v: &[u8]) {
        self.header(name, v.len());
        self.buf.extend_from_slice(v);
    }

    /// A section of flags (one byte each, 0 or 1).
    pub fn bools(&mut self, name: &str, v: &[bool]) {
        self.header(name, v.len());
        self.buf.extend(v.iter().map(|&b| u8::from(b)));
    }

    /// One flag.
    pub fn bool(&mut self, name: &str, v: bool) {
        self.bools(name, &[v]);
    }

    /// A section of u32.
    pub fn u32s(&mut self, name: &str, v: &[u32]) {
        self.header(name, v.len());
        for x in v {
            self.buf.extend_from_slice(&x.to_le_bytes());
        }
    }

    /// A section of u64.
    pub fn u64s(&mut self, name: &str, v: &[u64]) {
        self.header(name, v.len());
        for x in v {
            self.buf.extend_from_slice(&x.to_le_bytes());
        }
    }

    /// One u64.
    pub fn u64(&mut self, name: &str, v: u64) {
        self.u64s(name, &[v]);
    }

    /// A section of f64.
    pub fn f64s(&mut self, name: &str, v: &[f64]) {
        self.header(name, v.len());
        for x in v {
            self.buf.extend_from_slice(&x.to_le_bytes());
        }
    }

    /// One f64.
    pub fn f64(&mut self, name: &str, v: f64) {
        self.f64s(name, &[v]);
    }

    /// A section of 3-vectors (3 f64 each).
    pub fn vec3s(&mut self, name: &str, v: &[[f64; 3]]) {
        self.vecs(name, v);
    }

    /// A section of [`Vec3`] (x, y, z; the count is the number of vectors).
    pub fn vectors(&mut self, name: &str, v: &[Vec3]) {
        self.header(name, v.len());
        for p in v {
            for c in [p.x, p.y, p.z] {
                self.buf.extend_from_slice(&c.to_le_bytes());
            }
        }
    }

    /// A section of `D`-vectors (`D` f64 each; the count is the number of vectors).
    pub fn vecs<const D: usize>(&mut self, name: &str, v: &[[f64; D]]) {
        self.header(name, v.len());
        for x in v {
            for c in x {
                self.buf.extend_from_slice(&c.to_le_bytes());
            }
        }
    }

    /// The bytes.
    pub fn finish(self) -> Vec<u8> {
        self.buf
    }
}

/// Reads the sections back, in the order written.
pub struct StateReader<'a> {
    buf: &'a [u8],
    pos: usize,
}

impl<'a> StateReader<'a> {
    /// Check the header and that the state is of `kind`.
    pub fn new(buf: &'a [u8], kind: StateKind) -> Result<Self> {
        if buf.len() >= 8 && &buf[..8] == OLD_MAGIC {
            // Python's FEM state file: DEMFEMCK, format, length, SHA-256, then a state
            if buf.get(52..60) == Some(MAGIC.as_slice()) {
                return Err(bad(format!(
                    "an FEM state file of demfem.fem.FemModel.save_state (its own header \
                     before the state), not {}",
                    kind.what()
                )));
            }
            return Err(bad(
                "a DEM checkpoint written by an older demfem checkpoint format (DEMFEMCK); \
                 this build cannot read it: rerun from the start"
                    .into(),
            ));
        }
        if buf.len() < 12 || &buf[..8] != MAGIC {
            return Err(bad(format!(
                "not a demfem checkpoint or state ({} bytes, no DEMFEMST header)",
                buf.len()
            )));
        }
        let format = u32::from_le_bytes([buf[8], buf[9], buf[10], buf[11]]);
        let mut r = Self { buf, pos: 12 };
        let found = match format {
            // the FEM states written before the kind section
            1 => StateKind::Fem,
            FORMAT => {
                let tag = r.u8s("kind", None)?;
                StateKind::ALL
                    .into_iter()
                    .find(|k| k.tag().as_bytes() == tag.as_slice())
                    .ok_or_else(|| {
                        bad(format!("unknown kind {:?}", String::from_utf8_lossy(&tag)))
                    })?
            }
            f if f > FORMAT => {
                return Err(bad(format!(
                    "format {f}, written by a newer demfem; this build reads up to {FORMAT}"
                )))
            }
            f => {
                return Err(bad(format!(
                    "format {f}, written by an older demfem checkpoint format; rerun from \
                     the start"
                )))
            }
        };
        if found != kind {
            return Err(bad(format!(
                "{} (kind {:?}), not {} (kind {:?})",
                found.what(),
                found.tag(),
                kind.what(),
                kind.tag()
            )));
        }
        Ok(r)
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        let end = self
            .pos
            .checked_add(n)
            .filter(|&e| e <= self.buf.len())
            .ok_or_else(|| bad(format!("truncated at byte {}", self.pos)))?;
        let s = &self.buf[self.pos..end];
        self.pos = end;
        Ok(s)
    }

    /// The next section's element count, after checking its name and (when given) count.
    fn header(&mut self, name: &str, expected: Option<usize>, width: usize) -> Result<usize> {
        let at = self.pos;
        let truncated = |_| {
            bad(format!(
                "truncated at byte {at}, where {name:?} was expected"
            ))
        };
        let len = self.take(1).map_err(truncated)?[0] as usize;
        let found = self.take(len).map_err(truncated)?;
        if found != name.as_bytes() {
            return Err(bad(format!(
                "section {:?} where {name:?} was expected",
                String::from_utf8_lossy(found)
            )));
        }
        let c = self.take(8).map_err(truncated)?;
        let count = u64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]);
        if let Some(e) = expected {
            if e as u64 != count {
                return Err(bad(format!(
                    "{name}: {count} entries saved, this model has {e} (a state of another model)"
                )));
            }
        }
        let remaining = (self.buf.len() - self.pos) as u64;
        if count
            .checked_mul(width as u64)
            .is_none_or(|b| b > remaining)
        {
            return Err(bad(format!(
                "{name}: {count} entries of {width} bytes, {remaining} bytes left (truncated \
                 or corrupt)"
            )));
        }
        Ok(count as usize)
    }

    fn words<const W: usize>(
        &mut self,
        name: &str,
        expected: Option<usize>,
        per: usize,
    ) -> Result<Vec<[u8; W]>> {
        let count = self.header(name, expected, W * per)?;
        let raw = self.take(count * per * W)?;
        Ok(raw
            .chunks_exact(W)
            .map(|c| {
                let mut a = [0u8; W];
                a.copy_from_slice(c);
                a
            })
            .collect())
    }

    fn one<T>(name: &str, v: Vec<T>) -> Result<T> {
        v.into_iter()
            .next()
            .ok_or_else(|| bad(format!("{name}: no entry")))
    }

    /// A section of bytes (of `expected` entries when given).
    pub fn u8s(&mut self, name: &str, expected: Option<usize>) -> Result<Vec<u8>> {
        let count = self.header(name, expected, 1)?;
        Ok(self.take(count)?.to_vec())
    }

    /// A section of flags; a byte other than 0 or 1 is refused.
    pub fn bools(&mut self, name: &str, expected: Option<usize>) -> Result<Vec<bool>> {
        self.u8s(name, expected)?
            .into_iter()
            .map(|b| match b {
                0 => Ok(false),
                1 => Ok(true),
                b => Err(bad(format!("{name}: byte {b} is not a flag (0 or 1)"))),
            })
            .collect()
    }

    /// One flag.
    pub fn bool(&mut self, name: &str) -> Result<bool> {
        Self::one(name, self.bools(name, Some(1))?)
    }

    /// A section of u32.
    pub fn u32s(&mut self, name: &str, expected: Option<usize>) -> Result<Vec<u32>> {
        Ok(self
            .words::<4>(name, expected, 1)?
            .into_iter()
            .map(u32::from_le_bytes)
            .collect())
    }

    /// A section of u64.
    pub fn u64s(&mut self, name: &str, expected: Option<usize>) -> Result<Vec<u64>> {
        Ok(self
            .words::<8>(name, expected, 1)?
            .into_iter()
            .map(u64::from_le_bytes)
            .collect())
    }

    /// One u64.
    pub fn u64(&mut self, name: &str) -> Result<u64> {
        Self::one(name, self.u64s(name, Some(1))?)
    }

    /// A section of f64 (of `expected` entries when given).
    pub fn f64s(&mut self, name: &str, expected: Option<usize>) -> Result<Vec<f64>> {
        Ok(self
            .words::<8>(name, expected, 1)?
            .into_iter()
            .map(f64::from_le_bytes)
            .collect())
    }

    /// One f64.
    pub fn f64(&mut self, name: &str) -> Result<f64> {
        Self::one(name, self.f64s(name, Some(1))?)
    }

    /// A section of 3-vectors.
    pub fn vec3s(&mut self, name: &str, expected: Option<usize>) -> Result<Vec<[f64; 3]>> {
        self.vecs(name, expected)
    }

    /// A section of [`Vec3`] (of `expected` vectors when given).
    pub fn vectors(&mut self, name: &str, expected: Option<usize>) -> Result<Vec<Vec3>> {
        Ok(self
            .vecs::<3>(name, expected)?
            .into_iter()
            .map(|[x, y, z]| Vec3::new(x, y, z))
            .collect())
    }

    /// A section of `D`-vectors (of `expected` vectors when given).
    pub fn vecs<const D: usize>(
        &mut self,
        name: &str,
        expected: Option<usize>,
    ) -> Result<Vec<[f64; D]>> {
        let flat: Vec<f64> = self
            .words::<8>(name, expected, D)?
            .into_iter()
            .map(f64::from_le_bytes)
            .collect();
        Ok(flat
            .chunks_exact(D)
            .map(|c| {
                let mut a = [0.0; D];
                a.copy_from_slice(c);
                a
            })
            .collect())
    }

    /// Refuse trailing bytes.
    pub fn finish(self) -> Result<()> {
        if self.pos != self.buf.len() {
            return Err(bad(format!(
                "{} bytes left after the last section",
                self.buf.len() - self.pos
            )));
        }
        Ok(())
    }
}

fn io_error(path: &Path) -> impl Fn(std::io::Error) -> DemfemError + '_ {
    move |e| DemfemError::Io {
        path: path.display().to_string(),
        detail: e.to_string(),
    }
}

/// Write `bytes` to `path` atomically: to `<path>.tmp`, fsync, rename over `path` (then
/// fsync the folder where the platform can), so that after a crash `path` is either the old
/// file or the whole new one. A failed write removes the temporary file.
pub fn write_file_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    let written = std::fs::File::create(&tmp)
        .and_then(|mut f| {
            f.write_all(bytes)?;
            f.sync_all()
        })
        .and_then(|()| std::fs::rename(&tmp, path));
    if let Err(e) = written {
        let _ = std::fs::remove_file(&tmp);
        return Err(io_error(path)(e));
    }
    if let Some(dir) = path.parent() {
        // make the rename itself durable; not every platform can open a directory
        let dir = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        if let Ok(d) = std::fs::File::open(dir) {
            let _ = d.sync_all();
        }
    }
    Ok(())
}

/// The bytes of the file at `path`, or [`DemfemError::Io`] naming it.
pub fn read_file(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(io_error(path))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(kind: StateKind) -> Vec<u8> {
        let mut w = StateWriter::new(kind);
        w.f64("time", -0.0);
        w.f64s("x", &[1.5, f64::NAN, f64::MIN_POSITIVE]);
        w.u64("steps", u64::MAX);
        w.u32s("ids", &[0, 7, u32::MAX]);
        w.bools("alive", &[true, false, true]);
        w.vectors("p", &[Vec3::new(1.0, -2.0, 3.0)]);
        w.vecs("six", &[[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]]);
        w.finish()
    }

    fn read(bytes: &[u8], kind: StateKind) -> Result<()> {
        let mut r = StateReader::new(bytes, kind)?;
        assert_eq!(r.f64("time")?.to_bits(), (-0.0f64).to_bits());
        let x = r.f64s("x", Some(3))?;
        assert_eq!(x[0], 1.5);
        assert!(x[1].is_nan());
        assert_eq!(r.u64("steps")?, u64::MAX);
        assert_eq!(r.u32s("ids", None)?, [0, 7, u32::MAX]);
        assert_eq!(r.bools("alive", Some(3))?, [true, false, true]);
        assert_eq!(r.vectors("p", None)?, [Vec3::new(1.0, -2.0, 3.0)]);
        assert_eq!(r.vecs::<6>("six", Some(1))?[0][5], 6.0);
        r.finish()
    }

    fn detail(e: DemfemError) -> String {
        match e {
            DemfemError::ShapeMismatch { detail, .. } => detail,
            e => panic!("expected ShapeMismatch, got {e:?}"),
        }
    }

    #[test]
    fn round_trip_is_bitwise() {
        read(&sample(StateKind::Dem), StateKind::Dem).unwrap();
        read(&sample(StateKind::Fem), StateKind::Fem).unwrap();
    }

    #[test]
    fn the_other_kind_is_refused_by_name() {
        let e = detail(
            StateReader::new(&sample(StateKind::Dem), StateKind::Fem)
                .err()
                .unwrap(),
        );
        assert!(
            e.contains("a DEM checkpoint") && e.contains("not an FEM"),
            "{e}"
        );
        let e = detail(
            StateReader::new(&sample(StateKind::Fem), StateKind::Dem)
                .err()
                .unwrap(),
        );
        assert!(
            e.contains("an FEM") && e.contains("not a DEM checkpoint"),
            "{e}"
        );
    }

    #[test]
    fn every_truncation_and_every_byte_flip_is_an_error_or_a_value_never_a_panic() {
        let bytes = sample(StateKind::Dem);
        for n in 0..bytes.len() {
            assert!(
                read(&bytes[..n], StateKind::Dem).is_err(),
                "prefix {n} read"
            );
        }
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(detail(read(&longer, StateKind::Dem).unwrap_err()).contains("1 bytes left"));
        for i in 0..bytes.len() {
            for bit in [0x01, 0x80] {
                let mut b = bytes.clone();
                b[i] ^= bit;
                let mut r = match StateReader::new(&b, StateKind::Dem) {
                    Ok(r) => r,
                    Err(_) => continue,
                };
                // the typed reads alone: the values of a flipped payload byte differ
                let _ = r
                    .f64s("time", Some(1))
                    .and_then(|_| r.f64s("x", Some(3)))
                    .and_then(|_| r.u64s("steps", Some(1)))
                    .and_then(|_| r.u32s("ids", None))
                    .and_then(|_| r.bools("alive", Some(3)))
                    .and_then(|_| r.vectors("p", None))
                    .and_then(|_| r.vecs::<6>("six", Some(1)));
            }
        }
    }

    #[test]
    fn names_counts_flags_and_impossible_counts_are_checked() {
        let bytes = sample(StateKind::Fem);
        let mut r = StateReader::new(&bytes, StateKind::Fem).unwrap();
        let e = detail(r.f64s("clock", None).unwrap_err());
        assert!(
            e.contains(r#"section "time" where "clock" was expected"#),
            "{e}"
        );
        let mut r = StateReader::new(&bytes, StateKind::Fem).unwrap();
        r.f64("time").unwrap();
        let e = detail(r.f64s("x", Some(4)).unwrap_err());
        assert!(e.contains("x: 3 entries saved, this model has 4"), "{e}");

        let mut w = StateWriter::new(StateKind::Dem);
        w.u8s("flags", &[0, 1, 2]);
        let b = w.finish();
        let mut r = StateReader::new(&b, StateKind::Dem).unwrap();
        assert!(detail(r.bools("flags", None).unwrap_err()).contains("byte 2 is not a flag"));

        // a count of 2^60 f64 is refused before anything is allocated
        let mut b = StateWriter::new(StateKind::Dem).finish();
        b.push(1);
        b.push(b'x');
        b.extend_from_slice(&(1u64 << 60).to_le_bytes());
        let mut r = StateReader::new(&b, StateKind::Dem).unwrap();
        assert!(detail(r.f64s("x", None).unwrap_err()).contains("truncated or corrupt"));
    }

    #[test]
    fn old_and_foreign_files_are_refused_by_what_they_are() {
        let mut old = b"DEMFEMCK".to_vec();
        old.extend_from_slice(&3u32.to_le_bytes());
        old.extend_from_slice(&[0; 40]);
        let e = detail(StateReader::new(&old, StateKind::Dem).err().unwrap());
        assert!(
            e.contains("older demfem checkpoint format") && e.contains("rerun"),
            "{e}"
        );
        // Python's FEM state file: DEMFEMCK, format 1, length, SHA-256, then a state
        let mut py = b"DEMFEMCK".to_vec();
        py.extend_from_slice(&1u32.to_le_bytes());
        py.extend_from_slice(&[0; 40]);
        py.extend_from_slice(&sample(StateKind::Fem));
        let e = detail(StateReader::new(&py, StateKind::Dem).err().unwrap());
        assert!(e.contains("FemModel.save_state"), "{e}");
        for junk in [&b""[..], b"DEMFEM", b"not a demfem state at all"] {
            let e = detail(StateReader::new(junk, StateKind::Dem).err().unwrap());
            assert!(e.contains("no DEMFEMST header"), "{e}");
        }
        let mut newer = sample(StateKind::Dem);
        newer[8..12].copy_from_slice(&(FORMAT + 1).to_le_bytes());
        let e = detail(StateReader::new(&newer, StateKind::Dem).err().unwrap());
        assert!(e.contains("newer demfem"), "{e}");
        let mut zero = sample(StateKind::Dem);
        zero[8..12].copy_from_slice(&0u32.to_le_bytes());
        let e = detail(StateReader::new(&zero, StateKind::Dem).err().unwrap());
        assert!(e.contains("older demfem checkpoint format"), "{e}");
    }

    #[test]
    fn format_1_fem_states_without_kind_still_read() {
        let new = sample(StateKind::Fem);
        let kind_len = 1 + 4 + 8 + 3; // name length, "kind", count, "fem"
        let mut old = new[..12].to_vec();
        old[8..12].copy_from_slice(&1u32.to_le_bytes());
        old.extend_from_slice(&new[12 + kind_len..]);
        read(&old, StateKind::Fem).unwrap();
        assert!(StateReader::new(&old, StateKind::Dem).is_err());
    }

    #[test]
    fn atomic_write_replaces_the_file_and_leaves_no_temporary() {
        let dir = std::env::temp_dir().join(format!("demfem-state-io-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("a.state");
        write_file_atomic(&path, b"one").unwrap();
        write_file_atomic(&path, b"two").unwrap();
        assert_eq!(read_file(&path).unwrap(), b"two");
        assert!(!dir.join("a.state.tmp").exists());
        let missing = dir.join("no such folder").join("b.state");
        match write_file_atomic(&missing, b"x") {
            Err(DemfemError::Io { path, .. }) => assert!(path.contains("b.state")),
            r => panic!("expected an i/o error, got {r:?}"),
        }
        assert!(matches!(read_file(&missing), Err(DemfemError::Io { .. })));
        std::fs::remove_dir_all(&dir).ok();
    }
}
