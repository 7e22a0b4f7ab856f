//! Bitwise fingerprints of short runs of every engine, for refactorings that must not change
//! a single bit: the explicit FEM with tets and with shells (contact between bodies, a moving
//! belt with friction, no-tension springs, gravity, a checkpoint restored halfway; and a run
//! with damping, prescribed dofs, ramped and extra loads), the DEM table (Hertz–Reissner and
//! Hertz–Mindlin) and the rigid cartridge cluster. Each line prints the IEEE bits (hex) of
//! the final state's hash, of the energies, the contact force peaks, σ1 and the step counts.
//!
//! Bits depend on the platform's libm (meshes use sin and cos), so nothing is asserted here:
//! run it before and after a change and compare the output
//! (`cargo test --release --test bitwise_fingerprint -- --ignored --nocapture`).

mod common;
mod dem_support;
#[path = "rigid_common/mod.rs"]
mod rigid_common;

use common::alternating_triangles;
use demfem::dem::table::{anchor_scene, TableStart};
use demfem::dem::{DemContactLaw as DemLaw, Simulation};
use demfem::fem::contact::{
    ContactSettings, FemContact, NoTensionSpring, RigidShape, RigidSurface,
};
use demfem::fem::explicit::dof_rows;
use demfem::fem::mesh::{box_tet_mesh, place, union, TriMesh};
use demfem::fem::shell::ShellModel;
use demfem::fem::stress::{element_stresses, max_principal_stress};
use demfem::fem::ShellExplicit;
use demfem::fem::{
    AxisymmetricProfile, ExplicitConfig, ExplicitSolver, LinearElastic, LoadHistory, Prescribed,
    PrescribedKind,
};
use std::f64::consts::PI;

/// FNV-1a over the bits of the values.
fn hash(values: impl IntoIterator<Item = f64>) -> u64 {
    let mut h: u64 = 0xcbf29ce484222325;
    for x in values {
        for b in x.to_bits().to_le_bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x100000001b3);
        }
    }
    h
}

fn line(name: &str, values: &[(&str, f64)]) {
    let s: Vec<String> = values
        .iter()
        .map(|(k, v)| format!("{k}={:016x}({v:.6e})", v.to_bits()))
        .collect();
    println!("FP {name}: {}", s.join(" "));
}

fn glass() -> LinearElastic {
    LinearElastic::new(7.3e10, 0.2, 2500.0).unwrap()
}

fn belt(mu: f64) -> RigidSurface {
    RigidSurface {
        shape: RigidShape::Plane {
            point: [0.0; 3],
            normal: [0.0, 0.0, 1.0],
        },
        surface_velocity: [0.2, 0.0, 0.0],
        friction: mu,
    }
}

/// Largest normal force of each channel over the whole contact history, N.
fn peaks(history: &[f64], channels: usize) -> Vec<f64> {
    let stride = 1 + 4 * channels;
    let mut p = vec![0.0f64; channels];
    for row in history.chunks_exact(stride) {
        for c in 0..channels {
            p[c] = p[c].max(row[1 + 4 * c]);
        }
    }
    p
}

// ---- tets ------------------------------------------------------------------------------

/// Two upright glass tubes side by side on the belt, the second closing on the first at
/// 0.18 m/s, friction 0.2, gravity, no-tension springs on a few nodes of the first.
fn tet_cluster() -> (ExplicitSolver, FemContact, Vec<[f64; 3]>) {
    let mat = glass();
    let tube = AxisymmetricProfile::tube(4.7e-3, 5.8e-3, 12e-3)
        .unwrap()
        .tet_mesh(16, 1, 2e-3)
        .unwrap()
        .mesh;
    let i3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let a = place(&tube, i3, [0.0, 0.0, 0.0]).unwrap();
    let b = place(&tube, i3, [11.6e-3 + 2e-6, 0.0, 0.0]).unwrap();
    let (mesh, body) = union(&[a, b]);
    let mut cfg = ExplicitConfig::new(mat);
    cfg.energy_interval = 50;
    let s = ExplicitSolver::new(&mesh, cfg).unwrap();
    let n = mesh.nodes.len();
    let region: Vec<u32> = mesh.nodes.iter().map(|p| u32::from(p[2] > 6e-3)).collect();
    let settings = ContactSettings {
        friction: 0.2,
        output_interval: 5,
        ..Default::default()
    };
    let mut c = FemContact::new(&mesh, &body, &region, &mat, settings).unwrap();
    c.add_rigid(belt(0.2)).unwrap();
    let springs: Vec<NoTensionSpring> = (0..n)
        .filter(|&i| body[i] == 0 && mesh.nodes[i][0] < -5.7e-3)
        .map(|i| {
            let p = mesh.nodes[i];
            NoTensionSpring {
                node: i,
                anchor: [p[0] - 1e-3, p[1], p[2]],
                stiffness: 1e5,
                rest_length: 1e-3,
            }
        })
        .collect();
    c.add_springs(&springs).unwrap();
    let v: Vec<[f64; 3]> = body
        .iter()
        .map(|&b| if b == 1 { [-0.18, 0.0, 0.0] } else { [0.0; 3] })
        .collect();
    (s, c, v)
}

