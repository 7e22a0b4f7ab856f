//! Quasi-static pinch of the default cartridge: two opposite radial forces of 100 N at
//! mid-body (z = 27 mm), each spread uniformly over the outer-surface nodes within 1 mm of
//! the contact point (a stand-in for the Hertz patch). Peak maximum principal stress σ1
//! and wall time against mesh density: tets with 1–4 layers through the wall, and the
//! CST+DKT shell. Run: `cargo run --release --example fem_pinch_study`.
use demfem::fem::shell::ShellModel;
use demfem::fem::static_solve::solve_static;
use demfem::fem::stress::{element_stresses, max_principal_stress};
use demfem::fem::{AxisymmetricProfile, LinearElastic};
use std::time::Instant;

const F: f64 = 100.0;
const Z0: f64 = 27e-3;
const PATCH: f64 = 1e-3;

fn main() -> demfem::Result<()> {
    let p = AxisymmetricProfile::default_cartridge();
    let glass = LinearElastic::paper_glass();
    println!("model        n_theta  layers  elements   dofs    σ1_peak(MPa)  wall(s)");
    for (n_theta, layers, h) in [
        (48, 1, 0.6e-3),
        (64, 2, 0.5e-3),
        (64, 3, 0.5e-3),
        (64, 4, 0.5e-3),
        (96, 4, 0.35e-3),
    ] {
        let t0 = Instant::now();
        let rm = p.tet_mesh(n_theta, layers, h)?;
        let m = &rm.mesh;
        let r_out = 5.8e-3;
        let mut loads = vec![[0.0; 3]; m.n_nodes()];
        for sign in [1.0, -1.0] {
            let c = [sign * r_out, 0.0, Z0];
            let sel: Vec<usize> = (0..m.n_nodes())
                .filter(|&i| {
                    let x = m.nodes[i];
                    let r = (x[0] * x[0] + x[1] * x[1]).sqrt();
                    (r - r_out).abs() < 1e-9
                        && ((x[0] - c[0]).powi(2) + x[1].powi(2) + (x[2] - c[2]).powi(2)).sqrt()
                            < PATCH
                })
                .collect();
            for &i in &sel {
                loads[i][0] -= sign * F / sel.len() as f64;
            }
        }
        // 3-2-1 supports at the open bottom end (the load is self-equilibrated).
        let a = rm.node_index(0, 0, 0);
        let b = rm.node_index(n_theta / 2, 0, 0);
        let c = rm.node_index(n_theta / 4, 0, 0);
        let fixed = [
            (a, 0, 0.0),
            (a, 1, 0.0),
            (a, 2, 0.0),
            (b, 1, 0.0),
            (b, 2, 0.0),
            (c, 2, 0.0),
        ];
        let sol = solve_static(m, &glass, &loads, &fixed)?;
        let s1 = element_stresses(m, &glass, &sol.displacement)?
            .iter()
            .map(max_principal_stress)
            .fold(f64::MIN, f64::max);
        println!(
            "tet          {n_theta:7} {layers:7} {:9} {:7} {:13.2} {:8.2}",
            m.n_elements(),
            3 * m.n_nodes(),
            s1 / 1e6,
            t0.elapsed().as_secs_f64()
        );
    }
    for (n_theta, h) in [(48, 0.6e-3), (64, 0.5e-3), (96, 0.35e-3), (128, 0.25e-3)] {
        let t0 = Instant::now();
        let mesh = p.shell_mesh(n_theta, h)?;
        let model = ShellModel::new(mesh, glass)?;
        let m = &model.mesh;
        let r_mid = 0.5 * (4.7e-3 + 5.8e-3);
        let mut f = vec![0.0; model.n_dofs()];
        for sign in [1.0, -1.0] {
            let sel: Vec<usize> = (0..m.nodes.len())
                .filter(|&i| {
                    let x = m.nodes[i];
                    ((x[0] - sign * r_mid).powi(2) + x[1].powi(2) + (x[2] - Z0).powi(2)).sqrt()
                        < PATCH
                })
                .collect();
            for &i in &sel {
                f[6 * i] -= sign * F / sel.len() as f64;
            }
        }
        let idx = |i: usize| i; // station 0 ring: node i = θ index i
        let fixed = [
            (idx(0), 0, 0.0),
            (idx(0), 1, 0.0),
            (idx(0), 2, 0.0),
            (idx(n_theta / 2), 1, 0.0),
            (idx(n_theta / 2), 2, 0.0),
            (idx(n_theta / 4), 2, 0.0),
        ];
        let x = model.solve_static(&f, &fixed)?;
        let s1 = model
            .max_principal_stresses(&x)?
            .iter()
            .flat_map(|s| s.iter().cloned())
            .fold(f64::MIN, f64::max);
        println!(
            "shell        {n_theta:7}       - {:9} {:7} {:13.2} {:8.2}",
            m.triangles.len(),
            model.n_dofs(),
            s1 / 1e6,
            t0.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
