//! Stress invariants against closed forms, refusal of unstable steps, and mass scaling.

use demfem::fem::stable_step::StepBound;
use demfem::fem::stress::{max_principal_stress, principal_stresses, von_mises};
use demfem::fem::{AxisymmetricProfile, ExplicitConfig, ExplicitSolver, LinearElastic};
use demfem::DemfemError;

#[test]
fn principal_and_von_mises_closed_forms() {
    // Uniaxial σ: σ1 = σ, von Mises = |σ|.
    let s = [100.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    assert!((max_principal_stress(&s) - 100.0).abs() < 1e-12);
    assert!((von_mises(&s) - 100.0).abs() < 1e-12);
    // Pure shear τ_xy: principal ±τ, von Mises √3 τ.
    let s = [0.0, 0.0, 0.0, 0.0, 0.0, 50.0];
    let p = principal_stresses(&s);
    assert!((p[0] - 50.0).abs() < 1e-10 && p[1].abs() < 1e-10 && (p[2] + 50.0).abs() < 1e-10);
    assert!((von_mises(&s) - 3f64.sqrt() * 50.0).abs() < 1e-10);
    // A rotated diagonal tensor R diag(3, 1, -2) Rᵀ (rotation 30° about z, then 45° about x):
    // eigenvalues are invariant.
    let (c1, s1) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let (c2, s2) = (45f64.to_radians().cos(), 45f64.to_radians().sin());
    let rz = [[c1, -s1, 0.0], [s1, c1, 0.0], [0.0, 0.0, 1.0]];
    let rx = [[1.0, 0.0, 0.0], [0.0, c2, -s2], [0.0, s2, c2]];
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            for k in 0..3 {
                r[i][j] += rx[i][k] * rz[k][j];
            }
        }
    }
    let d = [3.0, 1.0, -2.0];
    let mut a = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            for k in 0..3 {
                a[i][j] += r[i][k] * d[k] * r[j][k];
            }
        }
    }
    let p = principal_stresses(&[a[0][0], a[1][1], a[2][2], a[1][2], a[0][2], a[0][1]]);
    for (x, y) in p.iter().zip(d) {
        assert!((x - y).abs() < 1e-12, "{p:?}");
    }
}

#[test]
fn user_step_above_limit_is_refused_and_mass_scaling_is_reported() {
    let m = LinearElastic::paper_glass();
    let mesh = AxisymmetricProfile::tube(4.7e-3, 5.8e-3, 4e-3)
        .unwrap()
        .tet_mesh(24, 2, 0.5e-3)
        .unwrap()
        .mesh;
    let mut cfg = ExplicitConfig::new(m);
    cfg.step_bound = StepBound::ElementEigenvalue;
    let base = ExplicitSolver::new(&mesh, cfg).unwrap();
    let limit = base.dt_limit();
    cfg.dt = Some(1.01 * limit);
    match ExplicitSolver::new(&mesh, cfg) {
        Err(DemfemError::UnstableTimeStep { dt, limit: l, .. }) => assert!(dt > l),
        other => panic!("expected UnstableTimeStep, got {other:?}"),
    }
    cfg.dt = Some(-1.0);
    assert!(matches!(
        ExplicitSolver::new(&mesh, cfg),
        Err(DemfemError::InvalidParameter { .. })
    ));
    // Damping lowers the limit: (2/ω)(√(1+ξ²) − ξ).
    cfg.dt = None;
    cfg.rayleigh_beta = 0.2 * limit;
    let damped = ExplicitSolver::new(&mesh, cfg).unwrap();
    let w = 2.0 / limit;
    let xi = 0.2 * limit * w / 2.0;
    let expected = 2.0 / w * ((1.0 + xi * xi).sqrt() - xi);
    assert!((damped.dt_limit() - expected).abs() < 1e-12 * expected);
    // Mass scaling to twice the limit: the new limit reaches the target, the added mass
    // is reported and every node got at least its unscaled mass.
    cfg.rayleigh_beta = 0.0;
    cfg.mass_scaling_dt = Some(2.0 * limit);
    let scaled = ExplicitSolver::new(&mesh, cfg).unwrap();
    assert!(scaled.dt_limit() >= 2.0 * limit * (1.0 - 1e-9));
    let m0: f64 = base.mass().iter().sum();
    let m1: f64 = scaled.mass().iter().sum();
    assert!((m1 - m0 - scaled.added_mass()).abs() < 1e-9 * m1);
    assert!(scaled.added_mass() > 0.0);
    println!(
        "mass scaling to 2×dt: added {:.1} % of {:.3e} kg",
        100.0 * scaled.added_mass() / m0,
        m0
    );
}
