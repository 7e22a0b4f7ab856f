//! Explicit impact: a bar in uniaxial strain (lateral displacements held) whose end is
//! driven at constant velocity v0 carries a compressive step wave of stress
//! σ_zz = −ρ c_d v0 travelling at the dilatational speed c_d = √((λ+2μ)/ρ)
//! (one-dimensional wave theory), and the work done splits equally into kinetic and
//! strain energy.

use demfem::fem::mesh::box_tet_mesh;
use demfem::fem::stress::element_stresses;
use demfem::fem::{
    ExplicitConfig, ExplicitSolver, LinearElastic, LoadHistory, Prescribed, PrescribedKind,
};

#[test]
fn constant_velocity_impact_on_a_bar_in_uniaxial_strain() {
    let m = LinearElastic::paper_glass();
    let (a, l) = (1e-3, 20e-3);
    let mesh = box_tet_mesh(a, a, l, 2, 2, 80).unwrap();
    let v0 = 0.18; // the paper's maximum impact speed, m/s
    let mut pres = Vec::new();
    for (i, x) in mesh.nodes.iter().enumerate() {
        for c in 0..2 {
            pres.push(Prescribed {
                node: i,
                component: c,
                kind: PrescribedKind::Displacement(0.0),
            });
        }
        if x[2] < 1e-12 {
            pres.push(Prescribed {
                node: i,
                component: 2,
                kind: PrescribedKind::Velocity(v0),
            });
        }
    }
    let mut s = ExplicitSolver::new(&mesh, ExplicitConfig::new(m)).unwrap();
    s.set_prescribed(&pres, LoadHistory::Constant).unwrap();
    let cd = m.dilatational_wave_speed();
    let t_end = 0.5 * l / cd; // front at mid-length, no reflection yet
    let n = (t_end / s.dt()).round() as u64;
    s.run(n).unwrap();
    let es = element_stresses(&mesh, &m, s.displacement()).unwrap();
    // Mean σ_zz over the elements well behind the front (z in [0.1 L, 0.35 L]) and ahead
    // of it (z > 0.65 L).
    let (mut behind, mut nb, mut ahead, mut na) = (0.0, 0, 0.0f64, 0);
    for (t, se) in mesh.tets.iter().zip(&es) {
        let zc = t.iter().map(|&i| mesh.nodes[i][2]).sum::<f64>() / 4.0;
        if zc > 0.1 * l && zc < 0.35 * l {
            behind += se[2];
            nb += 1;
        } else if zc > 0.65 * l {
            ahead = ahead.max(se[2].abs());
            na += 1;
        }
    }
    behind /= nb as f64;
    let exact = -m.density * cd * v0;
    let e = s.energy();
    println!(
        "impact: {n} steps, σzz behind front {behind:.4e} Pa vs −ρ c_d v0 = {exact:.4e} (rel {:.2e}); max |σzz| ahead {ahead:.2e}; E_kin/E_int = {:.4}",
        (behind - exact).abs() / exact.abs(), e.kinetic / e.internal
    );
    // Plateau within 2 % (central differences at 0.9 × critical step give a sharp front
    // with a few per cent of Gibbs ringing, averaged out over the plateau).
    assert!((behind - exact).abs() < 0.02 * exact.abs());
    // Nothing ahead of the front beyond the numerical precursor (< 1 % of the plateau).
    assert!(na > 0 && ahead < 0.01 * exact.abs(), "precursor {ahead:e}");
    // Equipartition of the work done by the driven end: E_kin = E_int (3 %), and the
    // discrete energy balance holds to round-off.
    assert!((e.kinetic / e.internal - 1.0).abs() < 0.03);
    assert!(e.relative_balance_error() < 1e-9);
}