fn tet_cluster_setup() -> (ExplicitSolver, demfem::fem::TetMesh) {
    let (mut s, c, v) = tet_cluster();
    let g = 9.81;
    let loads: Vec<[f64; 3]> = s.mass().iter().map(|&m| [0.0, 0.0, -m * g]).collect();
    s.set_loads(loads, LoadHistory::Constant).unwrap();
    s.set_initial_velocity(&v).unwrap();
    s.set_contact(c).unwrap();
    // the mesh again, for stresses
    let mat = glass();
    let tube = AxisymmetricProfile::tube(4.7e-3, 5.8e-3, 12e-3)
        .unwrap()
        .tet_mesh(16, 1, 2e-3)
        .unwrap()
        .mesh;
    let i3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let a = place(&tube, i3, [0.0, 0.0, 0.0]).unwrap();
    let b = place(&tube, i3, [11.6e-3 + 2e-6, 0.0, 0.0]).unwrap();
    let _ = mat;
    (s, union(&[a, b]).0)
}

fn tet_report(name: &str, s: &ExplicitSolver, mesh: &demfem::fem::TetMesh) {
    let c = s.contact().unwrap();
    let e = s.energy();
    let ce = s.contact_energy();
    let sig = element_stresses(mesh, &glass(), s.displacement()).unwrap();
    let s1 = sig
        .iter()
        .map(max_principal_stress)
        .fold(f64::MIN, f64::max);
    let p = peaks(c.history(), c.channels().len());
    let hist_hash = hash(s.energy_history().iter().flat_map(|e| {
        [
            e.time,
            e.kinetic,
            e.internal,
            e.external_work,
            e.damping_work,
            e.initial,
        ]
    }));
    line(
        name,
        &[
            ("steps", s.steps() as f64),
            ("dt", s.dt()),
            ("time", s.time()),
            (
                "u_v_hash",
                f64::from_bits(hash(
                    s.displacement()
                        .iter()
                        .chain(s.velocity())
                        .flatten()
                        .cloned(),
                )),
            ),
            (
                "f_contact_hash",
                f64::from_bits(hash(s.contact_force().iter().flatten().cloned())),
            ),
            ("energy_hist_hash", f64::from_bits(hist_hash)),
            (
                "contact_hist_hash",
                f64::from_bits(hash(c.history().iter().cloned())),
            ),
            ("kinetic", e.kinetic),
            ("internal", e.internal),
            ("external_work", e.external_work),
            ("initial", e.initial),
            ("rel_balance", e.relative_balance_error()),
            ("c_elastic", ce.elastic),
            ("c_springs", ce.springs),
            ("c_friction", ce.friction_work),
            ("c_rigid", ce.rigid_work),
            ("c_work", ce.contact_work),
            ("peak_max", p.iter().cloned().fold(0.0, f64::max)),
            ("peak_hash", f64::from_bits(hash(p.iter().cloned()))),
            ("sigma1_max", s1),
        ],
    );
}

fn tet_cluster_fingerprint() {
    let (mut s, mesh) = tet_cluster_setup();
    let n = 1000;
    s.run(n / 2).unwrap();
    let saved = s.save_state();
    s.run(n / 2).unwrap();
    tet_report("tet_cluster", &s, &mesh);
    let (mut r, _) = tet_cluster_setup();
    r.restore_state(&saved).unwrap();
    r.run(n / 2).unwrap();
    tet_report("tet_cluster_restored", &r, &mesh);
}

