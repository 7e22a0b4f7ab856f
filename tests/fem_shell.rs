//! Thin shell (flat CST + DKT triangle): patch tests and the shell obstacle course
//! (MacNeal & Harder 1985; Belytschko et al. 1985): Scordelis–Lo roof, pinched cylinder
//! with end diaphragms, pinched hemisphere with an 18° hole. Each prints a convergence
//! table; the finest mesh must be within 3 % of the reference value.
#![allow(clippy::needless_range_loop)]

mod common;

use common::grid;
use demfem::fem::element::ShellTri;
use demfem::fem::shell::ShellModel;
use demfem::fem::LinearElastic;
use std::f64::consts::PI;

/// The DKT curvatures of a quadratic deflection w = ½ a x² + ½ b y² + c x y + d x + e y + g
/// are reproduced exactly everywhere in an arbitrary triangle: κ = [−a, −b, −2c].
#[test]
fn dkt_and_membrane_patch_test_single_element() {
    let el = ShellTri::new([[0.1, 0.2, 0.0], [1.3, 0.4, 0.0], [0.5, 1.1, 0.0]], 0.01).unwrap();
    let (a, b, c, d, e) = (0.7, -1.3, 0.45, 0.2, -0.1);
    let mut u = nalgebra::SVector::<f64, 9>::zeros();
    for n in 0..3 {
        let (x, y) = (el.local[n][0], el.local[n][1]);
        u[3 * n] = 0.5 * a * x * x + 0.5 * b * y * y + c * x * y + d * x + e * y + 0.3;
        u[3 * n + 1] = b * y + c * x + e; // θx = ∂w/∂y
        u[3 * n + 2] = -(a * x + c * y + d); // θy = −∂w/∂x
    }
    for (xi, eta) in [
        (0.0, 0.0),
        (1.0, 0.0),
        (0.0, 1.0),
        (0.2, 0.3),
        (0.5, 0.5),
        (1.0 / 3.0, 1.0 / 3.0),
    ] {
        let k = el.dkt_b(xi, eta) * u;
        assert!(
            (k[0] + a).abs() < 1e-12 && (k[1] + b).abs() < 1e-12 && (k[2] + 2.0 * c).abs() < 1e-12,
            "κ = {k:?} at ({xi}, {eta})"
        );
    }
    // Membrane: u = ε_xx x + γ/2 y, v = ε_yy y + γ/2 x.
    let mut um = nalgebra::SVector::<f64, 6>::zeros();
    for n in 0..3 {
        let (x, y) = (el.local[n][0], el.local[n][1]);
        um[2 * n] = 1e-3 * x + 2e-4 * y;
        um[2 * n + 1] = -5e-4 * y + 2e-4 * x;
    }
    let em = el.membrane_b() * um;
    assert!(
        (em[0] - 1e-3).abs() < 1e-15
            && (em[1] + 5e-4).abs() < 1e-15
            && (em[2] - 4e-4).abs() < 1e-15
    );
}

