//! Explicit FEM throughput: tet element-updates per second (element force + nodal gather,
//! and the whole central-difference step) at 1 and 2 threads, on a cartridge-size glass
//! tube (OD 11.6 mm, wall 1.1 mm, 64 mm long, 2 layers through the wall, ~73k tets).
//! Also prints the one-off set-up cost of the two critical-step bounds, and measures
//! shell (CST + DKT triangle) element-updates per second on the cartridge mid-surface.
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use demfem::fem::stable_step::StepBound;
use demfem::fem::tet_forces::TetForceKernel;
use demfem::fem::{
    AxisymmetricProfile, ExplicitConfig, ExplicitSolver, LinearElastic, LoadHistory, Prescribed,
};
use std::time::Instant;

fn bench_fem(c: &mut Criterion) {
    let rm = AxisymmetricProfile::tube(4.7e-3, 5.8e-3, 64e-3)
        .unwrap()
        .tet_mesh(52, 2, 0.55e-3)
        .unwrap();
    let mesh = rm.mesh;
    let n_el = mesh.n_elements() as u64;
    let glass = LinearElastic::paper_glass();
    let (l, mu) = glass.lame();
    println!("mesh: {} nodes, {} tets", mesh.n_nodes(), n_el);
    for bound in [
        StepBound::ElementEigenvalue,
        StepBound::CertifiedGlobal {
            margin: 0.01,
            iterations: 400,
        },
    ] {
        let mut cfg = ExplicitConfig::new(glass);
        cfg.step_bound = bound;
        let t0 = Instant::now();
        let s = ExplicitSolver::new(&mesh, cfg).unwrap();
        println!(
            "{bound:?}: set-up {:.2} s, dt_limit {:.4e} s, factorisations {}",
            t0.elapsed().as_secs_f64(),
            s.dt_limit(),
            s.eigenvalue_bound().factorizations
        );
    }
    let u: Vec<[f64; 3]> = mesh
        .nodes
        .iter()
        .map(|x| [1e-6 * x[2], -2e-6 * x[0], 3e-6 * x[1]])
        .collect();
    let mut out = vec![[0.0; 3]; mesh.n_nodes()];
    let mut kernel = TetForceKernel::new(&mesh, l, mu).unwrap();
    let mut cfg = ExplicitConfig::new(glass);
    cfg.step_bound = StepBound::ElementEigenvalue;
    cfg.energy_interval = 0;
    let mut solver = ExplicitSolver::new(&mesh, cfg).unwrap();
    let mut loads = vec![[0.0; 3]; mesh.n_nodes()];
    for (i, x) in mesh.nodes.iter().enumerate() {
        if x[2] > 64e-3 - 1e-9 {
            loads[i] = [0.0, 1.0, 0.0];
        }
    }
    solver.set_loads(loads, LoadHistory::Constant).unwrap();
    let fixed: Vec<Prescribed> = (0..mesh.n_nodes())
        .filter(|&i| mesh.nodes[i][2] < 1e-9)
        .flat_map(Prescribed::fix_node)
        .collect();
    solver
        .set_prescribed(&fixed, LoadHistory::Constant)
        .unwrap();

    let mut g = c.benchmark_group("tet_element_updates");
    g.throughput(Throughput::Elements(n_el));
    g.sample_size(30);
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        g.bench_function(format!("internal_force_{threads}t"), |b| {
            b.iter(|| pool.install(|| kernel.apply(&u, &mut out)))
        });
        g.bench_function(format!("full_step_{threads}t"), |b| {
            b.iter(|| pool.install(|| solver.step()))
        });
    }
    g.finish();

    // Shells: flat CST+DKT triangles on the cartridge mid-surface, same circumferential
    // and axial resolution.
    let shell_mesh = AxisymmetricProfile::default_cartridge()
        .shell_mesh(52, 0.55e-3)
        .unwrap();
    let n_tri = shell_mesh.triangles.len() as u64;
    let model = demfem::fem::shell::ShellModel::new(shell_mesh, glass).unwrap();
    let fixed: Vec<(usize, usize)> = (0..model.mesh.nodes.len())
        .filter(|&i| model.mesh.nodes[i][2] < 1e-9)
        .flat_map(|i| (0..6).map(move |k| (i, k)))
        .collect();
    let mut shell = demfem::fem::ShellExplicit::new(&model, &fixed, None).unwrap();
    let f: Vec<[f64; 6]> = model
        .mesh
        .nodes
        .iter()
        .map(|x| {
            [
                0.0,
                if x[2] > 64e-3 - 1e-9 { 1.0 } else { 0.0 },
                0.0,
                0.0,
                0.0,
                0.0,
            ]
        })
        .collect();
    shell
        .set_loads(f, demfem::fem::LoadHistory::Constant)
        .unwrap();
    println!(
        "shell mesh: {} nodes, {} triangles, dt_limit {:.3e} s",
        model.mesh.nodes.len(),
        n_tri,
        shell.dt_limit()
    );
    let mut g = c.benchmark_group("shell_element_updates");
    g.throughput(Throughput::Elements(n_tri));
    g.sample_size(30);
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        g.bench_function(format!("full_step_{threads}t"), |b| {
            b.iter(|| pool.install(|| shell.step()))
        });
    }
    g.finish();
}

criterion_group!(benches, bench_fem);
criterion_main!(benches);
