//! Threads and restarts must not change results: 1 and 2 threads give bitwise identical
//! states, and a run restored from a checkpoint continues bitwise identically to an
//! uninterrupted one (tangential history included); the AVX2 and baseline builds of the
//! step kernels agree bitwise, and so do the batched and the one-contact-at-a-time kernels.

mod dem_support;
use dem_support::bits;

use demfem::contact::reissner_stiffness;
use demfem::dem::table::{anchor_scene, TableStart};
use demfem::dem::{
    DemContactLaw, Effect, EffectSet, Material, ParticleInit, Partner, Scene, Simulation,
};
use demfem::geometry::{Vec3, WallMotion};

/// The packed anchor table (840 spheres, above the parallel threshold) at E = 1e8 Pa so that
/// 3000 steps see real contact dynamics (belt drag, friction, collisions with the funnel).
fn packed_soft(threads: usize) -> Simulation {
    let mut scene = anchor_scene(1e8, TableStart::PackedIntoFunnel).unwrap();
    scene.threads = threads;
    scene.record_onsets = true;
    Simulation::new(&scene).unwrap()
}

/// The same table with the studies' law: Hertz in series with the Reissner shell of the
/// default cartridge body (t = 1.1 mm, R = 5.25 mm) on every material, Mindlin tangential.
fn packed_soft_hertz_reissner(threads: usize) -> Simulation {
    let mut scene = anchor_scene(1e8, TableStart::PackedIntoFunnel).unwrap();
    scene.threads = threads;
    scene.record_onsets = true;
    scene.model = DemContactLaw::HertzReissnerMindlin;
    for m in scene.materials.iter_mut() {
        m.shell_stiffness = reissner_stiffness(1e8, m.poisson_ratio, 1.1e-3, 5.25e-3).unwrap();
    }
    Simulation::new(&scene).unwrap()
}

