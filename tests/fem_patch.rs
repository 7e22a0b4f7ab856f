//! Patch tests: a linear displacement field (constant strain) must be reproduced exactly by
//! linear tetrahedra on a distorted mesh, in the static solve and in explicit dynamics;
//! and the explicit solver must be bitwise deterministic for 1 and 2 threads.
#![allow(clippy::needless_range_loop)]

use demfem::fem::mesh::{box_tet_mesh, TetMesh};
use demfem::fem::static_solve::solve_static;
use demfem::fem::stress::element_stresses;
use demfem::fem::{
    ExplicitConfig, ExplicitSolver, LinearElastic, LoadHistory, Prescribed, PrescribedKind,
};

const L: f64 = 2e-3;

/// Box mesh with interior nodes moved by up to 15 % of the cell size (deterministic).
fn distorted_box() -> (TetMesh, Vec<bool>) {
    let n = 4;
    let mut mesh = box_tet_mesh(L, L, L, n, n, n).unwrap();
    let h = L / n as f64;
    let mut boundary = Vec::new();
    for (i, p) in mesh.nodes.iter_mut().enumerate() {
        let on_b = p.iter().any(|&c| c.abs() < 1e-12 || (c - L).abs() < 1e-12);
        boundary.push(on_b);
        if !on_b {
            for (c, x) in p.iter_mut().enumerate() {
                let r = ((i * 7 + c * 13) as f64 * 0.618_033_988_7).fract() - 0.5;
                *x += 0.3 * h * r;
            }
        }
    }
    mesh.validate().unwrap();
    (mesh, boundary)
}

/// A general (non-symmetric) displacement gradient and a translation, m/m and m.
fn field(x: [f64; 3]) -> [f64; 3] {
    let a = [
        [1.0e-3, 2.0e-4, -3.0e-4],
        [-1.0e-4, -5.0e-4, 4.0e-4],
        [2.5e-4, 1.5e-4, 7.0e-4],
    ];
    let c = [1e-6, -2e-6, 3e-6];
    [0, 1, 2].map(|i| c[i] + a[i][0] * x[0] + a[i][1] * x[1] + a[i][2] * x[2])
}

fn exact_stress(m: &LinearElastic) -> [f64; 6] {
    let a = [
        [1.0e-3, 2.0e-4, -3.0e-4],
        [-1.0e-4, -5.0e-4, 4.0e-4],
        [2.5e-4, 1.5e-4, 7.0e-4],
    ];
    let e = [
        a[0][0],
        a[1][1],
        a[2][2],
        0.5 * (a[1][2] + a[2][1]),
        0.5 * (a[0][2] + a[2][0]),
        0.5 * (a[0][1] + a[1][0]),
    ];
    let (l, mu) = m.lame();
    let tr = e[0] + e[1] + e[2];
    [
        l * tr + 2.0 * mu * e[0],
        l * tr + 2.0 * mu * e[1],
        l * tr + 2.0 * mu * e[2],
        2.0 * mu * e[3],
        2.0 * mu * e[4],
        2.0 * mu * e[5],
    ]
}

#[test]
fn static_patch_test_is_exact() {
    let m = LinearElastic::paper_glass();
    let (mesh, boundary) = distorted_box();
    let mut pres = Vec::new();
    for (i, p) in mesh.nodes.iter().enumerate() {
        if boundary[i] {
            let u = field(*p);
            for c in 0..3 {
                pres.push((i, c, u[c]));
            }
        }
    }
    let sol = solve_static(&mesh, &m, &vec![[0.0; 3]; mesh.nodes.len()], &pres).unwrap();
    // Exact up to round-off of a sparse factorisation: 1e-9 relative to the field (~1e-6 m).
    for (i, p) in mesh.nodes.iter().enumerate() {
        let u = field(*p);
        for c in 0..3 {
            assert!(
                (sol.displacement[i][c] - u[c]).abs() < 1e-9 * 2e-6,
                "node {i} comp {c}"
            );
        }
    }
    let s_exact = exact_stress(&m);
    let scale = s_exact.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    for s in element_stresses(&mesh, &m, &sol.displacement).unwrap() {
        for c in 0..6 {
            assert!(
                (s[c] - s_exact[c]).abs() < 1e-8 * scale,
                "stress {c}: {} vs {}",
                s[c],
                s_exact[c]
            );
        }
    }
}

