//! Explicit shell contact (`FemContact::new_shell` with `ShellExplicit`) against closed
//! forms and conservation laws: a flat plate bouncing on a rigid plane (each node a
//! spring-mass oscillator of the same frequency), two shell tubes colliding free (momentum
//! to round-off, energy balance, 1 vs 2 threads bitwise, checkpoint), a plate resting on a
//! moving belt under gravity (carries m g, dragged at μ m g), a clamped square plate pressed
//! by a rigid sphere (Timoshenko's centre deflection), and bad input.

mod common;

use common::{alternating_triangles, grid};
use demfem::error::DemfemError;
use demfem::fem::contact::{
    ContactSettings, FemContact, NoTensionSpring, RigidShape, RigidSurface,
};
use demfem::fem::explicit::dof_rows;
use demfem::fem::mesh::TriMesh;
use demfem::fem::shell::ShellModel;
use demfem::fem::LinearElastic;
use demfem::fem::ShellExplicit;
use std::f64::consts::PI;

fn glass() -> LinearElastic {
    LinearElastic::new(7.3e10, 0.2, 2500.0).unwrap()
}

/// Closed tube of radius `r`, length `l`, thickness `h` along x through (0, cy, cz):
/// `nc` nodes round, `nl` cells long.
fn tube(nc: usize, nl: usize, r: f64, l: f64, h: f64, cy: f64, cz: f64) -> TriMesh {
    let mut nodes = Vec::new();
    for j in 0..=nl {
        for i in 0..nc {
            let a = 2.0 * PI * i as f64 / nc as f64;
            nodes.push([l * j as f64 / nl as f64, cy + r * a.cos(), cz + r * a.sin()]);
        }
    }
    let triangles = alternating_triangles(nc, nl, |i, j| j * nc + i % nc);
    let thickness = vec![h; triangles.len()];
    TriMesh {
        nodes,
        triangles,
        thickness,
    }
}

fn join(a: &TriMesh, b: &TriMesh) -> (TriMesh, Vec<u32>) {
    let mut m = a.clone();
    let off = a.nodes.len();
    m.nodes.extend_from_slice(&b.nodes);
    m.triangles.extend(
        b.triangles
            .iter()
            .map(|t| [t[0] + off, t[1] + off, t[2] + off]),
    );
    m.thickness.extend_from_slice(&b.thickness);
    let mut body = vec![0u32; off];
    body.extend(vec![1u32; b.nodes.len()]);
    (m, body)
}

fn plane(mu: f64, belt: [f64; 3]) -> RigidSurface {
    RigidSurface {
        shape: RigidShape::Plane {
            point: [0.0; 3],
            normal: [0.0, 0.0, 1.0],
        },
        surface_velocity: belt,
        friction: mu,
    }
}

fn frictionless() -> ContactSettings {
    ContactSettings {
        friction: 0.0,
        output_interval: 1,
        ..Default::default()
    }
}