/// Whole-mesh patch test on a distorted plate lying in a tilted plane: with boundary dofs
/// prescribed from a constant-curvature + constant-membrane-strain field, interior nodes
/// reproduce the field exactly (rotated into global dofs).
#[test]
fn shell_mesh_patch_test_tilted_plate() {
    // Local plate frame: e1, e2 in a tilted plane, e3 normal.
    let e1 = [0.8, 0.0, 0.6];
    let e2 = [0.0, 1.0, 0.0];
    let e3 = [-0.6, 0.0, 0.8]; // e1 × e2
    let n = 6;
    let mut mesh = grid(n, n, 0.01, |s, t| {
        let (x, y) = (s, t);
        [
            x * e1[0] + y * e2[0],
            x * e1[1] + y * e2[1],
            x * e1[2] + y * e2[2],
        ]
    });
    // Distort interior nodes in the plate plane.
    for j in 1..n {
        for i in 1..n {
            let k = j * (n + 1) + i;
            let (ds, dt) = (
                0.02 * (((i * 7 + j * 3) % 5) as f64 - 2.0),
                0.02 * (((i * 3 + j * 5) % 5) as f64 - 2.0),
            );
            for c in 0..3 {
                mesh.nodes[k][c] += ds * e1[c] + dt * e2[c];
            }
        }
    }
    let model = ShellModel::new(mesh, LinearElastic::new(2e11, 0.3, 7800.0).unwrap()).unwrap();
    let (a, b, c) = (1e-3, -2e-3, 5e-4);
    let exact = |p: [f64; 3]| -> [f64; 6] {
        let x = p[0] * e1[0] + p[1] * e1[1] + p[2] * e1[2];
        let y = p[0] * e2[0] + p[1] * e2[1] + p[2] * e2[2];
        let w = 0.5 * a * x * x + 0.5 * b * y * y + c * x * y;
        let (tx, ty) = (b * y + c * x, -(a * x + c * y));
        let (ul, vl) = (1e-4 * x + 3e-5 * y, -2e-5 * y + 3e-5 * x);
        let mut d = [0.0; 6];
        for k in 0..3 {
            d[k] = ul * e1[k] + vl * e2[k] + w * e3[k];
            d[3 + k] = tx * e1[k] + ty * e2[k];
        }
        d
    };
    let mut fixed = Vec::new();
    for (i, p) in model.mesh.nodes.iter().enumerate() {
        let (ii, jj) = (i % (n + 1), i / (n + 1));
        if ii == 0 || jj == 0 || ii == n || jj == n {
            let d = exact(*p);
            for k in 0..6 {
                fixed.push((i, k, d[k]));
            }
        }
    }
    let f = vec![0.0; model.n_dofs()];
    let x = model.solve_static(&f, &fixed).unwrap();
    for (i, p) in model.mesh.nodes.iter().enumerate() {
        let d = exact(*p);
        for k in 0..5 {
            // Drilling rotation θ·e3 is not part of the field; translations and in-plane
            // rotations must match to round-off (scale 1e-3).
            assert!(
                (x[6 * i + k] - d[k]).abs() < 1e-10,
                "node {i} dof {k}: {} vs {}",
                x[6 * i + k],
                d[k]
            );
        }
    }
}

/// Scordelis–Lo roof: R = 25 ft, L = 50 ft, 80° arc, t = 0.25 ft, E = 4.32e8 lb/ft²,
/// ν = 0, self weight 90 lb/ft², rigid end diaphragms; reference vertical deflection at
/// the midspan of the free edge 0.3024 ft (MacNeal & Harder). Quarter model.
#[test]
fn scordelis_lo_roof() {
    let (r, half_l, phi0) = (25.0, 25.0, 40f64.to_radians());
    let mat = LinearElastic::new(4.32e8, 0.0, 1.0).unwrap();
    let mut last = 0.0;
    println!("Scordelis–Lo roof (ref 0.3024 ft)\n  n  dofs  w_A/ref");
    for n in [4, 8, 16, 32] {
        let mesh = grid(n, n, 0.25, |s, t| {
            let (x, phi) = (s * half_l, t * phi0);
            [x, r * phi.sin(), r * phi.cos()]
        });
        let model = ShellModel::new(mesh, mat).unwrap();
        let f = model.area_load([0.0, 0.0, -90.0]);
        let mut fixed = Vec::new();
        for (i, p) in model.mesh.nodes.iter().enumerate() {
            let (ii, jj) = (i % (n + 1), i / (n + 1));
            if ii == 0 {
                fixed.extend([(i, 0, 0.0), (i, 4, 0.0), (i, 5, 0.0)]);
            }
            if ii == n {
                fixed.extend([(i, 1, 0.0), (i, 2, 0.0)]);
            }
            if jj == 0 {
                fixed.extend([(i, 1, 0.0), (i, 3, 0.0), (i, 5, 0.0)]);
            }
            let _ = p;
        }
        let x = model.solve_static(&f, &fixed).unwrap();
        let a = n * (n + 1); // (i = 0, j = n): midspan, free edge
        let w = -x[6 * a + 2];
        last = w / 0.3024;
        println!("  {n:2}  {:5}  {last:.4}", model.n_dofs());
    }
    assert!((last - 1.0).abs() < 0.03, "Scordelis–Lo off: {last}");
}

