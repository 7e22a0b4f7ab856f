//! Critical time step: the element eigenvalue bound against exact results.

use demfem::fem::mesh::{AxisymmetricProfile, TetMesh};
use demfem::fem::stable_step::element_eigenvalue_bound;
use demfem::fem::stable_step::global_max_eigenvalue;
use demfem::fem::tet_forces::TetForceKernel;
use demfem::fem::{ExplicitConfig, ExplicitSolver, LinearElastic};
use demfem::DemfemError;
use nalgebra::{DMatrix, SymmetricEigen};

fn glass() -> LinearElastic {
    LinearElastic::new(45e9, 0.2, 2230.0).unwrap()
}

/// Regular tetrahedron of edge `a` centred at the origin, positively oriented.
fn regular_tet(a: f64) -> TetMesh {
    let s = a / (2.0 * 2f64.sqrt());
    let nodes = vec![[s, s, s], [s, -s, -s], [-s, s, -s], [-s, -s, s]];
    let mut t = [0, 1, 2, 3];
    if demfem::fem::mesh::signed_volume(nodes[0], nodes[1], nodes[2], nodes[3]) < 0.0 {
        t.swap(2, 3);
    }
    TetMesh {
        nodes,
        tets: vec![t],
    }
}

/// For a regular tet with lumped mass ρV/4 per node, the strain modes u_a = ε x_a are
/// M-orthogonal to the rigid modes and M⁻¹K maps ε → 8 C:ε/(ρa²) (because ∇N_a = 2x_a/a²
/// and Σ x_a x_aᵀ = a²/2 I). The largest eigenvalue is the dilatation, ε = I:
/// λ_max = 8(3λ+2μ)/(ρa²), so dt_crit = 2/√λ_max = a √(ρ / (2(3λ+2μ))).
#[test]
fn regular_tet_critical_step_matches_closed_form() {
    let m = glass();
    let (l, mu) = m.lame();
    for a in [1e-3, 0.37e-3, 2.5] {
        let mesh = regular_tet(a);
        let exact = a * (m.density / (2.0 * (3.0 * l + 2.0 * mu))).sqrt();
        let solver = ExplicitSolver::new(&mesh, ExplicitConfig::new(m)).unwrap();
        let rel = (solver.dt_limit() - exact).abs() / exact;
        // Only round-off separates the 12×12 symmetric eigen-solve from the closed form.
        assert!(
            rel < 1e-10,
            "a = {a}: dt_limit {} vs exact {exact}, rel {rel:e}",
            solver.dt_limit()
        );
        // The bound is exact for a single element: the dilatation mode grows just above it.
        for (factor, should_grow) in [(0.999, false), (1.001, true)] {
            let mut cfg = ExplicitConfig::new(m);
            cfg.dt = Some(factor * exact);
            if should_grow {
                // A step above the bound is refused; bypass the check by a tiny mass bump
                // is not possible, so run the recurrence on a step just below it and compare.
                assert!(matches!(
                    ExplicitSolver::new(&mesh, cfg),
                    Err(DemfemError::UnstableTimeStep { .. })
                ));
                continue;
            }
            let mut s = ExplicitSolver::new(&mesh, cfg).unwrap();
            let u0: Vec<[f64; 3]> = mesh
                .nodes
                .iter()
                .map(|x| [1e-6 * x[0], 1e-6 * x[1], 1e-6 * x[2]])
                .collect();
            s.set_initial_displacement(&u0).unwrap();
            s.run(2000).unwrap();
            let umax = s
                .displacement()
                .iter()
                .flatten()
                .fold(0.0f64, |acc, v| acc.max(v.abs()));
            let u0max = u0.iter().flatten().fold(0.0f64, |acc, v| acc.max(v.abs()));
            // Stable: amplitude bounded by 1/√(1−(ωdt/2)²) ≈ 22 at factor 0.999.
            assert!(
                umax < 30.0 * u0max,
                "dt = 0.999 dt_crit should stay bounded: {umax} vs {u0max}"
            );
        }
    }
}

/// Both bounds are below the true critical step; the certified global bound (the solver's
/// default) is within 10 % of it (within its 1 % margin, in fact) while the plain element
/// bound is ~20 % below. The true step comes from a dense eigen-solve of M^{-½}KM^{-½}
/// on a small tube mesh (cartridge wall, 2 layers).
#[test]
fn element_bound_is_safe_and_within_ten_percent_of_global() {
    let m = glass();
    let (l, mu) = m.lame();
    let prof = AxisymmetricProfile::tube(4.7e-3, 5.8e-3, 3e-3).unwrap();
    let rm = prof.tet_mesh(24, 2, 0.6e-3).unwrap();
    let mesh = rm.mesh;
    let mut kernel = TetForceKernel::new(&mesh, l, mu).unwrap();
    let mass = demfem::fem::assembly::lumped_mass(&mesh, kernel.tets(), m.density, None).unwrap();
    let (lam_e, _) = element_eigenvalue_bound(kernel.tets(), l, mu, m.density, None);
    // Dense global matrix from unit vectors through the element kernel.
    let n = mesh.nodes.len();
    let nd = 3 * n;
    let mut a = DMatrix::<f64>::zeros(nd, nd);
    let mut e = vec![[0.0; 3]; n];
    let mut y = vec![[0.0; 3]; n];
    for j in 0..nd {
        e[j / 3][j % 3] = 1.0 / mass[j / 3].sqrt();
        kernel.apply(&e, &mut y);
        e[j / 3][j % 3] = 0.0;
        for i in 0..nd {
            a[(i, j)] = y[i / 3][i % 3] / mass[i / 3].sqrt();
        }
    }
    let a = 0.5 * (&a + a.transpose());
    let lam_g = SymmetricEigen::new(a)
        .eigenvalues
        .iter()
        .cloned()
        .fold(0.0f64, f64::max);
    let lam_p = global_max_eigenvalue(&mut kernel, &mass, 3000).unwrap();
    let dt_e = 2.0 / lam_e.sqrt();
    let dt_g = 2.0 / lam_g.sqrt();
    println!("nodes {n}, dt_element {dt_e:e}, dt_true {dt_g:e}, ratio {:.4}, power-iteration λ/λ_true {:.5}", dt_e / dt_g, lam_p / lam_g);
    assert!(
        dt_e <= dt_g * (1.0 + 1e-12),
        "element bound must not exceed the true critical step"
    );
    assert!(
        dt_e >= 0.7 * dt_g,
        "element bound {dt_e:e} unexpectedly loose vs {dt_g:e}"
    );
    let solver = ExplicitSolver::new(&mesh, ExplicitConfig::new(m)).unwrap();
    let dt_c = solver.dt_limit();
    println!(
        "certified dt {dt_c:e}, ratio to true {:.4}, factorisations {}",
        dt_c / dt_g,
        solver.eigenvalue_bound().factorizations
    );
    assert!(
        dt_c <= dt_g * (1.0 + 1e-12),
        "certified bound must not exceed the true critical step"
    );
    assert!(
        dt_c >= 0.9 * dt_g,
        "certified bound {dt_c:e} more than 10 % below the true {dt_g:e}"
    );
    // Power iteration converges to λ_max from below.
    assert!(lam_p <= lam_g * (1.0 + 1e-9) && lam_p > 0.9 * lam_g);
}
