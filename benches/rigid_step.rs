//! Cost of one step of N cartridges standing in a hexagonal cluster on a moving belt, as
//! 632-bead clumps, as exact parry shapes, and as their equivalent spheres (a one-bead clump
//! of the same mass through the same loop), for N = 7 and 50. The paper reports that full
//! shapes cost about two orders of magnitude more than spheres; the ratio printed by this
//! bench is measured here, in one run.
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use demfem::rigid::{BeadClump, MassProperties, RigidScene, RigidSceneConfig, RigidShape};
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
            .add_body(id, Vector3::new(x, y, height), UnitQuaternion::identity(), Vector3::zeros(), Vector3::zeros())
            .unwrap();
    }
    let settle = (2e-3 / scene.time_step()) as u64;
    scene.run(settle).unwrap();
    scene
}

fn bench_rigid_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("rigid_step");
    group.sample_size(10).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(2));
    for n in [7usize, 50] {
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