#[test]
fn hertz_reissner_one_and_two_threads_are_bitwise_identical_and_restart_exactly() {
    let mut a = packed_soft_hertz_reissner(1);
    let mut b = packed_soft_hertz_reissner(2);
    a.step(1500).unwrap();
    b.step(1500).unwrap();
    assert!(
        a.contacts().len() > 500,
        "too few contacts: {}",
        a.contacts().len()
    );
    assert_eq!(bits(&a), bits(&b));
    let dir = std::env::temp_dir().join(format!("demfem-ck-hr-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("state.ck");
    a.save_checkpoint(&path).unwrap();
    a.step(1500).unwrap();
    b.step(1500).unwrap();
    let mut restarted = packed_soft_hertz_reissner(2);
    restarted.load_checkpoint(&path).unwrap();
    restarted.step(1500).unwrap();
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(bits(&a), bits(&restarted));
    assert_eq!(a.onsets(), b.onsets());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn one_and_two_threads_are_bitwise_identical() {
    let mut a = packed_soft(1);
    let mut b = packed_soft(2);
    a.step(3000).unwrap();
    b.step(3000).unwrap();
    assert!(
        a.contacts().len() > 500,
        "the test needs many contacts: {}",
        a.contacts().len()
    );
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(a.onsets(), b.onsets());
    assert!(!a.onsets().is_empty());
    // three blocks of particles (more threads than cores is allowed) cut the lists elsewhere
    let mut c = packed_soft(3);
    c.step(3000).unwrap();
    assert!(bits(&a) == bits(&c), "3 threads differ from 1");
    assert_eq!(a.onsets(), c.onsets());
}

#[test]
fn the_phase_clock_reads_each_threads_time_and_changes_nothing() {
    let mut a = packed_soft(2);
    let mut b = packed_soft(2);
    assert!(b.phase_times().is_empty(), "the clock is off by default");
    b.set_phase_timing(true);
    let start = std::time::Instant::now();
    a.step(500).unwrap();
    b.step(500).unwrap();
    let elapsed = start.elapsed().as_secs_f64();
    assert_eq!(bits(&a), bits(&b), "the clock changed the results");
    let times = b.phase_times();
    assert_eq!(times.len(), 2, "one entry per thread");
    for [force, particle] in &times {
        // each phase ran on every step, and no phase took longer than the two runs together
        assert!(
            *force > 0.0 && *force < elapsed,
            "force phase {force} s of {elapsed} s"
        );
        assert!(
            *particle > 0.0 && *particle < elapsed,
            "particle phase {particle} s of {elapsed} s"
        );
    }
    // restarting the clock starts from zero; turning it off empties it
    b.set_phase_timing(true);
    assert!(b.phase_times().iter().all(|t| t == &[0.0, 0.0]));
    b.set_phase_timing(false);
    assert!(b.phase_times().is_empty());
    // one thread: one entry, both phases timed
    let mut c = packed_soft(1);
    c.set_phase_timing(true);
    c.step(100).unwrap();
    let one = c.phase_times();
    assert_eq!(one.len(), 1);
    assert!(one[0][0] > 0.0 && one[0][1] > 0.0, "{one:?}");
}

#[test]
fn avx2_and_baseline_kernels_are_bitwise_identical() {
    let mut a = packed_soft(1);
    let mut b = packed_soft(2);
    a.set_avx2(false);
    let simd = b.set_avx2(true);
    assert!(!a.uses_avx2());
    if !simd {
        eprintln!("this CPU has no AVX2: only the baseline build can run here");
    }
    a.step(3000).unwrap();
    b.step(3000).unwrap();
    assert!(a.contacts().len() > 500);
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(a.onsets(), b.onsets());
}

/// The AVX2 particle update (four particles per instruction) and the plane pass agree with
/// the baseline build with the other effect sets that change them: `planar` (ω about x, y held
/// at zero) and rolling resistance (one-at-a-time pair kernels, generic step), with a few
/// particles removed.
#[test]
fn avx2_and_baseline_agree_with_planar_and_rolling_resistance() {
    let build = |effect: Effect| {
        let mut scene = anchor_scene(1e8, TableStart::PackedIntoFunnel).unwrap();
        scene.threads = 2;
        scene.record_onsets = true;
        scene.effects = scene.effects.with(effect);
        if effect == Effect::RollingResistance {
            scene.materials[0].rolling_friction = 0.01;
        }
        for w in scene.particles.angular_velocity.iter_mut() {
            *w = Vec3::new(0.0, 0.0, 3.0);
        }
        Simulation::new(&scene).unwrap()
    };
    for effect in [Effect::Planar, Effect::RollingResistance] {
        let mut a = build(effect);
        let mut b = build(effect);
        a.set_avx2(false);
        b.set_avx2(true);
        // removed particles break groups of four: those go one at a time
        for sim in [&mut a, &mut b] {
            for i in [5, 6, 101, 402] {
                sim.remove_particle(i).unwrap();
            }
        }
        a.step(1500).unwrap();
        b.step(1500).unwrap();
        assert!(a.contacts().len() > 500, "{effect:?}: too few contacts");
        assert_eq!(bits(&a), bits(&b), "{effect:?}");
        assert_eq!(a.onsets(), b.onsets(), "{effect:?}");
        if effect == Effect::Planar {
            assert!(b
                .angular_velocities()
                .iter()
                .all(|w| w.x == 0.0 && w.y == 0.0));
        }
    }
}

/// Which wall slots the batched kernels take is listed once per neighbour list and kernel
/// mode (`list_wall_slots`): switching the kernels mid-run, and removing particles mid-run,
/// must relist them, so the run stays bitwise that of an uninterrupted one.
#[test]
fn switching_kernels_and_removing_particles_mid_run_relists_the_wall_slots() {
    let mut a = packed_soft(2);
    let mut b = packed_soft(2);
    a.step(400).unwrap();
    b.step(400).unwrap();
    assert!(b.plane_pass_slots() > 500, "{}", b.plane_pass_slots());
    b.set_batched(false);
    for sim in [&mut a, &mut b] {
        sim.step(300).unwrap();
        // breaks groups of four of the plane pass
        for i in [9, 10, 333] {
            sim.remove_particle(i).unwrap();
        }
        sim.step(300).unwrap();
    }
    assert_eq!(b.plane_pass_slots(), 0);
    b.set_batched(true);
    b.set_avx2(false);
    a.step(300).unwrap();
    b.step(300).unwrap();
    assert_eq!(b.plane_pass_slots(), 0);
    b.set_avx2(true);
    a.step(300).unwrap();
    b.step(300).unwrap();
    if b.uses_avx2() {
        assert!(b.plane_pass_slots() > 500, "{}", b.plane_pass_slots());
    }
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(a.onsets(), b.onsets());
}

/// The batched kernels (several contacts in flight, four per AVX2 instruction in the force
/// pass) reproduce the one-at-a-time reference kernels bit for bit, on both builds, with the
/// Hertz–Mindlin and the Hertz–Reissner laws, and with a generic effect set (an oscillating
/// funnel wall: `moving_walls` is not one of the specialised sets).
#[test]
fn batched_and_one_at_a_time_kernels_are_bitwise_identical() {
    let oscillating = || {
        let mut scene = anchor_scene(1e8, TableStart::PackedIntoFunnel).unwrap();
        scene.threads = 2;
        scene.record_onsets = true;
        scene.effects = scene.effects.with(Effect::MovingWalls);
        // the first funnel strip swings ±4 mm across the belt every 0.05 s, and the belt
        // itself (a plane, so the AVX2 plane pass with a wall offset and velocity) shakes
        // ±0.1 mm vertically every 0.02 s
        scene.walls[4].motion = WallMotion::harmonic(Vec3::Y, 4e-3, 0.05, 0.0).unwrap();
        scene.walls[0].motion = WallMotion::harmonic(Vec3::Z, 1e-4, 0.02, 0.0).unwrap();
        Simulation::new(&scene).unwrap()
    };
    // radii 0–7 % smaller than the anchors' (no start overlaps): every pair and belt slot
    // has its own law constants, so neither kernel takes its uniform path
    let polydisperse = || {
        let mut scene = anchor_scene(1e8, TableStart::PackedIntoFunnel).unwrap();
        scene.threads = 2;
        scene.record_onsets = true;
        for (i, r) in scene.particles.radius.iter_mut().enumerate() {
            *r *= 1.0 - 0.07 * ((i * 7919) % 13) as f64 / 13.0;
        }
        Simulation::new(&scene).unwrap()
    };
    // the uniform pair kernel reads spins and springs from the particles' and pairs' rows
    // only with the effects that use them: without rotation, and without friction (whose
    // pairs keep a zero spring)
    let without = |effect: Effect| {
        move || {
            let mut scene = anchor_scene(1e8, TableStart::PackedIntoFunnel).unwrap();
            scene.threads = 2;
            scene.record_onsets = true;
            scene.effects = scene.effects.without(effect);
            if effect == Effect::Friction {
                for m in scene.materials.iter_mut() {
                    m.friction = 0.0;
                }
            }
            Simulation::new(&scene).unwrap()
        }
    };
    type Build = Box<dyn Fn() -> Simulation>;
    let scenes: [(&str, Build); 6] = [
        ("Hertz-Mindlin", Box::new(|| packed_soft(2))),
        ("Hertz-Reissner", Box::new(|| packed_soft_hertz_reissner(1))),
        ("moving walls", Box::new(oscillating)),
        ("polydisperse", Box::new(polydisperse)),
        ("no rotation", Box::new(without(Effect::Rotation))),
        ("frictionless", Box::new(without(Effect::Friction))),
    ];
    for (name, build) in scenes {
        for avx2 in [false, true] {
            let mut reference = build();
            reference.set_batched(false);
            reference.set_avx2(avx2);
            let mut batched = build();
            batched.set_avx2(avx2);
            assert!(batched.uses_batches() && !reference.uses_batches());
            // equal spheres of one material take the uniform pair path with AVX2 (the
            // Hertz–Reissner one evaluating its law in the lanes)
            let uniform = batched.uses_avx2() && name != "polydisperse";
            assert_eq!(batched.uniform_pairs(), uniform, "{name}, AVX2 {avx2}");
            for _ in 0..4 {
                reference.step(500).unwrap();
                batched.step(500).unwrap();
                let (r, b) = (bits(&reference), bits(&batched));
                let first = r.iter().zip(&b).position(|(x, y)| x != y);
                assert!(
                    first.is_none(),
                    "{name}, AVX2 {avx2}: value {first:?} differs"
                );
            }
            // the AVX2 batched step takes the belt slots four particles at a time (Hertz or
            // Hertz–Reissner constants), so the comparison covers that pass too
            let planes = batched.plane_pass_slots();
            if batched.uses_avx2() {
                assert!(planes > 500, "{name}: plane pass took {planes} slots");
            } else {
                assert_eq!(planes, 0, "{name}, AVX2 {avx2}");
            }
            assert_eq!(reference.plane_pass_slots(), 0);
            // the batched kernel skips pairs that cannot touch yet; the reference tests all
            assert!(
                batched.sleeping_pairs() > 20,
                "{name}: {} pairs skipped",
                batched.sleeping_pairs()
            );
            assert!(reference.contacts().len() > 500, "{name}: too few contacts");
            assert_eq!(reference.contacts(), batched.contacts(), "{name}");
            assert_eq!(reference.onsets(), batched.onsets(), "{name}");
            assert!(!reference.onsets().is_empty(), "{name}: no onsets");
        }
    }
}

#[test]
fn restart_from_checkpoint_is_bitwise_identical() {
    let dir = std::env::temp_dir().join(format!("demfem-ck-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("state.ck");
    let mut reference = packed_soft(1);
    reference.step(1500).unwrap();
    reference.save_checkpoint(&path).unwrap();
    reference.step(1500).unwrap();

    let mut restarted = packed_soft(2);
    restarted.load_checkpoint(&path).unwrap();
    assert_eq!(restarted.steps(), 1500);
    restarted.step(1500).unwrap();
    assert_eq!(bits(&reference), bits(&restarted));
    // the history survived: some contact is sticking with a non-zero tangential force
    assert!(restarted
        .contacts()
        .iter()
        .any(|c| c.tangential_force.length() > 0.0));
    assert!(
        !path.with_extension("ck.tmp").exists(),
        "temp file left behind"
    );

    // a checkpoint from another scene is refused
    let mut other_scene = anchor_scene(2e8, TableStart::PackedIntoFunnel).unwrap();
    other_scene.threads = 1;
    let mut other = Simulation::new(&other_scene).unwrap();
    assert!(other.load_checkpoint(&path).is_err());
    std::fs::remove_dir_all(&dir).ok();
}

/// The batched pair kernel skips a pair out of contact while neither sphere can have moved
/// half its gap (the travel bound, `Simulation::sleeping_pairs`). A 5 m/s sphere fired down
/// a row of resting spheres, with a skin wide enough that every gap of the row is a
/// candidate pair from the first step, hits each sphere at the same step as the one-at-a-time
/// kernels (which test every pair every step), and the runs end bitwise equal; the spheres
/// that were at rest when their pairs went to sleep are woken by the travel of the fast one.
#[test]
fn skipped_pairs_touch_at_the_same_step_as_tested_pairs() {
    let build = || {
        let r = 8e-3;
        // gaps 14, 1, 1.5 and 3 mm along x, off-centre in y (oblique hits), and one sphere
        // 60 mm to the side that nothing reaches
        let position = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.030, 1e-3, 0.0),
            Vec3::new(0.047, -1e-3, 0.5e-3),
            Vec3::new(0.0645, 0.0, 0.0),
            Vec3::new(0.0835, 2e-3, 0.0),
            Vec3::new(0.047, 0.060, 0.0),
        ];
        let n = position.len();
        let mut p = ParticleInit::at_rest(position, vec![r; n]);
        p.velocity[0] = Vec3::new(5.0, 0.0, 0.0);
        let glass = Material::new(1e9, 0.22, 2230.0, 0.2, 0.9, 0.0);
        let effects = EffectSet::of(&[Effect::Friction, Effect::Rotation, Effect::Damping]);
        let mut scene = Scene::new(p, vec![glass], vec![], effects);
        scene.gravity = Vec3::ZERO;
        scene.expected_max_speed = 5.0;
        scene.skin = Some(0.02);
        scene.record_onsets = true;
        Simulation::new(&scene).unwrap()
    };
    let mut reference = build();
    reference.set_batched(false);
    let mut batched = build();
    let mut slept = 0;
    for _ in 0..40 {
        reference.step(100).unwrap();
        batched.step(100).unwrap();
        slept = slept.max(batched.sleeping_pairs());
        assert_eq!(
            bits(&reference),
            bits(&batched),
            "at step {}",
            batched.steps()
        );
    }
    assert_eq!(reference.onsets(), batched.onsets());
    assert!(slept >= 5, "at most {slept} pairs skipped");
    // every sphere of the row was hit, the one to the side never
    let hit: Vec<u32> = batched
        .onsets()
        .iter()
        .filter_map(|o| match o.partner {
            Partner::Particle(j) => Some(j),
            Partner::Wall(_) => None,
        })
        .collect();
    for j in 1..5 {
        assert!(hit.contains(&j), "sphere {j} never hit: {hit:?}");
    }
    assert!(!hit.contains(&5));
}
