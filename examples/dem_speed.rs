//! Quick speed probe of the packed anchor table (development aid; the criterion bench
//! `benches/dem_step.rs` is the reference measurement).
use demfem::dem::table::{anchor_scene, TableStart};
use demfem::dem::Simulation;
use std::time::Instant;
fn main() {
    let e: f64 = std::env::args().nth(1).map(|a| a.parse().unwrap()).unwrap_or(45e9);
    let steps: u64 = std::env::args().nth(2).map(|a| a.parse().unwrap()).unwrap_or(20000);
    for threads in [1usize, 2] {
        let mut scene = anchor_scene(e, TableStart::PackedIntoFunnel).unwrap();
        scene.threads = threads;
        for v in scene.particles.velocity.iter_mut() { v.x = 0.2; }
        let mut sim = Simulation::new(&scene).unwrap();
        let t0 = Instant::now();
        sim.step(3 * steps).unwrap();
        let settle = t0.elapsed().as_secs_f64();
        let t0 = Instant::now();
        sim.step(steps).unwrap();
        let wall = t0.elapsed().as_secs_f64();
        let z: u32 = sim.coordination().iter().sum();
        println!(
            "threads {threads}: n={} settle {:.2}s, timed {:.3e} p-steps/s, Z={:.2}, pairs listed {}, rebuilds {}, ride-up {}",
            sim.len(), settle, sim.len() as f64 * steps as f64 / wall, z as f64 / sim.len() as f64,
            sim.contacts().len(), sim.rebuilds(), sim.riding_up_count(0.0, 0.002)
        );
    }
}