fn explicit_patch(threads: usize) -> Vec<[f64; 3]> {
    let m = LinearElastic::paper_glass();
    let (mesh, boundary) = distorted_box();
    let mut cfg = ExplicitConfig::new(m);
    cfg.rayleigh_beta = 1e-9;
    let mut s = ExplicitSolver::new(&mesh, cfg).unwrap();
    let u0: Vec<[f64; 3]> = mesh.nodes.iter().map(|p| field(*p)).collect();
    let mut pres = Vec::new();
    for (i, b) in boundary.iter().enumerate() {
        if *b {
            for c in 0..3 {
                pres.push(Prescribed {
                    node: i,
                    component: c,
                    kind: PrescribedKind::Displacement(u0[i][c]),
                });
            }
        }
    }
    s.set_prescribed(&pres, LoadHistory::Constant).unwrap();
    s.set_initial_displacement(&u0).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| s.run(300)).unwrap();
    // Interior nodes feel zero net force under constant strain: they must not move.
    for (i, p) in mesh.nodes.iter().enumerate() {
        let u = field(*p);
        for c in 0..3 {
            assert!(
                (s.displacement()[i][c] - u[c]).abs() < 1e-10 * 2e-6,
                "node {i} drifted"
            );
        }
    }
    s.displacement().to_vec()
}

#[test]
fn explicit_patch_test_is_exact() {
    explicit_patch(1);
}

/// Bitwise identical results for 1 and 2 threads on a loaded, damped cartridge-wall tube.
#[test]
fn explicit_is_bitwise_deterministic_across_thread_counts() {
    let prof = demfem::fem::AxisymmetricProfile::tube(4.7e-3, 5.8e-3, 8e-3).unwrap();
    let rm = prof.tet_mesh(32, 2, 0.5e-3).unwrap();
    let mesh = rm.mesh;
    let run = |threads: usize| {
        let mut cfg = ExplicitConfig::new(LinearElastic::paper_glass());
        cfg.rayleigh_alpha = 1e3;
        cfg.rayleigh_beta = 1e-9;
        cfg.step_bound = demfem::fem::stable_step::StepBound::ElementEigenvalue;
        let mut s = ExplicitSolver::new(&mesh, cfg).unwrap();
        let mut loads = vec![[0.0; 3]; mesh.nodes.len()];
        for (i, p) in mesh.nodes.iter().enumerate() {
            if p[2] > 8e-3 - 1e-9 {
                loads[i] = [1.0, -2.0, 5.0];
            }
        }
        s.set_loads(loads, LoadHistory::SmoothRamp { rise_time: 1e-6 })
            .unwrap();
        let fixed: Vec<Prescribed> = (0..mesh.nodes.len())
            .filter(|&i| mesh.nodes[i][2] < 1e-9)
            .flat_map(Prescribed::fix_node)
            .collect();
        s.set_prescribed(&fixed, LoadHistory::Constant).unwrap();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| s.run(400)).unwrap();
        (s.displacement().to_vec(), s.velocity().to_vec(), s.energy())
    };
    let (u1, v1, e1) = run(1);
    let (u2, v2, e2) = run(2);
    assert!(
        u1.iter().flatten().any(|x| x.abs() > 0.0),
        "the load must move the mesh"
    );
    assert!(u1
        .iter()
        .flatten()
        .zip(u2.iter().flatten())
        .all(|(a, b)| a.to_bits() == b.to_bits()));
    assert!(v1
        .iter()
        .flatten()
        .zip(v2.iter().flatten())
        .all(|(a, b)| a.to_bits() == b.to_bits()));
    assert_eq!(e1.internal.to_bits(), e2.internal.to_bits());
    assert_eq!(e1.external_work.to_bits(), e2.external_work.to_bits());
    let _ = explicit_patch(2);
}
