//! The per-node half of a step: one fused pass over the nodes that forms the damping and
//! external forces at t^n, updates velocities (free, prescribed or held dofs) and
//! displacements, counts reactions as external force, and sums the energy increments
//! (kinetic, external work, damping work, internal, J) per fixed chunk of nodes. An
//! undamped run (α = β = 0, the usual case) takes a pass without the damping memory; both
//! passes give the same bits for it (its damping force is +0 throughout).

use super::{DISPLACEMENT, FREE, HELD};

/// What one step's node pass reads, for every chunk.
pub(super) struct NodePass<'a, const D: usize> {
    pub(super) mass: &'a [f64],
    pub(super) rotary: &'a [f64],
    pub(super) f_int: &'a [[f64; D]],
    pub(super) loads: &'a [[f64; D]],
    pub(super) extra: &'a [[f64; D]],
    pub(super) f_contact: &'a [[f64; 3]],
    pub(super) bc_kind: &'a [[u8; D]],
    pub(super) bc_value: &'a [[f64; D]],
    pub(super) has_contact: bool,
    pub(super) alpha: f64,
    pub(super) beta: f64,
    pub(super) dt: f64,
    pub(super) dt_n: f64,
    pub(super) first: bool,
    /// Load history factor at t^n.
    pub(super) load_factor: f64,
    /// Boundary-condition history factor at t^{n+1}.
    pub(super) bc_factor_next: f64,
}

/// One chunk's state, from node `n0` on.
pub(super) struct Chunk<'a, const D: usize> {
    pub(super) n0: usize,
    pub(super) v: &'a mut [[f64; D]],
    pub(super) u: &'a mut [[f64; D]],
    pub(super) du_prev: &'a mut [[f64; D]],
    pub(super) f_total_prev: &'a mut [[f64; D]],
    pub(super) f_damp: &'a [[f64; D]],
    pub(super) f_damp_prev: &'a mut [[f64; D]],
    pub(super) f_ext: &'a mut [[f64; D]],
}

impl<const D: usize> NodePass<'_, D> {
    /// Update one chunk; returns its sums of the kinetic energy, the external-work and
    /// damping-work increments and the internal energy, J. `DAMPED`: α > 0 or β > 0 (the
    /// damping force βK v^{n−½} is in `f_damp` when β > 0).
    #[inline(always)]
    pub(super) fn chunk<const DAMPED: bool>(&self, c: Chunk<'_, D>) -> [f64; 4] {
        let (alpha, beta, dt, dt_n) = (self.alpha, self.beta, self.dt, self.dt_n);
        let mut acc = [0.0f64; 4];
        for k in 0..c.v.len() {
            let i = c.n0 + k;
            for d in 0..D {
                let m = if d < 3 { self.mass[i] } else { self.rotary[i] };
                let v_old = c.v[k][d];
                let damp = if DAMPED {
                    // βK v^{n−½} is in f_damp when β > 0; add αM v^{n−½}.
                    let stiff = if beta > 0.0 { c.f_damp[k][d] } else { 0.0 };
                    stiff + alpha * m * v_old
                } else {
                    0.0
                };
                let f_ext = if self.has_contact && d < 3 {
                    self.loads[i][d] * self.load_factor + self.extra[i][d] + self.f_contact[i][d]
                } else {
                    self.loads[i][d] * self.load_factor + self.extra[i][d]
                };
                c.f_ext[k][d] = f_ext;
                let resid = f_ext - self.f_int[i][d] - damp;
                let u_old = c.u[k][d];
                let (v_new, f_total) = match self.bc_kind[i][d] {
                    FREE => (v_old + dt_n * resid / m, f_ext + 0.0),
                    HELD => {
                        // Held where it is: the total external force on the dof is
                        // M a + f_int + d.
                        let a = -v_old / dt_n;
                        (0.0, m * a + self.f_int[i][d] + damp)
                    }
                    kind => {
                        let vn = if kind == DISPLACEMENT {
                            (self.bc_value[i][d] * self.bc_factor_next - u_old) / dt
                        } else {
                            self.bc_value[i][d]
                        };
                        let a = (vn - v_old) / dt_n;
                        (vn, f_ext + (m * a - resid))
                    }
                };
                let v_prev = if self.first {
                    2.0 * v_old - v_new
                } else {
                    v_old
                };
                acc[0] += 0.5 * m * v_prev * v_new;
                acc[1] += 0.5 * c.du_prev[k][d] * (c.f_total_prev[k][d] + f_total);
                if DAMPED {
                    acc[2] += 0.5 * c.du_prev[k][d] * (c.f_damp_prev[k][d] + damp);
                    c.f_damp_prev[k][d] = damp;
                }
                acc[3] += 0.5 * u_old * self.f_int[i][d];
                c.v[k][d] = v_new;
                c.f_total_prev[k][d] = f_total;
                let du = dt * v_new;
                c.u[k][d] = u_old + du;
                c.du_prev[k][d] = du;
            }
        }
        acc
    }
}
