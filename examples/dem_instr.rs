//! Instruction-count driver for the packed anchor table (development aid, pairs with
//! `perf stat -e instructions:u` or `valgrind --tool=callgrind`): settles the table once (or
//! loads the settled checkpoint from `path` if it exists, writing it otherwise), then runs
//! `steps` steps on `threads` threads. Instructions per particle-step are the difference of two
//! runs with different `steps`, divided by 840 × the step difference.
//!
//! An optional fourth argument runs an effect variant of the bench (`without_damping`,
//! `without_belt`, `plus_planar`, `plus_rolling_resistance`) from the settled state instead.
//!
//! With `DEMFEM_PHASE_TIMES` set, it prints each thread's time in the force and the particle
//! phase (`Simulation::phase_times`).
//!
//! Usage: `dem_instr <checkpoint path> <steps> [threads] [variant]`.
use demfem::dem::table::{anchor_scene, TableStart};
use demfem::dem::{Effect, Simulation};
use demfem::geometry::Vec3;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = std::path::PathBuf::from(&args[1]);
    let steps: u64 = args[2].parse().unwrap();
    let threads: usize = args.get(3).map(|a| a.parse().unwrap()).unwrap_or(1);
    let mut scene = anchor_scene(45e9, TableStart::PackedIntoFunnel).unwrap();
    for v in scene.particles.velocity.iter_mut() {
        v.x = 0.2;
    }
    scene.threads = threads;
    let mut sim = Simulation::new(&scene).unwrap();
    if path.exists() {
        sim.load_checkpoint(&path).unwrap();
    } else {
        sim.step(60_000).unwrap();
        sim.save_checkpoint(&path).unwrap();
    }
    if let Some(variant) = args.get(4) {
        scene.particles.position = sim.positions().to_vec();
        scene.particles.velocity = sim.velocities().to_vec();
        scene.particles.angular_velocity = sim.angular_velocities().to_vec();
        match variant.as_str() {
            "without_damping" => {
                scene.effects = scene.effects.without(Effect::Damping);
                scene.materials[0].restitution = 1.0;
            }
            "without_belt" => {
                scene.effects = scene.effects.without(Effect::Belt);
                scene.walls[0].surface_velocity = Vec3::ZERO;
            }
            "plus_planar" => {
                scene.effects = scene.effects.with(Effect::Planar);
                for w in scene.particles.angular_velocity.iter_mut() {
                    w.x = 0.0;
                    w.y = 0.0;
                }
            }
            "plus_rolling_resistance" => {
                scene.effects = scene.effects.with(Effect::RollingResistance);
                scene.materials[0].rolling_friction = 0.01;
            }
            other if other.starts_with("skin=") => {
                scene.skin = Some(other[5..].parse().unwrap());
            }
            other => panic!("unknown variant {other}"),
        }
        sim = Simulation::new(&scene).unwrap();
    }
    // DEMFEM_PHASE_TIMES=1: print each thread's time in the force and particle phases
    let timed = std::env::var_os("DEMFEM_PHASE_TIMES").is_some();
    sim.set_phase_timing(timed);
    let clock = std::time::Instant::now();
    sim.step(steps).unwrap();
    if timed {
        eprintln!("steps: {:.3} s", clock.elapsed().as_secs_f64());
        eprintln!("blocks begin at particles {:?}", sim.block_cuts());
    }
    for (t, [force, particle]) in sim.phase_times().iter().enumerate() {
        eprintln!("thread {t}: force phase {force:.3} s, particle phase {particle:.3} s");
    }
    let z: u32 = sim.coordination().iter().sum();
    // FNV-1a over the bits of every position, velocity and angular velocity: equal hashes
    // mean bitwise equal states
    let mut hash = 0xcbf29ce484222325u64;
    for v in sim
        .positions()
        .iter()
        .chain(sim.velocities())
        .chain(sim.angular_velocities())
    {
        for x in [v.x, v.y, v.z] {
            hash = (hash ^ x.to_bits()).wrapping_mul(0x100000001b3);
        }
    }
    let (pairs, slots) = sim.candidate_counts();
    let walls: u32 = sim.wall_contact_counts().iter().sum();
    eprintln!(
        "candidate pairs {pairs} (sleeping {}) wall slots {slots} (plane pass {}) active wall \
         contacts {walls}",
        sim.sleeping_pairs(),
        sim.plane_pass_slots()
    );
    println!(
        "state hash {hash:016x} steps {} rebuilds {} Z {:.3} max overlap {:.3e} x0 {:?}",
        sim.steps(),
        sim.rebuilds(),
        z as f64 / sim.len() as f64,
        sim.max_overlap(),
        sim.positions()[0]
    );
}
