//! Quick speed probe of the packed anchor table (development aid; the criterion bench
//! `benches/dem_step.rs` is the reference measurement). Prints wall-clock and CPU-time
//! throughput: on a shared machine the CPU-time figure is what a quiet core would give.
use demfem::dem::table::{anchor_scene, TableStart};
use demfem::dem::Simulation;
use std::time::Instant;

fn cpu_seconds() -> f64 {
    // process CPU time from /proc/self/stat (utime + stime, clock ticks of 1/100 s)
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = s.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    let t = |k: usize| f.get(k).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
    (t(11) + t(12)) / 100.0
}

fn main() {
    let e: f64 = std::env::args()
        .nth(1)
        .map(|a| a.parse().unwrap())
        .unwrap_or(45e9);
    let steps: u64 = std::env::args()
        .nth(2)
        .map(|a| a.parse().unwrap())
        .unwrap_or(20000);
    let settle: u64 = std::env::args()
        .nth(3)
        .map(|a| a.parse().unwrap())
        .unwrap_or(60000);
    let mut scene = anchor_scene(e, TableStart::PackedIntoFunnel).unwrap();
    for v in scene.particles.velocity.iter_mut() {
        v.x = 0.2;
    }
    let mut sim = Simulation::new(&scene).unwrap();
    sim.step(settle).unwrap();
    let bytes = sim.checkpoint_bytes();
    for threads in [1usize, 2] {
        scene.threads = threads;
        let mut sim = Simulation::new(&scene).unwrap();
        sim.restore_checkpoint_bytes(&bytes, "settled").unwrap();
        let (t0, c0) = (Instant::now(), cpu_seconds());
        sim.step(steps).unwrap();
        let (wall, cpu) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
        let z: u32 = sim.coordination().iter().sum();
        let ps = sim.len() as f64 * steps as f64;
        println!(
            "threads {threads}: {:.3e} p-steps/s wall, {:.3e} per CPU-s; Z={:.2}, rebuilds {}",
            ps / wall,
            ps / cpu,
            z as f64 / sim.len() as f64,
            sim.rebuilds()
        );
    }
}