/// A free square plate (uniform grid: every triangle of area A) falls flat onto a rigid
/// plane at v0. Every node's penalty k_node = Σ s·E·t/3 and mass Σ ρ t A/3 have the same
/// ratio E/(ρ A), so the plate stays flat and every node is one oscillator: contact lasts
/// π √(ρ A / (s E)) and the plate leaves at −v0 (momentum change 2 m v0).
#[test]
fn a_flat_shell_plate_bounces_off_a_rigid_plane_as_a_spring_mass() {
    let mat = glass();
    let (a, h, n) = (0.01, 1e-3, 8);
    let z0 = 0.5 * h + 2e-6;
    let mesh = grid(n, n, h, |s, t| [s * a, t * a, z0]);
    let nn = mesh.nodes.len();
    let model = ShellModel::new(mesh.clone(), mat).unwrap();
    let mut s = ShellExplicit::new(&model, &[], None).unwrap();
    let v0 = 0.5;
    s.set_uniform_velocity([0.0, 0.0, -v0]).unwrap();
    // A soft penalty (s = 0.01) so that the contact lasts some 30 steps.
    let scale = 0.01;
    let settings = ContactSettings {
        penalty_scale: scale,
        ..frictionless()
    };
    let mut c = FemContact::new_shell(&mesh, &vec![0; nn], &vec![0; nn], &mat, settings).unwrap();
    c.add_rigid(plane(0.0, [0.0; 3])).unwrap();
    s.set_contact(c).unwrap();
    let m: f64 = s.mass().to_vec().iter().sum();
    let area_tri = 0.5 * (a / n as f64).powi(2);
    let duration = PI * (mat.density * area_tri / (scale * mat.young_modulus)).sqrt();
    let t_touch = 2e-6 / v0;
    let steps = ((t_touch + 1.5 * duration) / s.dt()).ceil() as u64;
    let (mut first, mut last) = (f64::NAN, f64::NAN);
    let mut worst: f64 = 0.0;
    for _ in 0..steps {
        s.step();
        assert!(s.contact_energy().elastic >= 0.0);
        if s.contact().unwrap().active_contacts() > 0 {
            if first.is_nan() {
                first = s.time();
            }
            last = s.time();
        }
        worst = worst.max(s.energy_balance().relative_balance_error());
    }
    let p = s.momentum();
    let measured = last - first + s.dt();
    println!(
        "plate bounce: p_z {:.5e} vs {:.5e}, contact {measured:.4e} s vs {duration:.4e} s, balance {worst:.1e}",
        p[2],
        m * v0
    );
    assert!((p[2] / (m * v0) - 1.0).abs() < 0.01, "rebound momentum");
    assert!(p[0].abs() < 1e-12 * m * v0 && p[1].abs() < 1e-12 * m * v0);
    assert!((measured / duration - 1.0).abs() < 0.03, "contact duration");
    assert!(worst < 0.01, "energy balance {worst}");
}

struct Collision {
    u: Vec<f64>,
    p_start: [f64; 3],
    p_end: [f64; 3],
    p_scale: f64,
    worst_balance: f64,
    peak_force: f64,
    saved: Vec<u8>,
    saved_at: u64,
    steps: u64,
}

fn two_tubes_model() -> (ShellModel, TriMesh, Vec<u32>) {
    let mat = glass();
    let (r, l, h) = (4.3e-3, 0.02, 1.1e-3);
    let gap = 5e-6;
    let a = tube(24, 10, r, l, h, 0.0, 0.0);
    let dz = 0.3 * r;
    let b = tube(
        24,
        10,
        r,
        l,
        h,
        ((2.0 * r + h + gap).powi(2) - dz * dz).sqrt(),
        dz,
    );
    let (mesh, body) = join(&a, &b);
    (ShellModel::new(mesh.clone(), mat).unwrap(), mesh, body)
}

fn collide(threads: usize) -> Collision {
    let mat = glass();
    let (model, mesh, body) = two_tubes_model();
    let nn = mesh.nodes.len();
    let settings = ContactSettings {
        friction: 0.2,
        output_interval: 1,
        ..Default::default()
    };
    let c = FemContact::new_shell(&mesh, &body, &vec![0; nn], &mat, settings).unwrap();
    let mut s = ShellExplicit::new(&model, &[], None).unwrap();
    let mut v = vec![0.0; 6 * nn];
    for i in 0..nn {
        v[6 * i + 1] = if body[i] == 0 { 0.4 } else { -0.4 };
        v[6 * i] = if body[i] == 0 { 0.05 } else { 0.0 };
    }
    s.set_initial_velocity(&dof_rows(&v).unwrap()).unwrap();
    s.set_contact(c).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let steps = (150e-6 / s.dt()).ceil() as u64;
    let saved_at = steps / 2;
    let p_start = s.momentum();
    let m: f64 = s.mass().to_vec().iter().sum();
    let mut out = Collision {
        u: Vec::new(),
        p_start,
        p_end: [0.0; 3],
        p_scale: 0.4 * m,
        worst_balance: 0.0,
        peak_force: 0.0,
        saved: Vec::new(),
        saved_at,
        steps,
    };
    pool.install(|| {
        for k in 0..steps {
            if k == saved_at {
                out.saved = s.save_state();
            }
            s.run(1).unwrap();
            if let Some(x) = s.contact().unwrap().last_sample().first() {
                out.peak_force = out.peak_force.max(x.normal_force);
            }
            out.worst_balance = out
                .worst_balance
                .max(s.energy_balance().relative_balance_error());
        }
    });
    out.p_end = s.momentum();
    out.u = s.displacement().as_flattened().to_vec();
    out
}

