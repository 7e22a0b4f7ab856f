//! Whole-contact event records (`Scene::record_events`), against closed forms and against the
//! run without them: a head-on Hertz impact of two spheres and a sphere on a wall give the
//! Hertz peak force and contact time (Johnson §11.4) and the impulse m*(1 + e) v that momentum
//! fixes; recording changes no trajectory bit; events are the same on 1 and 2 threads and
//! after a restart from a checkpoint taken while contacts are open.

mod dem_support;
use dem_support::*;

use demfem::dem::table::{anchor_scene, TableStart};
use demfem::dem::{ContactEvent, Effect, EffectSet, ParticleInit, Partner, Scene, Simulation};
use demfem::geometry::Vec3;

/// Two equal spheres closing head-on at `v` (each at v/2), no walls, no gravity.
fn head_on(e: f64, rest: f64, v: f64) -> (Scene, f64, f64) {
    let (r, rho) = (0.008, 2230.0);
    let mut p = ParticleInit::at_rest(
        vec![
            Vec3::new(-r - 1e-6, 0.0, 0.0),
            Vec3::new(r + 1e-6, 0.0, 0.0),
        ],
        vec![r, r],
    );
    p.velocity = vec![Vec3::new(0.5 * v, 0.0, 0.0), Vec3::new(-0.5 * v, 0.0, 0.0)];
    let effects = if rest < 1.0 {
        EffectSet::of(&[Effect::Damping])
    } else {
        EffectSet::empty()
    };
    let mut scene = Scene::new(p, vec![material(e, 0.22, rho, 0.0, rest)], vec![], effects);
    scene.gravity = Vec3::ZERO;
    scene.record_events = true;
    let m = sphere_mass(rho, r);
    (scene, m, r)
}

fn run_until_apart(sim: &mut Simulation, max_steps: u64) {
    for _ in 0..max_steps {
        sim.step(50).unwrap();
        if !sim.events().is_empty() {
            return;
        }
    }
    panic!("the contact did not end");
}

#[test]
fn head_on_impact_event_matches_hertz_and_momentum() {
    let (e, v) = (45e9, 0.2);
    let (mut scene, m, r) = head_on(e, 1.0, v);
    let (_, f_th, t_th) = hertz_impact(e_star(e, 0.22, e, 0.22), 0.5 * r, 0.5 * m, v);
    scene.time_step = Some(t_th / 2000.0);
    let mut sim = Simulation::new(&scene).unwrap();
    run_until_apart(&mut sim, 100_000);
    let ev: ContactEvent = sim.events()[0];
    assert_eq!(sim.events().len(), 1);
    assert_eq!((ev.particle, ev.partner), (0, Partner::Particle(1)));
    assert!(ev.complete);
    assert!(
        (ev.normal_speed / v - 1.0).abs() < 1e-3,
        "onset speed {}",
        ev.normal_speed
    );
    // Hertz: F_max and t_c to the step's resolution (2.868 is Johnson's rounded constant)
    assert!(
        (ev.peak_normal_force / f_th - 1.0).abs() < 2e-3,
        "F {} vs {f_th}",
        ev.peak_normal_force
    );
    assert!(
        (ev.duration / t_th - 1.0).abs() < 3e-3,
        "t_c {} vs {t_th}",
        ev.duration
    );
    // elastic: the impulse reverses the relative momentum, m* (1 + e) v with m* = m/2
    let j_th = 0.5 * m * 2.0 * v;
    assert!(
        (ev.normal_impulse / j_th - 1.0).abs() < 1e-3,
        "J {} vs {j_th}",
        ev.normal_impulse
    );
    assert!(ev.max_overlap > 0.0 && ev.peak_tangential_force.abs() < 1e-12);
}

#[test]
fn damped_wall_impact_impulse_is_m_one_plus_e_v() {
    let (e, rest, v, r, rho) = (45e9, 0.5, 0.3, 0.008, 2230.0);
    let mut scene = sphere_on_floor(
        r,
        r + 1e-6,
        Vec3::new(0.0, 0.0, -v),
        Vec3::ZERO,
        vec![material(e, 0.22, rho, 0.0, rest), rigid(0.22, 0.0, rest)],
        EffectSet::of(&[Effect::Damping]),
    );
    scene.record_events = true;
    let m = sphere_mass(rho, r);
    let (_, _, t_th) = hertz_impact(e_star(e, 0.22, 1e21, 0.22), r, m, v);
    scene.time_step = Some(t_th / 2000.0);
    let mut sim = Simulation::new(&scene).unwrap();
    run_until_apart(&mut sim, 100_000);
    let ev = sim.events()[0];
    assert_eq!(ev.partner, Partner::Wall(0));
    let v_out = sim.velocities()[0].z;
    // the impulse is the momentum change the integrator made, and e sets it: m (1 + e) v
    assert!((ev.normal_impulse / (m * (v + v_out)) - 1.0).abs() < 2e-3);
    assert!(
        (ev.normal_impulse / (m * (1.0 + rest) * v) - 1.0).abs() < 5e-3,
        "J {}",
        ev.normal_impulse
    );
    assert!(
        (ev.partner_position.z).abs() < 1e-9,
        "contact point on the wall"
    );
}

fn packed(threads: usize, events: bool) -> Simulation {
    let mut scene = anchor_scene(1e8, TableStart::PackedIntoFunnel).unwrap();
    scene.threads = threads;
    scene.record_onsets = true;
    scene.record_events = events;
    Simulation::new(&scene).unwrap()
}

