//! The contact's tangential law: an elastic stick spring of the normal stiffness with a
//! Coulomb cap, and the work it dissipates (see the module documentation of
//! [`super`]).

use super::vec3::{add, dot, norm, scale, sub, tangential};

/// Normal force, tangential force (stick spring with Coulomb return), stored elastic energy
/// and dissipated work for a contact of penetration `d`, normal `n` (pointing towards the
/// node), relative velocity `vrel` of the node, velocity `surface` of a rigid surface it
/// slides on (zero against a body), stiffness `k`, friction `mu`, step `dt`.
#[allow(clippy::too_many_arguments)]
pub(super) fn friction_update(
    stick_old: [f64; 3],
    n: [f64; 3],
    vrel: [f64; 3],
    surface: [f64; 3],
    d: f64,
    k: f64,
    mu: f64,
    dt: f64,
) -> ([f64; 3], [f64; 3], f64, f64) {
    let fn_mag = k * d;
    let normal = scale(n, fn_mag);
    if mu == 0.0 {
        return (normal, [0.0; 3], 0.5 * k * d * d, 0.0);
    }
    // Keep the magnitude of the old stick force when the tangent plane turns.
    let old = tangential(stick_old, n);
    let (lo, lt) = (norm(stick_old), norm(old));
    let old = if lt > 0.0 { scale(old, lo / lt) } else { old };
    let vt = tangential(vrel, n);
    let trial = sub(old, scale(vt, k * dt));
    let t_mag = norm(trial);
    let cap = mu * fn_mag;
    let (ft, dissipated) = if t_mag > cap {
        let ft = scale(trial, cap / t_mag);
        // The work the bodies did on the stick spring this step, by the trapezoidal rule
        // the solver uses for work (mean force times the tangential travel (old − trial)/k),
        // less the change of the spring's energy: the bookkeeping closes step by step. For
        // steady sliding (old = ft) it is μ f_n times the slip. A moving rigid surface's
        // work is counted with the new force alone (`FemContact::compute`), so half the
        // change of force times its travel v_s Δt closes the step there.
        let work = 0.5 * dot(add(old, ft), sub(old, trial)) / k;
        let stored = 0.5 * (cap * cap - dot(old, old)) / k;
        let surface_term = 0.5 * dot(sub(ft, old), surface) * dt;
        (ft, -work - stored + surface_term)
    } else {
        (trial, 0.0)
    };
    let ft_mag = norm(ft);
    (
        normal,
        ft,
        0.5 * k * d * d + 0.5 * ft_mag * ft_mag / k,
        dissipated,
    )
}