/// Two glass shell tubes (cartridge size) collide off-centre with friction: linear
/// momentum is conserved to round-off, the energy balance (kinetic + strain + contact +
/// friction work) closes within 1 %, the run is bitwise identical on 1 and 2 threads, and
/// a run restored from a checkpoint halfway ends bitwise where the uninterrupted one does.
#[test]
fn two_shell_tubes_collide_conserving_momentum_and_energy() {
    let one = collide(1);
    let two = collide(2);
    println!(
        "tubes: peak normal force {:.3} N, worst energy balance {:.2e}, p {:?} -> {:?}",
        one.peak_force, one.worst_balance, one.p_start, one.p_end
    );
    assert!(one.peak_force > 1.0, "the tubes touched");
    for d in 0..3 {
        assert!(
            (one.p_end[d] - one.p_start[d]).abs() < 1e-10 * one.p_scale,
            "momentum {d}: {} -> {}",
            one.p_start[d],
            one.p_end[d]
        );
    }
    assert!(
        one.worst_balance < 0.01,
        "energy balance {}",
        one.worst_balance
    );
    assert!(
        one.u
            .iter()
            .zip(&two.u)
            .all(|(a, b)| a.to_bits() == b.to_bits()),
        "1 and 2 threads differ"
    );
    // Restore the halfway state into a fresh solver and finish the run.
    let mat = glass();
    let (model, mesh, body) = two_tubes_model();
    let nn = mesh.nodes.len();
    let settings = ContactSettings {
        friction: 0.2,
        output_interval: 1,
        ..Default::default()
    };
    let c = FemContact::new_shell(&mesh, &body, &vec![0; nn], &mat, settings).unwrap();
    let mut s = ShellExplicit::new(&model, &[], None).unwrap();
    s.set_contact(c).unwrap();
    s.restore_state(&one.saved).unwrap();
    s.run(one.steps - one.saved_at).unwrap();
    assert!(
        s.displacement()
            .as_flattened()
            .iter()
            .zip(&one.u)
            .all(|(a, b)| a.to_bits() == b.to_bits()),
        "restored run differs"
    );
    // A state of another model is refused.
    let plate = grid(2, 2, 1e-3, |x, y| [x * 0.01, y * 0.01, 0.01]);
    let pm = ShellModel::new(plate, mat).unwrap();
    let mut other = ShellExplicit::new(&pm, &[], None).unwrap();
    assert!(other.restore_state(&one.saved).is_err());
}

/// A square plate resting on a belt moving at v_b under gravity, placed at its static
/// penetration g ρ A/(s E) (each node's oscillator at rest): the plane carries m g (1 %)
/// and friction accelerates the plate at μ g while it slips (v_x = μ g t, 1 %); friction
/// work and the belt's work close the energy balance.
#[test]
fn a_shell_plate_on_the_belt_carries_its_weight_and_is_dragged_at_mu_n() {
    let mat = glass();
    let (a, h, n) = (0.01, 1e-3, 6);
    let g = 9.81;
    let area_tri = 0.5 * (a / n as f64).powi(2);
    let delta = g * mat.density * area_tri / mat.young_modulus;
    let mesh = grid(n, n, h, |s, t| [s * a, t * a, 0.5 * h - delta]);
    let nn = mesh.nodes.len();
    let model = ShellModel::new(mesh.clone(), mat).unwrap();
    let mut s = ShellExplicit::new(&model, &[], None).unwrap();
    s.add_gravity([0.0, 0.0, -g]).unwrap();
    let mu = 0.3;
    let settings = ContactSettings {
        friction: mu,
        output_interval: 1,
        initial_overlap_tolerance: 2.0 * delta,
        ..Default::default()
    };
    let mut c = FemContact::new_shell(&mesh, &vec![0; nn], &vec![0; nn], &mat, settings).unwrap();
    c.add_rigid(plane(mu, [1.0, 0.0, 0.0])).unwrap();
    s.set_contact(c).unwrap();
    let m: f64 = s.mass().to_vec().iter().sum();
    let steps = (200e-6 / s.dt()).ceil() as u64;
    let (mut fn_sum, mut ft_sum, mut count) = (0.0, 0.0, 0);
    for k in 0..steps {
        s.run(1).unwrap();
        if k > steps / 4 {
            let x = s.contact().unwrap().last_sample()[0];
            fn_sum += x.normal_force;
            ft_sum += x.tangential_force;
            count += 1;
        }
    }
    let fnm = fn_sum / count as f64;
    let ftm = ft_sum / count as f64;
    let vx = s.momentum()[0] / m;
    let t = s.time();
    let e = s.energy_balance();
    println!(
        "plate on belt: N {fnm:.6e} vs m g {:.6e}, T {ftm:.6e} vs mu N {:.6e}, v_x {vx:.5e} vs {:.5e}, friction work {:.3e} J, balance {:.1e}",
        m * g,
        mu * m * g,
        mu * g * t,
        e.friction_work,
        e.relative_balance_error()
    );
    assert!((fnm / (m * g) - 1.0).abs() < 0.01, "normal force");
    assert!((ftm / (mu * m * g) - 1.0).abs() < 0.01, "friction force");
    assert!((vx / (mu * g * t) - 1.0).abs() < 0.01, "drag");
    assert!(e.friction_work > 0.0 && e.rigid_work > 0.0);
    assert!(e.relative_balance_error() < 0.01);
}

