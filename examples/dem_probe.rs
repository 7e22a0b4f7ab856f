//! Probe: prints the evolution of a jammed box (development aid).
#[path = "../tests/dem_support/mod.rs"]
mod dem_support;
use demfem::dem::Simulation;
fn main() {
    let mut scene = dem_support::jammed_box(10, 8, 73e9);
    let f: f64 = std::env::args()
        .nth(1)
        .map(|a| a.parse().unwrap())
        .unwrap_or(0.2);
    let lim = Simulation::new(&scene).unwrap().stable_step().limit;
    scene.time_step = Some(f * lim);
    let mut sim = Simulation::new(&scene).unwrap();
    println!("dt {} limit {:?}", sim.dt(), sim.stable_step());
    for k in 0..20 {
        sim.step(10000).unwrap();
        let n = sim.len() as f64;
        let vx: f64 = sim.velocities().iter().map(|v| v.x).sum::<f64>() / n;
        let z: u32 = sim.coordination().iter().sum();
        let zw: u32 = sim.wall_contact_counts().iter().sum();
        let xmax = sim.positions().iter().map(|p| p.x).fold(0.0, f64::max);
        let zmax = sim.positions().iter().map(|p| p.z).fold(0.0, f64::max);
        println!("{k} t={:.4} vx={vx:.4} Z={:.3} wall={zw} xmax={xmax:.5} zmax={zmax:.6} ov={:.3e} KE={:.3e}", sim.time(), z as f64 / n, sim.max_overlap(), sim.kinetic_energy());
    }
}
