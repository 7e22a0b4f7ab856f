//! Particle-steps per second of the anchor accumulation table (840 glass spheres, d = 16 mm,
//! E = 45 GPa, Hertz–Mindlin, μ = 0.2, e = 0.5, belt 0.2 m/s, funnel; dt = 0.5 r √(ρ/E), the
//! anchors' step) in a packed state, on 1 and 2 threads, and what each effect costs; and the
//! same state under the studies' series law (Hertz–Reissner–Mindlin), evaluated four contacts
//! per AVX2 instruction, against the one-contact-at-a-time kernel.
//!
//! The packed state is made once: spheres start in a dense hexagonal packing against the
//! closed funnel, moving at the belt speed, and run `SETTLE_STEPS`; its checkpoint is then
//! restored into simulations with 1 and 2 threads (a checkpoint does not depend on threads).
//!
//! Run: `CARGO_TARGET_DIR=/work/target-dem cargo bench --bench dem_step`. Criterion reports
//! time per iteration of `STEPS_PER_ITER` steps and the throughput in "elements" =
//! particle-steps.
use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, Throughput};
use demfem::contact::reissner_stiffness;
use demfem::dem::table::{anchor_scene, TableStart};
use demfem::dem::{DemContactLaw, Effect, Scene, Simulation};
use demfem::geometry::Vec3;
use std::time::Duration;

const SETTLE_STEPS: u64 = 60_000;
const STEPS_PER_ITER: u64 = 200;

fn packed_scene() -> (Scene, Vec<u8>) {
    let mut scene = anchor_scene(45e9, TableStart::PackedIntoFunnel).expect("anchor scene");
    for v in scene.particles.velocity.iter_mut() {
        v.x = 0.2;
    }
    let mut sim = Simulation::new(&scene).expect("simulation");
    sim.step(SETTLE_STEPS).expect("settle");
    let z: u32 = sim.coordination().iter().sum();
    eprintln!(
        "packed state: t = {:.4} s, mean coordination {:.2}, {} spheres riding up, max overlap {:.2e} m",
        sim.time(),
        z as f64 / sim.len() as f64,
        sim.riding_up_count(0.0, 0.002),
        sim.max_overlap()
    );
    let bytes = sim.checkpoint_bytes();
    // the settled state as initial conditions, for scenes with other effects
    scene.particles.position = sim.positions().to_vec();
    scene.particles.velocity = sim.velocities().to_vec();
    scene.particles.angular_velocity = sim.angular_velocities().to_vec();
    (scene, bytes)
}

/// A group of 10 samples of `STEPS_PER_ITER` steps of the 840 spheres, throughput in
/// particle-steps, warmed up for `warm_up_ms` and measured for `measure_s`.
fn group<'c>(
    c: &'c mut Criterion,
    name: &str,
    warm_up_ms: u64,
    measure_s: u64,
) -> BenchmarkGroup<'c, WallTime> {
    let mut g = c.benchmark_group(name);
    g.throughput(Throughput::Elements(840 * STEPS_PER_ITER));
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(warm_up_ms))
        .measurement_time(Duration::from_secs(measure_s));
    g
}

fn bench_threads(c: &mut Criterion, bytes: &[u8]) {
    let mut g = group(c, "anchor_table_packed_45GPa", 1000, 4);
    for (threads, avx2, batched) in [
        (1usize, true, true),
        (2, true, true),
        (1, false, true),
        (1, true, false),
    ] {
        // restore the exact packed state (history included) rather than the copied initial data
        let mut sim = {
            let mut fresh = anchor_scene(45e9, TableStart::PackedIntoFunnel).expect("scene");
            for v in fresh.particles.velocity.iter_mut() {
                v.x = 0.2;
            }
            fresh.threads = threads;
            let mut sim = Simulation::new(&fresh).expect("simulation");
            sim.restore_checkpoint_bytes(bytes, "packed")
                .expect("restore");
            sim
        };
        // the AVX2 build of the kernels where the CPU has it; the baseline build for comparison
        let simd = sim.set_avx2(avx2);
        // batched contact kernels, or the one-at-a-time reference kernels for comparison
        sim.set_batched(batched);
        let name = match (avx2, batched) {
            (true, true) => format!("threads_{threads}"),
            (false, _) => format!("threads_{threads}_baseline_no_avx2"),
            (true, false) => format!("threads_{threads}_one_contact_at_a_time"),
        };
        if avx2 && !simd {
            eprintln!("no AVX2 on this CPU: {name} runs the baseline build");
        }
        g.bench_function(name, |b| b.iter(|| sim.step(STEPS_PER_ITER).expect("step")));
    }
    g.finish();
}