/// A clamped square glass plate (side a, thickness t) pressed at its centre by a rigid
/// sphere moving slowly down: the centre deflection follows Timoshenko & Woinowsky-Krieger
/// (Theory of Plates and Shells, §44, table 59), w = 0.00560 F a²/D, D = E t³/(12(1 − ν²))
/// for ν = 0.3, within 5 % (mesh 16×16 DKT; the load is spread over the contact nodes; the
/// sphere's travel is slow against the plate's first period, the ratio is averaged over the
/// last periods).
#[test]
fn a_clamped_shell_plate_under_a_sphere_follows_the_point_load_closed_form() {
    let mat = LinearElastic::new(7.3e10, 0.3, 2500.0).unwrap();
    let (a, h, n) = (0.02, 0.5e-3, 16);
    let mesh = grid(n, n, h, |s, t| [s * a, t * a, 0.0]);
    let nn = mesh.nodes.len();
    let model = ShellModel::new(mesh.clone(), mat).unwrap();
    let mut fixed = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            if i == 0 || j == 0 || i == n || j == n {
                for k in 0..6 {
                    fixed.push((j * (n + 1) + i, k));
                }
            }
        }
    }
    let mut s = ShellExplicit::new(&model, &fixed, None).unwrap();
    let d_plate = mat.young_modulus * h.powi(3) / (12.0 * (1.0 - 0.09));
    // First period of the clamped square plate: ω = 35.99 √(D/(ρ t)) / a².
    let omega = 35.99 * (d_plate / (mat.density * h)).sqrt() / (a * a);
    let period = 2.0 * PI / omega;
    let r_s = 0.005;
    let travel_time = 12.0 * period;
    let w_end = 2e-5;
    let vs = w_end / travel_time;
    let centre = (n / 2) * (n + 1) + n / 2;
    let mut c =
        FemContact::new_shell(&mesh, &vec![0; nn], &vec![0; nn], &mat, frictionless()).unwrap();
    c.add_rigid(RigidSurface {
        shape: RigidShape::Sphere {
            center: [0.5 * a, 0.5 * a, 0.5 * h + r_s + 1e-7],
            radius: r_s,
            velocity: [0.0, 0.0, -vs],
        },
        surface_velocity: [0.0; 3],
        friction: 0.0,
    })
    .unwrap();
    s.set_contact(c).unwrap();
    let steps = (travel_time / s.dt()).ceil() as u64;
    let window = (2.0 * period / s.dt()) as u64;
    let (mut fsum, mut wsum) = (0.0, 0.0);
    for k in 0..steps {
        s.run(1).unwrap();
        if k + window >= steps {
            let f: f64 = s.contact_force().iter().map(|f| -f[2]).sum();
            fsum += f;
            wsum += -s.displacement()[centre][2];
        }
    }
    let closed = 0.00560 * fsum * a * a / d_plate;
    println!(
        "clamped plate: mean w {:.5e} m vs 0.0056 F a²/D {:.5e} m (rel {:.2e}), {} steps",
        wsum / window as f64,
        closed / window as f64,
        wsum / closed - 1.0,
        steps
    );
    assert!((wsum / closed - 1.0).abs() < 0.05);
}

