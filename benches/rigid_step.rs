//! Cost of one step of N cartridges standing in a hexagonal cluster on a moving belt, as
//! 632-bead clumps, as exact parry shapes, and as their equivalent spheres, for N = 7 and 50.
//! The spheres run twice: as one-bead clumps through the same rigid-body loop
//! (`sphere_N`), and through a plain sphere loop written here (`sphere_loop_N`: same contact
//! model, Mindlin history, rotation by ω only, sort-and-sweep pairs), the cost a sphere DEM
//! would have. The paper reports that full shapes cost about two orders of magnitude more than
//! spheres; the ratios follow from the medians of one run.
use std::time::Duration;

use std::collections::HashMap;

use criterion::{criterion_group, criterion_main, Criterion};
use demfem::rigid::{
    BeadClump, ContactMaterial, ContactPoint, MassProperties, Plane, RigidContactLaw, RigidScene,
    RigidSceneConfig, RigidShape,
};
use nalgebra::{UnitQuaternion, Vector3};

#[path = "../tests/rigid_common/mod.rs"]
mod rigid_common;
use rigid_common::*;

fn equivalent_sphere() -> (RigidShape, MassProperties) {
    let m = CARTRIDGE_MASS;
    let r = (3.0 * m / (4.0 * std::f64::consts::PI * GLASS_DENSITY)).cbrt();
    let (clump, mass) = BeadClump::from_beads(&[Vector3::zeros()], &[r], &[m]).unwrap();
    (RigidShape::Clump(clump), mass)
}

/// `n` bodies on a hexagonal lattice of pitch `pitch` (m), just touching, settled for 2 ms.
fn cluster(kind: &str, n: usize) -> RigidScene {
    let (shape, mass, pitch, height) = match kind {
        "sphere" => {
            let (s, m) = equivalent_sphere();
            let r = s.bounding_radius();
            (s, m, 2.0 * r, r)
        }
        _ => {
            let (s, m) = cartridge(kind);
            (s, m, 11.6e-3, com_height())
        }
    };
    let config = RigidSceneConfig {
        planes: vec![RigidSceneConfig::belt(Vector3::new(0.2, 0.0, 0.0)).unwrap()],
        ..Default::default()
    };
    let mut scene = RigidScene::new(config).unwrap();
    let id = scene.add_shape(shape, mass).unwrap();
    let side = (n as f64).sqrt().ceil() as usize;
    for k in 0..n {
        let (i, j) = ((k % side) as f64, (k / side) as f64);
        let x = pitch * (i + 0.5 * (j % 2.0));
        let y = pitch * j * 3f64.sqrt() / 2.0;
        scene
            .add_body(
                id,
                Vector3::new(x, y, height),
                UnitQuaternion::identity(),
                Vector3::zeros(),
                Vector3::zeros(),
            )
            .unwrap();
    }
    let settle = (2e-3 / scene.time_step()) as u64;
    scene.run(settle).unwrap();
    scene
}

/// Equivalent spheres without the rigid-body machinery: velocity Verlet on x, v, ω.
struct SphereLoop {
    x: Vec<Vector3<f64>>,
    v: Vec<Vector3<f64>>,
    w: Vec<Vector3<f64>>,
    f: Vec<Vector3<f64>>,
    t: Vec<Vector3<f64>>,
    radius: f64,
    mass: f64,
    inertia: f64,
    belt: Plane,
    model: RigidContactLaw,
    dt: f64,
    history: HashMap<(usize, usize), Vector3<f64>>,
    history_next: HashMap<(usize, usize), Vector3<f64>>,
    order: Vec<(f64, usize)>,
}

impl SphereLoop {
    fn cluster(n: usize, dt: f64) -> Self {
        let m = CARTRIDGE_MASS;
        let r = (3.0 * m / (4.0 * std::f64::consts::PI * GLASS_DENSITY)).cbrt();
        let side = (n as f64).sqrt().ceil() as usize;
        let x = (0..n)
            .map(|k| {
                let (i, j) = ((k % side) as f64, (k / side) as f64);
                Vector3::new(
                    2.0 * r * (i + 0.5 * (j % 2.0)),
                    2.0 * r * j * 3f64.sqrt() / 2.0,
                    r,
                )
            })
            .collect();
        let model = RigidContactLaw::new(
            ContactMaterial::PAPER_GLASS,
            ContactMaterial::PAPER_GLASS,
            0.5,
            0.2,
        )
        .unwrap();
        let mut s = Self {
            x,
            v: vec![Vector3::zeros(); n],
            w: vec![Vector3::zeros(); n],
            f: vec![Vector3::zeros(); n],
            t: vec![Vector3::zeros(); n],
            radius: r,
            mass: m,
            inertia: 0.4 * m * r * r,
            belt: RigidSceneConfig::belt(Vector3::new(0.2, 0.0, 0.0)).unwrap(),
            model,
            dt,
            history: HashMap::new(),
            history_next: HashMap::new(),
            order: Vec::new(),
        };
        s.forces();
        s
    }

