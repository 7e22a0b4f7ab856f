//! Shared helpers of the DEM integration tests: closed forms written out here, independently
//! of `demfem::contact`, and small scene builders.
#![allow(dead_code)]

use demfem::dem::{EffectSet, Material, ParticleInit, Scene, Simulation};
use demfem::geometry::{Vec3, Wall, WallShape};

/// Hertz stiffness k_H = 4/3 E* √R* (Johnson, Contact Mechanics, eq. 4.22).
pub fn k_hertz(e_star: f64, r_star: f64) -> f64 {
    4.0 / 3.0 * e_star * r_star.sqrt()
}

/// E* of two materials.
pub fn e_star(e1: f64, nu1: f64, e2: f64, nu2: f64) -> f64 {
    1.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2)
}

/// Undamped Hertz impact (Johnson §11.4): δ_max = (15 m* v² / (16 E* √R*))^{2/5},
/// F_max = 4/3 E* √R* δ_max^{3/2}, t_c = 2.868 (m*² / (R* E*² v))^{1/5}.
pub fn hertz_impact(e_star: f64, r_star: f64, m_star: f64, v: f64) -> (f64, f64, f64) {
    let d = (15.0 * m_star * v * v / (16.0 * e_star * r_star.sqrt())).powf(0.4);
    let f = 4.0 / 3.0 * e_star * r_star.sqrt() * d.powf(1.5);
    let t = 2.868 * (m_star * m_star / (r_star * e_star * e_star * v)).powf(0.2);
    (d, f, t)
}

/// Sphere mass, kg.
pub fn sphere_mass(density: f64, r: f64) -> f64 {
    density * 4.0 / 3.0 * std::f64::consts::PI * r * r * r
}

/// A material (shell stiffness ∞).
pub fn material(e: f64, nu: f64, rho: f64, mu: f64, rest: f64) -> Material {
    Material::new(e, nu, rho, mu, rest, 0.0)
}

/// A "rigid" wall material: E large enough that E* differs from the particle's by < 1e-9.
pub fn rigid(nu: f64, mu: f64, rest: f64) -> Material {
    material(1e21, nu, 1000.0, mu, rest)
}

/// One sphere of radius r above the floor plane z = 0 at height z, velocity v.
pub fn sphere_on_floor(
    r: f64,
    z: f64,
    v: Vec3,
    w: Vec3,
    mats: Vec<Material>,
    effects: EffectSet,
) -> Scene {
    let mut p = ParticleInit::at_rest(vec![Vec3::new(0.0, 0.0, z)], vec![r]);
    p.velocity[0] = v;
    p.angular_velocity[0] = w;
    let floor = Wall::fixed(WallShape::plane(Vec3::ZERO, Vec3::Z).unwrap(), 1);
    let mut s = Scene::new(p, mats, vec![floor], effects);
    s.gravity = Vec3::ZERO;
    s
}

/// Deterministic pseudo-random numbers in [0, 1) (splitmix64), for reproducible packings.
pub struct Rng(pub u64);
impl Rng {
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E3779B97F4A7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58476D1CE4E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D049BB133111EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A jammed monolayer: `nx` × `ny` glass spheres (d = 16 mm) in hexagonal packing with 0.1 %
/// gap, in a box whose walls touch the packing, on a belt moving at 0.2 m/s towards +x that
/// presses the pack against the end wall. Effects: gravity, belt, friction, rotation,
/// damping, planar (upright-cartridge kinematics: the spheres slide on the belt instead of
/// rolling, so the belt keeps loading the pack with μ m g per sphere; free spheres would end
/// up spinning in place, which transmits no force, and the pack would relax).
pub fn jammed_box(nx: usize, ny: usize, young_modulus: f64) -> Scene {
    use demfem::dem::Effect;
    let r = 0.008;
    let pitch = 2.0 * r * 1.001;
    let row = pitch * 3f64.sqrt() / 2.0;
    let mut pos = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let x = r * 1.001 + i as f64 * pitch + if j % 2 == 1 { pitch / 2.0 } else { 0.0 };
            pos.push(Vec3::new(x, r * 1.001 + j as f64 * row, r));
        }
    }
    let lx = pos.iter().map(|p| p.x).fold(0.0, f64::max) + r * 1.001;
    let ly = (ny - 1) as f64 * row + 2.0 * r * 1.001;
    let n = pos.len();
    let particles = ParticleInit::at_rest(pos, vec![r; n]);
    let mut floor = Wall::fixed(WallShape::plane(Vec3::ZERO, Vec3::Z).unwrap(), 0);
    floor.surface_velocity = Vec3::new(0.2, 0.0, 0.0);
    let walls = vec![
        floor,
        Wall::fixed(WallShape::plane(Vec3::ZERO, Vec3::X).unwrap(), 0),
        Wall::fixed(
            WallShape::plane(Vec3::new(lx, 0.0, 0.0), -Vec3::X).unwrap(),
            0,
        ),
        Wall::fixed(WallShape::plane(Vec3::ZERO, Vec3::Y).unwrap(), 0),
        Wall::fixed(
            WallShape::plane(Vec3::new(0.0, ly, 0.0), -Vec3::Y).unwrap(),
            0,
        ),
    ];
    let glass = Material::new(young_modulus, 0.22, 2230.0, 0.2, 0.5, 0.0);
    let effects = EffectSet::of(&[
        Effect::Gravity,
        Effect::Belt,
        Effect::Friction,
        Effect::Rotation,
        Effect::Damping,
        Effect::Planar,
    ]);
    Scene::new(particles, vec![glass], walls, effects)
}

/// The bits of every position, velocity and angular velocity: equal exactly when two runs
/// are bitwise the same.
pub fn bits(sim: &Simulation) -> Vec<u64> {
    let mut out = Vec::new();
    for v in sim
        .positions()
        .iter()
        .chain(sim.velocities())
        .chain(sim.angular_velocities())
    {
        out.extend([v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]);
    }
    out
}
