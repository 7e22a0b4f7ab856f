//! A run's dynamic state as bytes, for exact checkpoints of explicit runs: the solver (and
//! its contact model) is rebuilt from the same inputs, then its state is restored, and the
//! run continues bitwise as if it had never stopped.
//!
//! Format: the magic `DEMFEMST`, a format number (u32), then named sections, each the name
//! (u8 length + bytes), an element count (u64) and the little-endian elements. The reader
//! checks every name and every count against the solver it restores into, so a state from
//! another model is refused naming the first section that differs, never half-applied.

use crate::error::{DemfemError, Result};

const MAGIC: &[u8; 8] = b"DEMFEMST";
const FORMAT: u32 = 1;

/// Writes named sections.
pub struct StateWriter {
    buf: Vec<u8>,
}

impl Default for StateWriter {
    fn default() -> Self {
        Self::new()
    }
}

impl StateWriter {
    /// An empty state with its header.
    pub fn new() -> Self {
        let mut buf = Vec::with_capacity(1 << 16);
        buf.extend_from_slice(MAGIC);
        buf.extend_from_slice(&FORMAT.to_le_bytes());
        Self { buf }
    }

    fn header(&mut self, name: &str, count: usize) {
        debug_assert!(name.len() < 256);
        self.buf.push(name.len() as u8);
        self.buf.extend_from_slice(name.as_bytes());
        self.buf.extend_from_slice(&(count as u64).to_le_bytes());
    }

    /// A section of f64.
    pub fn f64s(&mut self, name: &str, v: &[f64]) {
        self.header(name, v.len());
        for x in v {
            self.buf.extend_from_slice(&x.to_le_bytes());
        }
    }

    /// A section of 3-vectors (3 f64 each).
    pub fn vec3s(&mut self, name: &str, v: &[[f64; 3]]) {
        self.vecs(name, v);
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

    /// A section of u64.
    pub fn u64s(&mut self, name: &str, v: &[u64]) {
        self.header(name, v.len());
        for x in v {
            self.buf.extend_from_slice(&x.to_le_bytes());
        }
    }

    /// A section of u32.
    pub fn u32s(&mut self, name: &str, v: &[u32]) {
        self.header(name, v.len());
        for x in v {
            self.buf.extend_from_slice(&x.to_le_bytes());
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

fn bad(detail: String) -> DemfemError {
    DemfemError::ShapeMismatch {
        field: "saved state".into(),
        detail,
    }
}

impl<'a> StateReader<'a> {
    /// Check the header.
    pub fn new(buf: &'a [u8]) -> Result<Self> {
        if buf.len() < 12 || &buf[..8] != MAGIC {
            return Err(bad("not a demfem explicit-run state".into()));
        }
        let format = u32::from_le_bytes([buf[8], buf[9], buf[10], buf[11]]);
        if format != FORMAT {
            return Err(bad(format!(
                "state format {format}, this build reads {FORMAT}"
            )));
        }
        Ok(Self { buf, pos: 12 })
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
        let len = self.take(1)?[0] as usize;
        let found = self.take(len)?;
        if found != name.as_bytes() {
            return Err(bad(format!(
                "section {:?} where {name:?} was expected",
                String::from_utf8_lossy(found)
            )));
        }
        let c = self.take(8)?;
        let count = u64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]) as usize;
        if let Some(e) = expected {
            if e != count {
                return Err(bad(format!(
                    "{name}: {count} entries saved, this model has {e} (a state of another model)"
                )));
            }
        }
        if count.checked_mul(width).is_none_or(|b| b > self.buf.len()) {
            return Err(bad(format!("{name}: impossible count {count}")));
        }
        Ok(count)
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

    /// A section of f64 (of `expected` entries when given).
    pub fn f64s(&mut self, name: &str, expected: Option<usize>) -> Result<Vec<f64>> {
        Ok(self
            .words::<8>(name, expected, 1)?
            .into_iter()
            .map(f64::from_le_bytes)
            .collect())
    }

    /// A section of 3-vectors.
    pub fn vec3s(&mut self, name: &str, expected: Option<usize>) -> Result<Vec<[f64; 3]>> {
        self.vecs(name, expected)
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

    /// A section of u64.
    pub fn u64s(&mut self, name: &str, expected: Option<usize>) -> Result<Vec<u64>> {
        Ok(self
            .words::<8>(name, expected, 1)?
            .into_iter()
            .map(u64::from_le_bytes)
            .collect())
    }

    /// A section of u32.
    pub fn u32s(&mut self, name: &str, expected: Option<usize>) -> Result<Vec<u32>> {
        Ok(self
            .words::<4>(name, expected, 1)?
            .into_iter()
            .map(u32::from_le_bytes)
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
