//! Critical-step bounds on the default cartridge (52 divisions around, 0.55 mm axial
//! target, 1–4 layers through the wall): element eigenvalue bound vs certified global
//! bound (power iteration + Cholesky certificate of σM − K), with set-up times.
//! Run: `cargo run --release --example fem_step_bound`.
use demfem::fem::stable_step::StepBound;
use demfem::fem::{AxisymmetricProfile, ExplicitConfig, ExplicitSolver, LinearElastic};
use std::time::Instant;

fn main() -> demfem::Result<()> {
    let p = AxisymmetricProfile::default_cartridge();
    println!("layers   tets   dt_element(s)  setup(s)  dt_certified(s)  setup(s)  ratio");
    for layers in 1..=4 {
        let mesh = p.tet_mesh(52, layers, 0.55e-3)?.mesh;
        let mut res = Vec::new();
        for bound in [
            StepBound::ElementEigenvalue,
            StepBound::CertifiedGlobal {
                margin: 0.01,
                iterations: 400,
            },
        ] {
            let mut cfg = ExplicitConfig::new(LinearElastic::paper_glass());
            cfg.step_bound = bound;
            let t0 = Instant::now();
            let s = ExplicitSolver::new(&mesh, cfg)?;
            res.push((s.dt_limit(), t0.elapsed().as_secs_f64()));
        }
        println!(
            "{layers:6} {:7} {:14.4e} {:9.2} {:16.4e} {:9.2} {:6.3}",
            mesh.n_elements(),
            res[0].0,
            res[0].1,
            res[1].0,
            res[1].1,
            res[1].0 / res[0].0
        );
    }
    Ok(())
}
