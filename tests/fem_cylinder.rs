//! Thick and thin cylinders against closed forms: Lamé under internal pressure (static,
//! and explicit with damping tending to it), and the breathing frequency of a thin ring.
//! All use plane strain: u_z = 0 on both end faces, which makes the finite tube an exact
//! slice of the infinite one.

use demfem::fem::assembly::surface_pressure_loads;
use demfem::fem::mesh::{AxisymmetricProfile, RevolvedTetMesh};
use demfem::fem::static_solve::solve_static;
use demfem::fem::stress::{element_stresses, nodal_stresses, stress_along_line};
use demfem::fem::{
    ExplicitConfig, ExplicitSolver, LinearElastic, LoadHistory, Prescribed, PrescribedKind,
};

const A: f64 = 4.7e-3; // inner radius, m (cartridge body)
const B: f64 = 5.8e-3; // outer radius, m
const P: f64 = 1e6; // internal pressure, Pa

/// Lamé plane strain: u_r(r) = (1+ν)/E · a²p/(b²−a²) · ((1−2ν) r + b²/r).
fn lame_ur(m: &LinearElastic, r: f64) -> f64 {
    let nu = m.poisson_ratio;
    (1.0 + nu) / m.young_modulus * A * A * P / (B * B - A * A) * ((1.0 - 2.0 * nu) * r + B * B / r)
}
/// Lamé hoop stress σ_θ(r) = a²p/(b²−a²) (1 + b²/r²).
fn lame_hoop(r: f64) -> f64 {
    A * A * P / (B * B - A * A) * (1.0 + B * B / (r * r))
}

/// Plane-strain constraints: u_z = 0 on both ends, plus u_y = 0 at θ = 0, π and u_x = 0
/// at θ = π/2 on the inner ring of z = 0 (zero in the exact solution; they remove the
/// in-plane rigid motions).
fn constraints(rm: &RevolvedTetMesh) -> Vec<(usize, usize, f64)> {
    let mut c = Vec::new();
    let nz = rm.z_stations.len();
    for k in [0, nz - 1] {
        for j in 0..=rm.n_layers {
            for i in 0..rm.n_theta {
                c.push((rm.node_index(i, j, k), 2, 0.0));
            }
        }
    }
    c.push((rm.node_index(0, 0, 0), 1, 0.0));
    c.push((rm.node_index(rm.n_theta / 2, 0, 0), 1, 0.0));
    c.push((rm.node_index(rm.n_theta / 4, 0, 0), 0, 0.0));
    c
}

fn inner_pressure(rm: &RevolvedTetMesh) -> Vec<[f64; 3]> {
    surface_pressure_loads(&rm.mesh, P, |x| {
        ((x[0] * x[0] + x[1] * x[1]).sqrt() - A).abs() < 1e-9
    })
    .unwrap()
}

fn mean_inner_ur(rm: &RevolvedTetMesh, u: &[[f64; 3]]) -> f64 {
    let mut s = 0.0;
    for i in 0..rm.n_theta {
        let n = rm.node_index(i, 0, 0);
        let x = rm.mesh.nodes[n];
        let r = (x[0] * x[0] + x[1] * x[1]).sqrt();
        s += (u[n][0] * x[0] + u[n][1] * x[1]) / r;
    }
    s / rm.n_theta as f64
}

