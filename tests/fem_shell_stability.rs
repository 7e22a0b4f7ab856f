//! Stability of the explicit thin shell under a point impact: a clamped glass plate, 40
//! times thinner than wide, gets a point force switched on at its centre at t = 0 and runs
//! 100 000 steps at 0.99 of the certified stable step. Closed form: for a step load on an
//! undamped linear system the centre's deflection under a centre load is Σ aᵢ (1 − cos ωᵢt)
//! with every aᵢ ≥ 0, so it stays within [0, 2 × static]. Checked: no NaN, the energy
//! balance closes, the deflection respects that bound (and reaches well above the static
//! value, so the run is dynamic), and a step above the limit is refused.
mod common;

use common::grid;
use demfem::error::DemfemError;
use demfem::fem::explicit::dof_rows;
use demfem::fem::mesh::TriMesh;
use demfem::fem::shell::ShellModel;
use demfem::fem::LinearElastic;
use demfem::fem::{LoadHistory, ShellExplicit};

fn plate(n: usize, side: f64, h: f64) -> TriMesh {
    grid(n, n, h, |s, t| [side * s, side * t, 0.0])
}

#[test]
fn thin_plate_under_a_sudden_point_load_at_0_99_of_the_stable_step() {
    let (n, side, h, load) = (16, 0.02, 0.5e-3, 10.0);
    let glass = LinearElastic::new(73e9, 0.2, 2230.0).unwrap();
    let model = ShellModel::new(plate(n, side, h), glass).unwrap();
    let nn = model.mesh.nodes.len();
    let edge = |i: usize| {
        let (a, b) = (i % (n + 1), i / (n + 1));
        a == 0 || b == 0 || a == n || b == n
    };
    let fixed: Vec<(usize, usize)> = (0..nn)
        .filter(|&i| edge(i))
        .flat_map(|i| (0..6).map(move |k| (i, k)))
        .collect();
    let fixed_vals: Vec<(usize, usize, f64)> = fixed.iter().map(|&(i, k)| (i, k, 0.0)).collect();
    let centre = (n / 2) * (n + 1) + n / 2;
    let mut f = vec![0.0; model.n_dofs()];
    f[6 * centre + 2] = -load;
    let w_static = -model.solve_static(&f, &fixed_vals).unwrap()[6 * centre + 2];
    assert!(w_static > 0.0);

    let probe = ShellExplicit::new(&model, &fixed, None).unwrap();
    let limit = probe.dt_limit();
    match ShellExplicit::new(&model, &fixed, Some(1.01 * limit)) {
        Err(DemfemError::UnstableTimeStep { .. }) => {}
        other => panic!("a step above the limit must be refused, got {other:?}"),
    }
    let mut s = ShellExplicit::new(&model, &fixed, Some(0.99 * limit)).unwrap();
    s.set_loads(dof_rows(&f).unwrap(), LoadHistory::Constant)
        .unwrap();
    let (mut w_min, mut w_max, mut worst_balance) = (f64::INFINITY, 0.0f64, 0.0f64);
    for _ in 0..1000 {
        s.run(100).unwrap();
        let w = -s.displacement()[centre][2];
        w_min = w_min.min(w);
        w_max = w_max.max(w);
        worst_balance = worst_balance.max(s.energy().relative_balance_error());
    }
    assert!(s.displacement().iter().flatten().all(|x| x.is_finite()));
    println!(
        "thin plate, point step load: dt {:.3e} s (0.99 x {:.3e}), w_static {w_static:.4e} m, \
         w in [{:.3e}, {:.3e}] x static, energy balance {worst_balance:.1e}",
        s.dt(),
        limit,
        w_min / w_static,
        w_max / w_static
    );
    assert!(worst_balance < 1e-3, "energy balance {worst_balance}");
    assert!(
        w_max <= 2.0 * w_static * 1.02,
        "overshoot {}",
        w_max / w_static
    );
    assert!(w_max > 1.5 * w_static, "not dynamic: {}", w_max / w_static);
    assert!(
        w_min >= -0.02 * w_static,
        "rebound past zero: {}",
        w_min / w_static
    );
}