/// Pinched cylinder with rigid end diaphragms: R = 300 in, L = 600 in, t = 3 in,
/// E = 3e6 psi, ν = 0.3, two opposite unit loads at midspan; reference deflection under
/// the load 1.8248e-5 in. Octant model with P/4.
#[test]
fn pinched_cylinder_with_diaphragms() {
    let (r, half_l, t) = (300.0, 300.0, 3.0);
    let mat = LinearElastic::new(3e6, 0.3, 1.0).unwrap();
    let mut last = 0.0;
    println!("Pinched cylinder (ref 1.8248e-5 in)\n  n  dofs  w/ref");
    for n in [8, 16, 32, 48] {
        let mesh = grid(n, n, t, |s, tt| {
            let (x, phi) = (s * half_l, tt * 0.5 * PI);
            [x, r * phi.sin(), r * phi.cos()]
        });
        let model = ShellModel::new(mesh, mat).unwrap();
        let mut f = vec![0.0; model.n_dofs()];
        f[2] = -0.25; // node (0,0): x = 0, φ = 0 → (0, 0, R)
        let mut fixed = Vec::new();
        for i in 0..model.mesh.nodes.len() {
            let (ii, jj) = (i % (n + 1), i / (n + 1));
            if ii == 0 {
                fixed.extend([(i, 0, 0.0), (i, 4, 0.0), (i, 5, 0.0)]);
            }
            if ii == n {
                fixed.extend([(i, 1, 0.0), (i, 2, 0.0)]);
            }
            if jj == 0 {
                fixed.extend([(i, 1, 0.0), (i, 3, 0.0), (i, 5, 0.0)]);
            }
            if jj == n {
                fixed.extend([(i, 2, 0.0), (i, 3, 0.0), (i, 4, 0.0)]);
            }
        }
        let x = model.solve_static(&f, &fixed).unwrap();
        last = -x[2] / 1.8248e-5;
        println!("  {n:2}  {:5}  {last:.4}", model.n_dofs());
    }
    assert!((last - 1.0).abs() < 0.03, "pinched cylinder off: {last}");
}

/// Pinched hemisphere with an 18° hole: R = 10, t = 0.04, E = 6.825e7, ν = 0.3, four
/// alternating radial loads of 2 on the equator; reference displacement under the load
/// 0.094 (MacNeal & Harder). Quarter model with half loads on the symmetry planes.
#[test]
fn pinched_hemisphere_with_hole() {
    let (r, t) = (10.0, 0.04);
    let mat = LinearElastic::new(6.825e7, 0.3, 1.0).unwrap();
    let mut last = 0.0;
    println!("Pinched hemisphere (ref 0.094)\n  n  dofs  u/ref");
    for n in [8, 16, 24, 32] {
        let mesh = grid(n, n, t, |s, tt| {
            let (az, lat) = (s * 0.5 * PI, tt * 72f64.to_radians());
            [
                r * lat.cos() * az.cos(),
                r * lat.cos() * az.sin(),
                r * lat.sin(),
            ]
        });
        let model = ShellModel::new(mesh, mat).unwrap();
        let mut f = vec![0.0; model.n_dofs()];
        f[0] = 1.0; // node (0,0): (R, 0, 0), outward
        f[6 * n + 1] = -1.0; // node (n,0): (0, R, 0), inward
        let mut fixed = Vec::new();
        for i in 0..model.mesh.nodes.len() {
            let ii = i % (n + 1);
            if ii == 0 {
                fixed.extend([(i, 1, 0.0), (i, 3, 0.0), (i, 5, 0.0)]);
            }
            if ii == n {
                fixed.extend([(i, 0, 0.0), (i, 4, 0.0), (i, 5, 0.0)]);
            }
        }
        fixed.push((0, 2, 0.0)); // rigid translation along z
        let x = model.solve_static(&f, &fixed).unwrap();
        last = x[0] / 0.094;
        let other = -x[6 * n + 1] / 0.094;
        println!(
            "  {n:2}  {:5}  {last:.4} (other load point {other:.4})",
            model.n_dofs()
        );
    }
    assert!((last - 1.0).abs() < 0.03, "pinched hemisphere off: {last}");
}