fn bench_effects(c: &mut Criterion, scene: &Scene) {
    let mut g = group(c, "effect_cost_1_thread", 500, 2);
    let variants: Vec<(&str, Box<dyn Fn(&mut Scene)>)> = vec![
        ("all_table_effects", Box::new(|_s: &mut Scene| {})),
        (
            "without_rotation",
            Box::new(|s: &mut Scene| {
                s.effects = s.effects.without(Effect::Rotation);
                s.particles
                    .angular_velocity
                    .iter_mut()
                    .for_each(|w| *w = Vec3::ZERO);
            }),
        ),
        (
            "without_friction",
            Box::new(|s: &mut Scene| {
                s.effects = s.effects.without(Effect::Friction);
                s.materials[0].friction = 0.0;
            }),
        ),
        (
            "without_damping",
            Box::new(|s: &mut Scene| {
                s.effects = s.effects.without(Effect::Damping);
                s.materials[0].restitution = 1.0;
            }),
        ),
        (
            "without_belt",
            Box::new(|s: &mut Scene| {
                s.effects = s.effects.without(Effect::Belt);
                s.walls[0].surface_velocity = Vec3::ZERO;
            }),
        ),
        (
            "plus_planar",
            Box::new(|s: &mut Scene| {
                s.effects = s.effects.with(Effect::Planar);
                s.particles.angular_velocity.iter_mut().for_each(|w| {
                    w.x = 0.0;
                    w.y = 0.0
                });
            }),
        ),
        (
            "plus_rolling_resistance",
            Box::new(|s: &mut Scene| {
                s.effects = s.effects.with(Effect::RollingResistance);
                s.materials[0].rolling_friction = 0.01;
            }),
        ),
        (
            "plus_onset_log",
            Box::new(|s: &mut Scene| s.record_onsets = true),
        ),
    ];
    for (name, change) in variants {
        let mut s = scene.clone();
        s.threads = 1;
        change(&mut s);
        let mut sim = Simulation::new(&s).expect("variant");
        g.bench_function(name, |b| b.iter(|| sim.step(STEPS_PER_ITER).expect("step")));
    }
    g.finish();
}

/// The packed state under the studies' law: Hertz in series with the Reissner shell of the
/// default cartridge body (t = 1.1 mm, R = 5.25 mm), one thread. `lanes`: the batched AVX2
/// kernels, which evaluate the law four contacts per instruction; `one_contact_at_a_time`:
/// the reference kernels; `hertz_mindlin`: the same state without the shell, for scale.
fn bench_series_law(c: &mut Criterion, scene: &Scene) {
    let mut g = group(c, "series_law_packed_45GPa", 1000, 4);
    for (name, series, batched) in [
        ("lanes", true, true),
        ("one_contact_at_a_time", true, false),
        ("hertz_mindlin", false, true),
    ] {
        let mut s = scene.clone();
        s.threads = 1;
        if series {
            s.model = DemContactLaw::HertzReissnerMindlin;
            for m in s.materials.iter_mut() {
                m.shell_stiffness =
                    reissner_stiffness(m.young_modulus, m.poisson_ratio, 1.1e-3, 5.25e-3)
                        .expect("shell stiffness");
            }
        }
        let mut sim = Simulation::new(&s).expect("series-law scene");
        sim.set_batched(batched);
        g.bench_function(name, |b| b.iter(|| sim.step(STEPS_PER_ITER).expect("step")));
    }
    g.finish();
}

fn benches(c: &mut Criterion) {
    let (scene, bytes) = packed_scene();
    bench_threads(c, &bytes);
    bench_effects(c, &scene);
    bench_series_law(c, &scene);
}

criterion_group!(dem, benches);
criterion_main!(dem);