/// A box with Rayleigh damping and mass scaling: prescribed ramped displacement on one face,
/// prescribed velocity on a node, smooth-ramp loads and extra loads.
fn tet_bc_fingerprint() {
    let mat = LinearElastic::new(1e7, 0.3, 1000.0).unwrap();
    let mesh = box_tet_mesh(0.01, 0.01, 0.02, 2, 2, 4).unwrap();
    let n = mesh.nodes.len();
    let mut cfg = ExplicitConfig::new(mat);
    cfg.rayleigh_alpha = 50.0;
    cfg.rayleigh_beta = 1e-6;
    cfg.energy_interval = 7;
    cfg.mass_scaling_dt = Some(4e-5);
    let mut s = ExplicitSolver::new(&mesh, cfg).unwrap();
    let mut p = Vec::new();
    for (i, x) in mesh.nodes.iter().enumerate() {
        if x[2] < 1e-9 {
            p.extend(Prescribed::fix_node(i));
        }
        if x[2] > 0.02 - 1e-9 {
            p.push(Prescribed {
                node: i,
                component: 2,
                kind: PrescribedKind::Displacement(1e-4),
            });
        }
    }
    p.push(Prescribed {
        node: n / 2,
        component: 0,
        kind: PrescribedKind::Velocity(0.01),
    });
    s.set_prescribed(&p, LoadHistory::Ramp { rise_time: 2e-4 })
        .unwrap();
    let loads: Vec<[f64; 3]> = (0..n)
        .map(|i| [1e-3 * (i % 3) as f64, 2e-3, -1e-3])
        .collect();
    s.set_loads(loads, LoadHistory::SmoothRamp { rise_time: 1e-4 })
        .unwrap();
    s.set_extra_loads(&vec![[0.0, -1e-3, 5e-4]; n]).unwrap();
    s.set_initial_velocity(&vec![[0.0, 0.01, 0.0]; n]).unwrap();
    s.run(500).unwrap();
    let e = s.energy();
    let sig = element_stresses(&mesh, &mat, s.displacement()).unwrap();
    let s1 = sig
        .iter()
        .map(max_principal_stress)
        .fold(f64::MIN, f64::max);
    line(
        "tet_bc",
        &[
            ("steps", s.steps() as f64),
            ("dt", s.dt()),
            ("time", s.time()),
            ("added_mass", s.added_mass()),
            (
                "u_v_hash",
                f64::from_bits(hash(
                    s.displacement()
                        .iter()
                        .chain(s.velocity())
                        .flatten()
                        .cloned(),
                )),
            ),
            (
                "f_int_hash",
                f64::from_bits(hash(s.internal_force().iter().flatten().cloned())),
            ),
            (
                "energy_hist_hash",
                f64::from_bits(hash(s.energy_history().iter().flat_map(|e| {
                    [
                        e.time,
                        e.kinetic,
                        e.internal,
                        e.external_work,
                        e.damping_work,
                        e.initial,
                    ]
                }))),
            ),
            ("kinetic", e.kinetic),
            ("internal", e.internal),
            ("external_work", e.external_work),
            ("damping_work", e.damping_work),
            ("rel_balance", e.relative_balance_error()),
            ("sigma1_max", s1),
        ],
    );
}

// ---- shells ----------------------------------------------------------------------------