fn expect_invalid(r: Result<impl Sized, DemfemError>, words: &[&str]) {
    match r {
        Ok(_) => panic!("accepted"),
        Err(e) => {
            let m = e.to_string();
            for w in words {
                assert!(m.contains(w), "{m:?} lacks {w:?}");
            }
        }
    }
}

/// Bad input is refused with clear errors: a non-positive thickness, bodies overlapping at
/// the start (naming the bodies and the depth), a shell penetrating the plane, a fixed step
/// above the contact-certified limit, a solid contact model, and a spring on a missing node.
#[test]
fn bad_shell_contact_input_is_refused() {
    let mat = glass();
    let h = 1e-3;
    let mut bad = grid(2, 2, h, |x, y| [x * 0.01, y * 0.01, 0.0]);
    bad.thickness[3] = 0.0;
    let nb = bad.nodes.len();
    expect_invalid(
        FemContact::new_shell(&bad, &vec![0; nb], &vec![0; nb], &mat, frictionless()),
        &["thickness", "triangle 3"],
    );
    // Two plates 0.6 t apart: their contact surfaces overlap by 0.4 t.
    let a = grid(2, 2, h, |x, y| [x * 0.01, y * 0.01, 0.0]);
    let b = grid(2, 2, h, |x, y| [x * 0.01, y * 0.01, 0.6 * h]);
    let (mesh, body) = join(&a, &b);
    let nn = mesh.nodes.len();
    let model = ShellModel::new(mesh.clone(), mat).unwrap();
    let c = FemContact::new_shell(&mesh, &body, &vec![0; nn], &mat, frictionless()).unwrap();
    let mut s = ShellExplicit::new(&model, &[], None).unwrap();
    expect_invalid(s.set_contact(c), &["body 0 overlaps body 1 by 4.0000"]);
    // On the plane, deeper than half the thickness.
    let low = grid(2, 2, h, |x, y| [x * 0.01, y * 0.01, 0.3 * h]);
    let nl = low.nodes.len();
    let ml = ShellModel::new(low.clone(), mat).unwrap();
    let mut c =
        FemContact::new_shell(&low, &vec![0; nl], &vec![0; nl], &mat, frictionless()).unwrap();
    c.add_rigid(plane(0.0, [0.0; 3])).unwrap();
    let mut s = ShellExplicit::new(&ml, &[], None).unwrap();
    expect_invalid(s.set_contact(c), &["penetrates rigid surface"]);
    // A fixed step the shells allow but the contact does not.
    let high = grid(2, 2, h, |x, y| [x * 0.01, y * 0.01, 0.01]);
    let mh = ShellModel::new(high.clone(), mat).unwrap();
    let free = ShellExplicit::new(&mh, &[], None).unwrap();
    let mut c =
        FemContact::new_shell(&high, &vec![0; nl], &vec![0; nl], &mat, frictionless()).unwrap();
    c.add_rigid(plane(0.0, [0.0; 3])).unwrap();
    let mut s = ShellExplicit::new(&mh, &[], Some(0.99 * free.dt_limit())).unwrap();
    expect_invalid(s.set_contact(c), &["contact allowance"]);
    // Springs on a node that does not exist.
    let mut c =
        FemContact::new_shell(&high, &vec![0; nl], &vec![0; nl], &mat, frictionless()).unwrap();
    expect_invalid(
        c.add_springs(&[NoTensionSpring {
            node: 999,
            anchor: [0.0; 3],
            stiffness: 1.0,
            rest_length: 1.0,
        }]),
        &["node 999"],
    );
    // A contact model of a solid mesh.
    let tet = demfem::fem::mesh::box_tet_mesh(0.01, 0.01, 0.01, 1, 1, 1).unwrap();
    let nt = tet.nodes.len();
    let ct = FemContact::new(&tet, &vec![0; nt], &vec![0; nt], &mat, frictionless()).unwrap();
    let mut s = ShellExplicit::new(&mh, &[], None).unwrap();
    expect_invalid(s.set_contact(ct), &["new_shell"]);
    // Initial velocity on a fixed dof.
    let mut s = ShellExplicit::new(&mh, &[(0, 2)], None).unwrap();
    expect_invalid(
        s.set_uniform_velocity([0.0; 3]).and_then(|_| {
            let mut v = vec![0.0; 6 * nl];
            v[2] = 1.0;
            s.set_initial_velocity(&dof_rows(&v)?)
        }),
        &["fixed dof"],
    );
}