/// Mesh: 64 divisions around, 4 layers through the 1.1 mm wall, 1 mm long (2 axial cells).
/// Tolerances: u_r at the bore within 1 % (faceting of the bore changes the load by
/// (π/64)²/6 ≈ 0.04 %, the wall discretisation error of linear tets at 4 layers is a few
/// 0.1 %); nodal-averaged hoop stress at mid-wall within 2 % (piecewise-constant element
/// stresses averaged at nodes are second-order accurate at interior nodes).
#[test]
fn lame_thick_cylinder_static() {
    let m = LinearElastic::paper_glass();
    let rm = AxisymmetricProfile::tube(A, B, 1e-3)
        .unwrap()
        .tet_mesh(64, 4, 0.5e-3)
        .unwrap();
    let sol = solve_static(&rm.mesh, &m, &inner_pressure(&rm), &constraints(&rm)).unwrap();
    let ur = mean_inner_ur(&rm, &sol.displacement);
    let ur_exact = lame_ur(&m, A);
    let err_u = (ur - ur_exact).abs() / ur_exact;
    // Outer surface too.
    let mut ur_out = 0.0;
    for i in 0..rm.n_theta {
        let n = rm.node_index(i, rm.n_layers, 0);
        let x = rm.mesh.nodes[n];
        ur_out +=
            (sol.displacement[n][0] * x[0] + sol.displacement[n][1] * x[1]) / B / rm.n_theta as f64;
    }
    let err_uo = (ur_out - lame_ur(&m, B)).abs() / lame_ur(&m, B);
    let es = element_stresses(&rm.mesh, &m, &sol.displacement).unwrap();
    let ns = nodal_stresses(&rm.mesh, &es).unwrap();
    // Line through the wall along +x at mid-length: σ_yy is the hoop stress there.
    let line = stress_along_line(&rm.mesh, &ns, [A, 0.0, 0.5e-3], [B, 0.0, 0.5e-3], 9).unwrap();
    assert_eq!(line.len(), 9, "all points through the wall lie in the mesh");
    let mid = line[4];
    let r_mid = 0.5 * (A + B);
    let err_s = (mid.stress[1] - lame_hoop(r_mid)).abs() / lame_hoop(r_mid);
    println!("Lamé static: u_r(a) rel err {err_u:.2e}, u_r(b) rel err {err_uo:.2e}, σθ(mid) rel err {err_s:.2e}");
    for s in &line {
        println!(
            "  r = {:.4} mm  σθ = {:.4e}  exact {:.4e}",
            (A + s.distance) * 1e3,
            s.stress[1],
            lame_hoop(A + s.distance)
        );
    }
    assert!(
        err_u < 0.01 && err_uo < 0.01,
        "radial displacement off: {err_u:e}, {err_uo:e}"
    );
    assert!(err_s < 0.02, "hoop stress at mid-wall off: {err_s:e}");
}

/// Explicit dynamics under a suddenly applied pressure with mass-proportional damping
/// (ζ ≈ 0.5 of the breathing mode) tends to the static Lamé solution and to the static
/// solve on the same mesh; the energy balance holds throughout.
#[test]
fn lame_explicit_tends_to_static() {
    let m = LinearElastic::paper_glass();
    let rm = AxisymmetricProfile::tube(A, B, 1e-3)
        .unwrap()
        .tet_mesh(32, 2, 0.5e-3)
        .unwrap();
    let cons = constraints(&rm);
    let loads = inner_pressure(&rm);
    let stat = solve_static(&rm.mesh, &m, &loads, &cons).unwrap();
    let r = 0.5 * (A + B);
    let omega = (m.young_modulus / (m.density * (1.0 - m.poisson_ratio.powi(2)))).sqrt() / r;
    let mut cfg = ExplicitConfig::new(m);
    cfg.rayleigh_alpha = omega; // ζ = α/(2ω) = 0.5
    cfg.energy_interval = 1;
    let mut s = ExplicitSolver::new(&rm.mesh, cfg).unwrap();
    let pres: Vec<Prescribed> = cons
        .iter()
        .map(|&(node, component, _)| Prescribed {
            node,
            component,
            kind: PrescribedKind::Displacement(0.0),
        })
        .collect();
    s.set_prescribed(&pres, LoadHistory::Constant).unwrap();
    s.set_loads(loads, LoadHistory::Constant).unwrap();
    // Decay e^{-αt/2} to < 1e-5 needs t > 23/ω.
    let t_end = 25.0 / omega;
    let n = (t_end / s.dt()).ceil() as u64;
    let mut peak: f64 = 0.0;
    for _ in 0..n {
        s.step();
        peak = peak.max(mean_inner_ur(&rm, s.displacement()));
        s.check_energy_balance(1e-9).unwrap(); // exact identity: round-off only
    }
    let ur = mean_inner_ur(&rm, s.displacement());
    let ur_static = mean_inner_ur(&rm, &stat.displacement);
    let e = s.energy();
    println!(
        "explicit Lamé: {n} steps, dt {:.3e}, peak/static {:.3}, final/static {:.6}, vs closed form {:.4}, energy rel err {:.2e}, damping work {:.3e} J",
        s.dt(), peak / ur_static, ur / ur_static, ur / lame_ur(&m, A), e.relative_balance_error(), e.damping_work
    );
    // Overshoot of a damped (ζ = 0.5) step response: 1 + e^{−πζ/√(1−ζ²)} = 1.163.
    assert!(
        (peak / ur_static - 1.163).abs() < 0.03,
        "overshoot {}",
        peak / ur_static
    );
    assert!(
        (ur / ur_static - 1.0).abs() < 1e-4,
        "does not tend to the static solve"
    );
    assert!(
        (ur / lame_ur(&m, A) - 1.0).abs() < 0.02,
        "does not tend to Lamé"
    );
}