#[test]
fn recording_events_changes_no_bit_and_matches_the_onsets() {
    let mut plain = packed(1, false);
    let mut rec = packed(1, true);
    plain.step(2000).unwrap();
    rec.step(2000).unwrap();
    assert_eq!(bits(&plain), bits(&rec));
    assert!(plain.events().is_empty() && plain.open_events().is_empty());
    // every ended contact began within the run (or was open at t = 0), and every onset is
    // either an ended event or still open
    let ended = rec.events().len();
    let open = rec.open_events().len();
    assert!(ended > 100, "too few events: {ended}");
    let at_start = rec
        .events()
        .iter()
        .chain(&rec.open_events())
        .filter(|e| e.time == 0.0)
        .count();
    assert_eq!(
        ended + open,
        rec.onsets().len(),
        "{ended} + {open} vs onsets (start: {at_start})"
    );
    for e in rec.events() {
        assert!(e.duration > 0.0 && e.peak_normal_force >= 0.0 && e.normal_impulse >= 0.0);
        assert!(e.normal_impulse <= e.peak_normal_force * e.duration * (1.0 + 1e-12));
    }
}

#[test]
fn events_are_the_same_on_two_threads_and_after_a_restart() {
    let mut a = packed(1, true);
    let mut b = packed(2, true);
    a.step(1500).unwrap();
    b.step(1500).unwrap();
    assert!(!a.open_events().is_empty());
    let dir = std::env::temp_dir().join(format!("demfem-ev-ck-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("state.ck");
    a.save_checkpoint(&path).unwrap();
    let before = a.events().len();
    a.step(1500).unwrap();
    b.step(1500).unwrap();
    assert_eq!(a.events(), b.events());
    assert_eq!(a.open_events(), b.open_events());
    let mut restarted = packed(2, true);
    restarted.load_checkpoint(&path).unwrap();
    restarted.step(1500).unwrap();
    assert_eq!(&a.events()[before..], restarted.events());
    assert_eq!(a.open_events(), restarted.open_events());
    // a checkpoint with events into a run without them (and back) loads
    let mut plain = packed(1, false);
    plain.load_checkpoint(&path).unwrap();
    plain.step(10).unwrap();
    std::fs::remove_dir_all(&dir).ok();
}

/// The head-on pair part-way through its contact (events recorded, so every section of the
/// checkpoint is there).
fn head_on_in_contact() -> Simulation {
    let mut sim = Simulation::new(&head_on(45e9, 1.0, 0.2).0).unwrap();
    for _ in 0..10_000 {
        if !sim.open_events().is_empty() {
            sim.step(3).unwrap();
            return sim;
        }
        sim.step(1).unwrap();
    }
    panic!("the spheres never touched");
}

fn refusal(sim: &mut Simulation, bytes: &[u8]) -> String {
    match sim.restore_checkpoint_bytes(bytes, "mem.ck") {
        Err(demfem::DemfemError::Io { path, detail }) => {
            assert_eq!(path, "mem.ck");
            detail
        }
        r => panic!("expected a refusal naming the source, got {r:?}"),
    }
}

#[test]
fn old_truncated_corrupt_and_foreign_checkpoints_are_refused_by_name() {
    let saved = head_on_in_contact();
    let bytes = saved.checkpoint_bytes();
    let mut fresh = Simulation::new(&head_on(45e9, 1.0, 0.2).0).unwrap();
    let before = bits(&fresh);

    // the checkpoint of an earlier demfem (magic DEMFEMCK, version 3)
    let mut old = b"DEMFEMCK".to_vec();
    old.extend_from_slice(&3u32.to_le_bytes());
    old.extend_from_slice(&bytes[12..]);
    let why = refusal(&mut fresh, &old);
    assert!(
        why.contains("older demfem checkpoint format") && why.contains("rerun from the start"),
        "{why}"
    );
    // every truncation, trailing bytes, a section renamed, a count changed, a bad flag
    for n in 0..bytes.len() {
        assert!(
            fresh
                .restore_checkpoint_bytes(&bytes[..n], "mem.ck")
                .is_err(),
            "a checkpoint cut at {n} of {} bytes was read",
            bytes.len()
        );
    }
    let mut longer = bytes.clone();
    longer.extend_from_slice(&[0; 3]);
    assert!(refusal(&mut fresh, &longer).contains("3 bytes left"));
    let at = |name: &[u8]| bytes.windows(name.len()).position(|w| w == name).unwrap();
    let mut renamed = bytes.clone();
    renamed[at(b"velocity")] = b'V';
    let why = refusal(&mut fresh, &renamed);
    assert!(why.contains(r#"where "velocity" was expected"#), "{why}");
    let mut counted = bytes.clone();
    let c = at(b"omega") + 5;
    counted[c] = 3; // 3 spheres' spins in a scene of 2
    let why = refusal(&mut fresh, &counted);
    assert!(
        why.contains("omega: 3 entries saved, this model has 2"),
        "{why}"
    );
    let mut flag = bytes.clone();
    flag[at(b"alive") + 5 + 8] = 7;
    assert!(refusal(&mut fresh, &flag).contains("not a flag"));
    // a state of another kind
    let fem = demfem::state_io::StateWriter::new(demfem::state_io::StateKind::Fem).finish();
    let why = refusal(&mut fresh, &fem);
    assert!(
        why.contains("an FEM explicit-run state") && why.contains("not a DEM"),
        "{why}"
    );
    assert_eq!(
        bits(&fresh),
        before,
        "a refused checkpoint changed the simulation"
    );

    // the intact bytes restore, and the run goes on as the saved one does
    let mut saved = saved;
    fresh.restore_checkpoint_bytes(&bytes, "mem.ck").unwrap();
    saved.step(100).unwrap();
    fresh.step(100).unwrap();
    assert_eq!(bits(&fresh), bits(&saved));
    assert_eq!(fresh.open_events(), saved.open_events());
}
