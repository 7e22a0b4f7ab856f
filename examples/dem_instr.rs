//! Instruction-count driver for the packed anchor table (development aid, pairs with
//! `perf stat -e instructions:u` or `valgrind --tool=callgrind`): settles the table once (or
//! loads the settled checkpoint from `path` if it exists, writing it otherwise), then runs
//! `steps` steps on `threads` threads. Instructions per particle-step are the difference of two
//! runs with different `steps`, divided by 840 × the step difference.
//!
//! Usage: `dem_instr <checkpoint path> <steps> [threads]`.
use demfem::dem::table::{anchor_scene, TableStart};
use demfem::dem::Simulation;

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
    sim.step(steps).unwrap();
    let z: u32 = sim.coordination().iter().sum();
    println!(
        "steps {} rebuilds {} Z {:.3} max overlap {:.3e} x0 {:?}",
        sim.steps(),
        sim.rebuilds(),
        z as f64 / sim.len() as f64,
        sim.max_overlap(),
        sim.positions()[0]
    );
}