    fn forces(&mut self) {
        let (r, dt) = (self.radius, self.dt);
        let mut history = std::mem::take(&mut self.history);
        let mut next = std::mem::take(&mut self.history_next);
        next.clear();
        for i in 0..self.x.len() {
            self.f[i] = Vector3::new(0.0, 0.0, -9.81 * self.mass);
            self.t[i] = Vector3::zeros();
            let overlap = r - self.belt.signed_distance(&self.x[i]);
            if overlap > 0.0 {
                let n = self.belt.normal;
                let c = ContactPoint {
                    point: self.x[i] - n * (r - 0.5 * overlap),
                    normal: n,
                    overlap,
                    radius_first: f64::INFINITY,
                    radius_second: r,
                    feature_first: 0,
                    feature_second: 0,
                };
                let rel = self.v[i] + self.w[i].cross(&(c.point - self.x[i]))
                    - self.belt.surface_velocity;
                let mut xi = history
                    .remove(&(usize::MAX, i))
                    .unwrap_or_else(Vector3::zeros);
                let f = self
                    .model
                    .force(
                        &c,
                        &rel,
                        self.mass,
                        self.model.e_star_body_plane,
                        &mut xi,
                        dt,
                    )
                    .unwrap();
                next.insert((usize::MAX, i), xi);
                self.f[i] += f;
                self.t[i] += (c.point - self.x[i]).cross(&f);
            }
        }
        self.order.clear();
        self.order
            .extend(self.x.iter().enumerate().map(|(i, x)| (x.x - r, i)));
        self.order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        for k in 0..self.order.len() {
            let (lower_a, a) = self.order[k];
            for &(lower_b, b) in &self.order[k + 1..] {
                if lower_b >= lower_a + 2.0 * r {
                    break;
                }
                let d = self.x[b] - self.x[a];
                let dist = d.norm();
                if dist >= 2.0 * r {
                    continue;
                }
                let n = d / dist;
                let overlap = 2.0 * r - dist;
                let point = self.x[a] + n * (r - 0.5 * overlap);
                let c = ContactPoint {
                    point,
                    normal: n,
                    overlap,
                    radius_first: r,
                    radius_second: r,
                    feature_first: 0,
                    feature_second: 0,
                };
                let rel = self.v[b] + self.w[b].cross(&(point - self.x[b]))
                    - self.v[a]
                    - self.w[a].cross(&(point - self.x[a]));
                let key = (a.min(b), a.max(b));
                let mut xi = history.remove(&key).unwrap_or_else(Vector3::zeros);
                let f = self
                    .model
                    .force(
                        &c,
                        &rel,
                        0.5 * self.mass,
                        self.model.e_star_body_body,
                        &mut xi,
                        dt,
                    )
                    .unwrap();
                next.insert(key, xi);
                self.f[b] += f;
                self.f[a] -= f;
                self.t[b] += (point - self.x[b]).cross(&f);
                self.t[a] -= (point - self.x[a]).cross(&f);
            }
        }
        self.history = next;
        self.history_next = history;
    }

    fn step(&mut self) {
        let h = self.dt;
        for i in 0..self.x.len() {
            self.v[i] += self.f[i] * (0.5 * h / self.mass);
            self.w[i] += self.t[i] * (0.5 * h / self.inertia);
            self.x[i] += self.v[i] * h;
        }
        self.forces();
        for i in 0..self.x.len() {
            self.v[i] += self.f[i] * (0.5 * h / self.mass);
            self.w[i] += self.t[i] * (0.5 * h / self.inertia);
        }
    }
}

fn bench_rigid_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("rigid_step");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    for n in [7usize, 50] {
        let dt = cluster("sphere", 1).time_step();
        let mut spheres = SphereLoop::cluster(n, dt);
        for _ in 0..(2e-3 / dt) as usize {
            spheres.step();
        }
        group.bench_function(format!("sphere_loop_{n}"), |b| b.iter(|| spheres.step()));
        for kind in ["sphere", "exact", "clump"] {
            let mut scene = cluster(kind, n);
            println!(
                "{kind} n={n}: dt {:.3e} s, {} contacts",
                scene.time_step(),
                scene.contacts_last_step()
            );
            group.bench_function(format!("{kind}_{n}"), |b| b.iter(|| scene.run(1).unwrap()));
        }
    }
    group.finish();
}

criterion_group!(benches, bench_rigid_step);
criterion_main!(benches);
