//! Neighbour search: a cell grid builds a Verlet list of candidate pairs (centre distance
//! below r_i + r_j + skin) sorted by (i, j); it is rebuilt only when a particle or a wall has
//! moved more than half the skin since the last build, so between rebuilds no contact can be
//! missed. Buffers are reused across rebuilds.

use crate::geometry::Vec3;

/// Reusable buffers of the cell grid.
#[derive(Debug, Default, Clone)]
pub(crate) struct CellGrid {
    cell_of: Vec<u32>,
    cell_start: Vec<u32>,
    sorted: Vec<u32>,
    scratch: Vec<u32>,
}

impl CellGrid {
    /// Candidate pairs (i < j), sorted by (i, j), of alive particles whose centre distance is
    /// below r_i + r_j + skin. Appends to `out` after clearing it.
    pub(crate) fn candidate_pairs(
        &mut self,
        position: &[Vec3],
        radius: &[f64],
        alive: &[bool],
        skin: f64,
        out: &mut Vec<(u32, u32)>,
    ) {
        out.clear();
        let n = position.len();
        let mut lo = Vec3::splat(f64::INFINITY);
        let mut hi = Vec3::splat(f64::NEG_INFINITY);
        let mut r_max: f64 = 0.0;
        let mut n_alive = 0usize;
        for i in 0..n {
            if alive[i] {
                lo = lo.min(position[i]);
                hi = hi.max(position[i]);
                r_max = r_max.max(radius[i]);
                n_alive += 1;
            }
        }
        if n_alive < 2 {
            return;
        }
        // Coordinates spanning more than f64::MAX (centres near ±1e308) overflow hi - lo to
        // infinity, and an infinite extent kept the cell-growing loop below spinning forever:
        // such a grid is measured in half coordinates (h = 0.5), which cannot overflow for
        // finite positions. h = 1 otherwise, so the usual grid is unchanged bit for bit.
        let h = if (hi - lo).is_finite() { 1.0 } else { 0.5 };
        let extent = hi * h - lo * h;
        let lo_h = lo * h;
        let mut cell = (2.0 * r_max + skin) * h;
        if !(cell.is_finite() && cell > 0.0) {
            // no usable reach (zero radii and skin, or overflow): one cell per axis
            cell = f64::MAX;
        }
        // keep the grid at most ~4 cells per particle so a far-away stray particle cannot blow
        // up memory; cells larger than needed only cost extra distance checks
        // capped before the cast so a stray particle far away cannot overflow the count
        let dims = |c: f64| -> [usize; 3] {
            let k = |e: f64| (e / c).floor().min(1e12) as usize + 1;
            [k(extent.x), k(extent.y), k(extent.z)]
        };
        let budget = 4.0 * n_alive as f64 + 64.0;
        let mut d = dims(cell);
        // bounded: the extent is finite, so the count falls to 1 per axis once the cell
        // exceeds it (at most ~1800 growths from the smallest positive cell to f64::MAX)
        while (d[0] as f64) * (d[1] as f64) * (d[2] as f64) > budget {
            if cell >= f64::MAX / 1.5 {
                cell = f64::MAX;
                d = [1, 1, 1];
                break;
            }
            cell *= 1.5;
            d = dims(cell);
        }
        let n_cells = d[0] * d[1] * d[2];
        let inv = 1.0 / cell;
        let cell_coord = |p: Vec3| -> [usize; 3] {
            let q = (p * h - lo_h) * inv;
            [
                (q.x as usize).min(d[0] - 1),
                (q.y as usize).min(d[1] - 1),
                (q.z as usize).min(d[2] - 1),
            ]
        };
        self.cell_of.clear();
        self.cell_start.clear();
        self.cell_start.resize(n_cells + 1, 0);
        for i in 0..n {
            let c = if alive[i] {
                let [cx, cy, cz] = cell_coord(position[i]);
                (cx + d[0] * (cy + d[1] * cz)) as u32
            } else {
                u32::MAX
            };
            self.cell_of.push(c);
            if c != u32::MAX {
                self.cell_start[c as usize + 1] += 1;
            }
        }
        for c in 0..n_cells {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        self.sorted.clear();
        self.sorted.resize(n_alive, 0);
        self.scratch.clear();
        self.scratch.extend_from_slice(&self.cell_start[..n_cells]);
        for i in 0..n {
            let c = self.cell_of[i];
            if c != u32::MAX {
                let slot = &mut self.scratch[c as usize];
                self.sorted[*slot as usize] = i as u32;
                *slot += 1;
            }
        }
        for i in 0..n {
            if !alive[i] {
                continue;
            }
            let start = out.len();
            let [cx, cy, cz] = cell_coord(position[i]);
            for z in cz.saturating_sub(1)..=(cz + 1).min(d[2] - 1) {
                for y in cy.saturating_sub(1)..=(cy + 1).min(d[1] - 1) {
                    for x in cx.saturating_sub(1)..=(cx + 1).min(d[0] - 1) {
                        let c = x + d[0] * (y + d[1] * z);
                        let (a, b) = (self.cell_start[c] as usize, self.cell_start[c + 1] as usize);
                        for &j in &self.sorted[a..b] {
                            let ju = j as usize;
                            if ju <= i {
                                continue;
                            }
                            let reach = radius[i] + radius[ju] + skin;
                            if (position[ju] - position[i]).length_squared() < reach * reach {
                                out.push((i as u32, j));
                            }
                        }
                    }
                }
            }
            out[start..].sort_unstable();
        }
    }
}