/// No-tension springs on shell nodes push a plate back and never pull: a plate moving at
/// v0 onto springs of total stiffness K comes back at −v0 after π √(m/K) (each node has
/// its spring of stiffness proportional to its mass, so the plate moves rigidly).
#[test]
fn no_tension_springs_on_shell_nodes_push_back_a_plate() {
    let mat = glass();
    let (a, h, n) = (0.01, 1e-3, 4);
    let mesh = grid(n, n, h, |s, t| [s * a, t * a, 0.0]);
    let nn = mesh.nodes.len();
    let model = ShellModel::new(mesh.clone(), mat).unwrap();
    let mut s = ShellExplicit::new(&model, &[], None).unwrap();
    let masses = s.mass().to_vec();
    let m: f64 = masses.iter().sum();
    let omega = 2e5;
    let rest = 1e-3;
    let springs: Vec<NoTensionSpring> = (0..nn)
        .map(|i| NoTensionSpring {
            node: i,
            anchor: [mesh.nodes[i][0], mesh.nodes[i][1], -rest - 1e-7],
            stiffness: masses[i] * omega * omega,
            rest_length: rest,
        })
        .collect();
    let mut c =
        FemContact::new_shell(&mesh, &vec![0; nn], &vec![0; nn], &mat, frictionless()).unwrap();
    c.add_springs(&springs).unwrap();
    let v0 = 0.2;
    s.set_uniform_velocity([0.0, 0.0, -v0]).unwrap();
    s.set_contact(c).unwrap();
    let steps = ((1e-7 / v0 + 1.5 * PI / omega) / s.dt()).ceil() as u64;
    let mut min_pz: f64 = 0.0;
    for _ in 0..steps {
        s.run(1).unwrap();
        min_pz = min_pz.min(s.momentum()[2]);
    }
    let p = s.momentum()[2];
    println!("springs: p_z {p:.5e} vs {:.5e}", m * v0);
    assert!((p / (m * v0) - 1.0).abs() < 0.01);
    assert!(s.contact_energy().springs == 0.0);
    assert!(min_pz >= -m * v0 * 1.0001);
}