/// Closed tube of radius `r`, length `l`, thickness `h` along z through (cx, 0):
/// `nc` nodes round, `nl` cells long, its bottom at z = z0.
fn shell_tube(nc: usize, nl: usize, r: f64, l: f64, h: f64, cx: f64, z0: f64) -> TriMesh {
    let mut nodes = Vec::new();
    for j in 0..=nl {
        for i in 0..nc {
            let a = 2.0 * PI * i as f64 / nc as f64;
            nodes.push([cx + r * a.cos(), r * a.sin(), z0 + l * j as f64 / nl as f64]);
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

fn shell_cluster_setup() -> (ShellModel, ShellExplicit) {
    let mat = glass();
    let (r, l, h) = (5.25e-3, 0.012, 1.1e-3);
    let z0 = 0.5 * h;
    let a = shell_tube(24, 6, r, l, h, 0.0, z0);
    let b = shell_tube(24, 6, r, l, h, 2.0 * r + h + 2e-6, z0);
    let mut mesh = a.clone();
    let off = a.nodes.len();
    mesh.nodes.extend_from_slice(&b.nodes);
    mesh.triangles.extend(
        b.triangles
            .iter()
            .map(|t| [t[0] + off, t[1] + off, t[2] + off]),
    );
    mesh.thickness.extend_from_slice(&b.thickness);
    let nn = mesh.nodes.len();
    let body: Vec<u32> = (0..nn).map(|i| u32::from(i >= off)).collect();
    let region: Vec<u32> = mesh.nodes.iter().map(|p| u32::from(p[2] > 6e-3)).collect();
    let model = ShellModel::new(mesh.clone(), mat).unwrap();
    let settings = ContactSettings {
        friction: 0.2,
        output_interval: 5,
        ..Default::default()
    };
    let mut c = FemContact::new_shell(&mesh, &body, &region, &mat, settings).unwrap();
    c.add_rigid(belt(0.2)).unwrap();
    let springs: Vec<NoTensionSpring> = (0..nn)
        .filter(|&i| body[i] == 0 && mesh.nodes[i][0] < -5.2e-3)
        .map(|i| {
            let p = mesh.nodes[i];
            NoTensionSpring {
                node: i,
                anchor: [p[0] - 1e-3, p[1], p[2]],
                stiffness: 1e5,
                rest_length: 1e-3,
            }
        })
        .collect();
    c.add_springs(&springs).unwrap();
    let mut s = ShellExplicit::new(&model, &[], None).unwrap();
    let mut v = vec![0.0; 6 * nn];
    for i in 0..nn {
        if body[i] == 1 {
            v[6 * i] = -0.18;
        }
    }
    s.set_initial_velocity(&dof_rows(&v).unwrap()).unwrap();
    s.add_gravity([0.0, 0.0, -9.81]).unwrap();
    s.set_contact(c).unwrap();
    (model, s)
}

fn shell_report(name: &str, model: &ShellModel, s: &ShellExplicit) {
    let c = s.contact().unwrap();
    let e = s.energy_balance();
    let ce = s.contact_energy();
    let sig = model
        .max_principal_stresses(s.displacement().as_flattened())
        .unwrap();
    let s1 = sig.iter().flatten().cloned().fold(f64::MIN, f64::max);
    let p = peaks(c.history(), c.channels().len());
    line(
        name,
        &[
            ("steps", s.steps() as f64),
            ("dt", s.dt()),
            ("time", s.time()),
            (
                "u_v_hash",
                f64::from_bits(hash(
                    s.displacement()
                        .iter()
                        .chain(s.velocity())
                        .flatten()
                        .cloned(),
                )),
            ),
            (
                "f_contact_hash",
                f64::from_bits(hash(s.contact_force().iter().flatten().cloned())),
            ),
            (
                "contact_hist_hash",
                f64::from_bits(hash(c.history().iter().cloned())),
            ),
            ("kinetic", e.kinetic),
            ("internal", e.internal),
            ("load_work", e.load_work),
            ("initial", e.initial),
            ("rel_balance", e.relative_balance_error()),
            ("c_elastic", ce.elastic),
            ("c_springs", ce.springs),
            ("c_friction", ce.friction_work),
            ("c_rigid", ce.rigid_work),
            ("c_work", ce.contact_work),
            ("peak_max", p.iter().cloned().fold(0.0, f64::max)),
            ("peak_hash", f64::from_bits(hash(p.iter().cloned()))),
            ("sigma1_max", s1),
        ],
    );
}

fn shell_cluster_fingerprint() {
    let (model, mut s) = shell_cluster_setup();
    let n = 1500;
    s.run(n / 2).unwrap();
    let saved = s.save_state();
    s.run(n / 2).unwrap();
    shell_report("shell_cluster", &model, &s);
    let (_, mut r) = shell_cluster_setup();
    r.restore_state(&saved).unwrap();
    r.run(n / 2).unwrap();
    shell_report("shell_cluster_restored", &model, &r);
}

/// A clamped square plate (fixed dofs) under a pressure and gravity, from an initial
/// displacement and velocity.
fn shell_fixed_fingerprint() {
    let mat = glass();
    let n = 6;
    let a = 0.02;
    let mesh = common::grid(n, n, 1e-3, |x, y| [a * x, a * y, 0.0]);
    let model = ShellModel::new(mesh.clone(), mat).unwrap();
    let mut fixed = Vec::new();
    for (i, p) in mesh.nodes.iter().enumerate() {
        if p[0] < 1e-12 || p[0] > a - 1e-12 || p[1] < 1e-12 || p[1] > a - 1e-12 {
            for k in 0..6 {
                fixed.push((i, k));
            }
        }
    }
    let mut s = ShellExplicit::new(&model, &fixed, None).unwrap();
    s.set_loads(
        dof_rows(&model.area_load([0.0, 0.0, -1e4])).unwrap(),
        LoadHistory::Constant,
    )
    .unwrap();
    s.add_gravity([0.0, 0.0, -9.81]).unwrap();
    let nd = 6 * mesh.nodes.len();
    let u0: Vec<f64> = (0..nd)
        .map(|d| if d % 6 == 2 { 1e-8 } else { 0.0 })
        .collect();
    s.set_initial_displacement(&dof_rows(&u0).unwrap()).unwrap();
    let v0: Vec<f64> = (0..nd)
        .map(|d| {
            if fixed.iter().any(|&(i, k)| 6 * i + k == d) || d % 6 != 2 {
                0.0
            } else {
                -1e-3
            }
        })
        .collect();
    s.set_initial_velocity(&dof_rows(&v0).unwrap()).unwrap();
    s.run(400).unwrap();
    let e = s.energy_balance();
    let sig = model
        .max_principal_stresses(s.displacement().as_flattened())
        .unwrap();
    let s1 = sig.iter().flatten().cloned().fold(f64::MIN, f64::max);
    line(
        "shell_fixed",
        &[
            ("steps", s.steps() as f64),
            ("dt", s.dt()),
            ("time", s.time()),
            (
                "u_v_hash",
                f64::from_bits(hash(
                    s.displacement()
                        .iter()
                        .chain(s.velocity())
                        .flatten()
                        .cloned(),
                )),
            ),
            ("kinetic", e.kinetic),
            ("internal", e.internal),
            ("load_work", e.load_work),
            ("initial", e.initial),
            ("rel_balance", e.relative_balance_error()),
            ("sigma1_max", s1),
        ],
    );
}

// ---- DEM and rigid bodies ----------------------------------------------------------------

fn dem_fingerprint(name: &str, law: DemLaw, steps: u64) {
    let mut scene = anchor_scene(1e8, TableStart::PackedIntoFunnel).unwrap();
    scene.threads = 2;
    scene.record_onsets = true;
    if let DemLaw::HertzReissnerMindlin = law {
        for m in scene.materials.iter_mut() {
            m.shell_stiffness =
                demfem::contact::reissner_stiffness(1e8, m.poisson_ratio, 1.1e-3, 5.25e-3).unwrap();
        }
    }
    scene.model = law;
    let mut sim = Simulation::new(&scene).unwrap();
    sim.step(steps).unwrap();
    let b = dem_support::bits(&sim);
    let h = hash(b.iter().map(|&x| f64::from_bits(x)));
    line(
        name,
        &[
            ("steps", steps as f64),
            ("state_hash", f64::from_bits(h)),
            ("contacts", sim.contacts().len() as f64),
            ("onsets", sim.onsets().len() as f64),
            ("events", sim.events().len() as f64),
        ],
    );
}

fn rigid_fingerprint() {
    use demfem::rigid::{RigidScene, RigidSceneConfig};
    use nalgebra::{UnitQuaternion, Vector3};
    let (shape, mass) = rigid_common::cartridge("clump");
    let config = RigidSceneConfig {
        planes: vec![RigidSceneConfig::belt(Vector3::new(0.2, 0.0, 0.0)).unwrap()],
        ..Default::default()
    };
    let mut scene = RigidScene::new(config).unwrap();
    let id = scene.add_shape(shape, mass).unwrap();
    for k in 0..4 {
        let x = 11.6e-3 * k as f64;
        scene
            .add_body(
                id,
                Vector3::new(x, 0.0, rigid_common::com_height()),
                UnitQuaternion::identity(),
                Vector3::new(if k == 3 { -0.1 } else { 0.0 }, 0.0, 0.0),
                Vector3::zeros(),
            )
            .unwrap();
    }
    scene.run(300).unwrap();
    let b = &scene.bodies;
    let h = hash(
        b.position
            .iter()
            .chain(&b.velocity)
            .chain(&b.angular_velocity_body)
            .flat_map(|v| [v.x, v.y, v.z])
            .chain(b.orientation.iter().flat_map(|q| [q.i, q.j, q.k, q.w])),
    );
    line(
        "rigid_cluster",
        &[
            ("steps", scene.steps() as f64),
            ("state_hash", f64::from_bits(h)),
            ("contacts", scene.contacts_last_step() as f64),
            ("elastic", scene.elastic_energy_last_step()),
        ],
    );
}

#[test]
#[ignore = "prints fingerprints to compare before and after a change; run with --ignored --nocapture"]
fn fingerprints() {
    tet_cluster_fingerprint();
    tet_bc_fingerprint();
    shell_cluster_fingerprint();
    shell_fixed_fingerprint();
    dem_fingerprint("dem_hertz_reissner", DemLaw::HertzReissnerMindlin, 1500);
    dem_fingerprint("dem_hertz_mindlin", DemLaw::HertzMindlin, 1500);
    rigid_fingerprint();
}