/// Explicit shell dynamics: a cantilever strip (L = 50 mm, b = 5 mm, h = 2 mm, steel with
/// ν = 0 so the strip is an Euler–Bernoulli beam, EI = E b h³/12) released from its static
/// tip-load shape vibrates in its first mode, ω1 = 1.8751² √(EI / (ρ b h L⁴)). The static
/// shape has a 97 % first-mode participation, so zero crossings of the tip deflection give
/// the first period; tolerance 2 % (mesh of 20×2 cells: DKT bending error ≈ 0.5 %).
/// Also: bitwise equal for 1 and 2 threads, and the discrete energy balance holds.
#[test]
fn explicit_shell_cantilever_first_frequency() {
    use demfem::fem::explicit::dof_rows;
    use demfem::fem::ShellExplicit;
    let (l, b, h) = (0.05, 0.005, 0.002);
    let mat = LinearElastic::new(2e11, 0.0, 7800.0).unwrap();
    let (nx, ny) = (20, 2);
    let model = ShellModel::new(grid(nx, ny, h, |s, t| [s * l, t * b, 0.0]), mat).unwrap();
    let mut fixed = Vec::new();
    let mut fixed_vals = Vec::new();
    for i in 0..model.mesh.nodes.len() {
        if i % (nx + 1) == 0 {
            for k in 0..6 {
                fixed.push((i, k));
                fixed_vals.push((i, k, 0.0));
            }
        }
    }
    let mut f = vec![0.0; model.n_dofs()];
    for j in 0..=ny {
        f[6 * (j * (nx + 1) + nx) + 2] = 1.0 / (ny + 1) as f64;
    }
    let u0 = model.solve_static(&f, &fixed_vals).unwrap();
    let tip = 6 * nx + 2;
    let ei = mat.young_modulus * b * h.powi(3) / 12.0;
    // Static tip deflection against P L³/(3EI), as a check of the initial state (1 %).
    let w_static = 1.0 * l.powi(3) / (3.0 * ei);
    assert!(
        (u0[tip] / w_static - 1.0).abs() < 0.01,
        "static tip {} vs {w_static}",
        u0[tip]
    );
    let omega = 1.875_104_07f64.powi(2) * (ei / (mat.density * b * h * l.powi(4))).sqrt();
    let period = 2.0 * PI / omega;
    let run = |threads: usize| {
        let mut s = ShellExplicit::new(&model, &fixed, None).unwrap();
        s.set_initial_displacement(&dof_rows(&u0).unwrap()).unwrap();
        let n = (2.3 * period / s.dt()).ceil() as u64;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut crossings = Vec::new();
        let mut prev = u0[tip];
        let mut max_err: f64 = 0.0;
        for _ in 0..n {
            let t0 = s.time();
            pool.install(|| s.step());
            let cur = s.displacement().as_flattened()[tip];
            if prev * cur < 0.0 {
                crossings.push(t0 + s.dt() * prev / (prev - cur));
            }
            prev = cur;
            max_err = max_err.max(s.energy().relative_balance_error());
        }
        (
            crossings,
            s.displacement().as_flattened().to_vec(),
            max_err,
            s.dt(),
            s.dt_limit(),
        )
    };
    let (c1, u1, err1, dt, dt_lim) = run(1);
    let (_, u2, _, _, _) = run(2);
    assert!(
        u1.iter().zip(&u2).all(|(a, b)| a.to_bits() == b.to_bits()),
        "1 and 2 threads differ"
    );
    assert!(c1.len() >= 4);
    let measured = 2.0 * (c1[c1.len() - 1] - c1[0]) / (c1.len() - 1) as f64;
    let rel = (measured - period).abs() / period;
    println!("shell cantilever: dt {dt:.3e} (limit {dt_lim:.3e}), period {measured:.5e} vs {period:.5e} (rel {rel:.2e}), energy balance {err1:.1e}");
    assert!(rel < 0.02);
    assert!(
        err1 < 1e-9,
        "discrete energy balance is exact up to round-off: {err1:e}"
    );
}