/// Shell faces are two-sided: a small plate (A) moving at v0 meets a larger free plate (B)
/// head-on, once coming from above B and once from below (B's normals point up both
/// times). Either way momentum is conserved, the energy balance closes (1 %), B is pushed
/// away from A, and the two runs are mirror images of each other (1e-9).
#[test]
fn shell_faces_take_contact_on_either_side() {
    let mat = glass();
    let (a, h, n) = (0.01, 1e-3, 6);
    let v0 = 0.3;
    let mut vb = Vec::new();
    for from_above in [true, false] {
        let sign = if from_above { 1.0 } else { -1.0 };
        let z = sign * (h + 2e-6);
        let lower = grid(n, n, h, |s, t| [s * a, t * a, 0.0]);
        let cell = a / n as f64;
        let upper = grid(n - 2, n - 2, h, |s, t| {
            [
                (s * (n - 2) as f64 + 1.3) * cell,
                (t * (n - 2) as f64 + 1.2) * cell,
                z,
            ]
        });
        let (mesh, body) = join(&lower, &upper);
        let nn = mesh.nodes.len();
        let model = ShellModel::new(mesh.clone(), mat).unwrap();
        let settings = ContactSettings {
            penalty_scale: 0.01,
            ..frictionless()
        };
        let c = FemContact::new_shell(&mesh, &body, &vec![0; nn], &mat, settings).unwrap();
        let mut s = ShellExplicit::new(&model, &[], None).unwrap();
        let mut v = vec![0.0; 6 * nn];
        for i in 0..nn {
            if body[i] == 1 {
                v[6 * i + 2] = -sign * v0;
            }
        }
        s.set_initial_velocity(&dof_rows(&v).unwrap()).unwrap();
        s.set_contact(c).unwrap();
        let p0 = s.momentum();
        let steps = (30e-6 / s.dt()).ceil() as u64;
        s.run(steps).unwrap();
        let m = s.mass().to_vec();
        let (mut pb, mut mb) = (0.0, 0.0);
        for i in 0..nn {
            if body[i] == 0 {
                pb += m[i] * s.velocity()[i][2];
                mb += m[i];
            }
        }
        let p1 = s.momentum();
        let e = s.energy_balance();
        println!(
            "from above {from_above}: v_B {:.6e} (v0 {v0}), p_z {:.3e} -> {:.3e}, balance {:.1e}",
            pb / mb,
            p0[2],
            p1[2],
            e.relative_balance_error()
        );
        assert!((p1[2] - p0[2]).abs() < 1e-10 * p0[2].abs());
        assert!(-sign * pb / mb > 0.1 * v0, "B pushed away from A");
        assert!(e.relative_balance_error() < 0.01);
        vb.push(pb / mb);
    }
    assert!(
        (vb[0] + vb[1]).abs() < 1e-9 * vb[0].abs(),
        "mirror images: {vb:?}"
    );
}

/// Two faceted shell tubes meet ridge to ridge (a node column of each facing the other's,
/// their contact surfaces `gap` apart). Neither node projects onto a face of the other
/// tube, so only the rounded edges and corners of the offset surface (the nearest point
/// of the triangle) catch the contact: it starts after gap / v (within two steps), and the
/// tubes part with momentum conserved and the energy balance closed (1 %).
#[test]
fn shell_tubes_meeting_ridge_to_ridge_touch_at_the_offset_distance() {
    let mat = glass();
    let (r, l, h, gap) = (4.3e-3, 0.01, 1.1e-3, 4e-6);
    let a = tube(24, 5, r, l, h, 0.0, 0.0);
    let b = tube(24, 5, r, l, h, 2.0 * r + h + gap, 0.0);
    let (mesh, body) = join(&a, &b);
    let nn = mesh.nodes.len();
    let model = ShellModel::new(mesh.clone(), mat).unwrap();
    let c = FemContact::new_shell(&mesh, &body, &vec![0; nn], &mat, frictionless()).unwrap();
    let mut s = ShellExplicit::new(&model, &[], None).unwrap();
    let v = 0.5;
    let mut v0 = vec![0.0; 6 * nn];
    for i in 0..nn {
        if body[i] == 1 {
            v0[6 * i + 1] = -v;
        }
    }
    s.set_initial_velocity(&dof_rows(&v0).unwrap()).unwrap();
    s.set_contact(c).unwrap();
    let p0 = s.momentum();
    let steps = (80e-6 / s.dt()).ceil() as u64;
    let mut first = f64::NAN;
    let mut worst: f64 = 0.0;
    for _ in 0..steps {
        let t = s.time();
        s.run(1).unwrap();
        if first.is_nan() && s.contact().unwrap().active_contacts() > 0 {
            first = t;
        }
        worst = worst.max(s.energy_balance().relative_balance_error());
    }
    let p1 = s.momentum();
    let t_touch = gap / v;
    println!(
        "ridge to ridge: first contact at {first:.4e} s vs gap/v {t_touch:.4e} s (dt {:.2e}), balance {worst:.2e}, p_y {:.3e} -> {:.3e}",
        s.dt(),
        p0[1],
        p1[1]
    );
    assert!(first >= t_touch - s.dt() && first <= t_touch + 2.0 * s.dt());
    assert!((p1[1] - p0[1]).abs() < 1e-10 * p0[1].abs());
    assert!(worst < 0.01);
    assert_eq!(
        s.contact().unwrap().active_contacts(),
        0,
        "the tubes parted"
    );
}