/// Breathing (n = 0) mode of a thin ring in plane strain: ω² = E / (ρ (1 − ν²) R²)
/// (mid-surface radius R; thickness correction O(h²/R²) = 2.5e-3 relative here, faceting
/// with 64 sides O((π/64)²) ≈ 2.4e-3). Tolerance 1 % on the frequency. The undamped run
/// also checks the discrete energy balance (exact up to round-off).
#[test]
fn thin_ring_breathing_frequency() {
    let m = LinearElastic::paper_glass();
    let (ri, ro) = (9.75e-3, 10.25e-3);
    let rm = AxisymmetricProfile::tube(ri, ro, 0.5e-3)
        .unwrap()
        .tet_mesh(64, 2, 0.5e-3)
        .unwrap();
    let r = 0.5 * (ri + ro);
    let omega = (m.young_modulus / (m.density * (1.0 - m.poisson_ratio.powi(2)))).sqrt() / r;
    let mut s = ExplicitSolver::new(&rm.mesh, ExplicitConfig::new(m)).unwrap();
    let mut pres = Vec::new();
    for node in 0..rm.mesh.nodes.len() {
        pres.push(Prescribed {
            node,
            component: 2,
            kind: PrescribedKind::Displacement(0.0),
        });
    }
    s.set_prescribed(&pres, LoadHistory::Constant).unwrap();
    let v0: Vec<[f64; 3]> = rm
        .mesh
        .nodes
        .iter()
        .map(|x| {
            let rr = (x[0] * x[0] + x[1] * x[1]).sqrt();
            [0.01 * x[0] / rr, 0.01 * x[1] / rr, 0.0]
        })
        .collect();
    s.set_initial_velocity(&v0).unwrap();
    let mean_ur = |u: &[[f64; 3]]| {
        let mut acc = 0.0;
        for (x, ui) in rm.mesh.nodes.iter().zip(u) {
            acc += (ui[0] * x[0] + ui[1] * x[1]) / (x[0] * x[0] + x[1] * x[1]).sqrt();
        }
        acc / u.len() as f64
    };
    let period = 2.0 * std::f64::consts::PI / omega;
    let n = (4.2 * period / s.dt()).ceil() as u64;
    let mut crossings = Vec::new();
    let mut prev = 0.0;
    for _ in 0..n {
        let t0 = s.time();
        s.step();
        let cur = mean_ur(s.displacement());
        if s.steps() > 2 && prev * cur < 0.0 {
            crossings.push(t0 + s.dt() * prev / (prev - cur));
        }
        prev = cur;
        s.check_energy_balance(1e-9).unwrap(); // exact identity: round-off only
    }
    assert!(
        crossings.len() >= 6,
        "too few zero crossings: {}",
        crossings.len()
    );
    let measured =
        2.0 * (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    let err = (measured - period).abs() / period;
    println!(
        "breathing period measured {measured:.5e} s, closed form {period:.5e} s, rel err {err:.2e}"
    );
    assert!(err < 0.01, "breathing period off by {err:e}");
}
