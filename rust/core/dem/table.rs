//! The anchor accumulation-table scene of `shared/anchors/dem/scene.py` (the scene Yade and
//! LIGGGHTS were timed on), for benchmarks and tests: 840 glass spheres of 16 mm on a belt at
//! 0.2 m/s in a 0.70 × 0.34 m table ending in a 45° funnel and a closed 20 mm outlet channel.

use crate::dem::effects::{Effect, EffectSet};
use crate::dem::material::Material;
use crate::dem::scene::{ParticleInit, Scene};
use crate::error::Result;
use crate::geometry::{Vec3, Wall, WallShape};

/// Sphere diameter, m.
pub const DIAMETER: f64 = 0.016;
/// Table width (y), m.
pub const WIDTH: f64 = 0.34;
/// Length of the rectangular part (x), m.
pub const LENGTH: f64 = 0.70;
/// Funnel opening, m.
pub const OPENING: f64 = 0.02;
/// Funnel length for 45° walls, m.
pub const FUNNEL_LENGTH: f64 = (WIDTH - OPENING) / 2.0;
/// Outlet channel length, m.
pub const CHANNEL_LENGTH: f64 = 0.05;
/// Height of funnel and channel walls, m.
pub const WALL_HEIGHT: f64 = 0.05;
/// Belt speed along +x, m/s.
pub const BELT_SPEED: f64 = 0.2;
/// Number of spheres.
pub const COUNT: usize = 840;

/// How the spheres start.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableStart {
    /// scene.py's start: 42 × 20 square packing with 1 % gap, 1 cm behind the pack, at rest.
    SquarePacking,
    /// Dense: a hexagonal packing (0.1 % gap) filled from the closed outlet backwards, so the
    /// pack sits against the funnel — a quick stand-in for the anchors' "packed" state.
    PackedIntoFunnel,
}

/// The glass of the anchors: ρ 2230 kg/m³, ν 0.22, μ 0.2, e 0.5, E as given (Pa).
pub fn glass(young_modulus: f64) -> Material {
    Material::new(young_modulus, 0.22, 2230.0, 0.2, 0.5, 0.0)
}

/// The walls: belt floor, back wall x = 0, side walls y = 0 and y = W, two 45° funnel
/// strips, two channel strips and the end wall closing the outlet. All use material 0.
pub fn walls() -> Result<Vec<Wall>> {
    let yc = WIDTH / 2.0;
    let (xa, xb) = (LENGTH, LENGTH + FUNNEL_LENGTH);
    let xe = xb + CHANNEL_LENGTH;
    let mut floor = Wall::fixed(WallShape::plane(Vec3::ZERO, Vec3::Z)?, 0);
    floor.surface_velocity = Vec3::new(BELT_SPEED, 0.0, 0.0);
    let h = WALL_HEIGHT;
    Ok(vec![
        floor,
        Wall::fixed(WallShape::plane(Vec3::ZERO, Vec3::X)?, 0),
        Wall::fixed(WallShape::plane(Vec3::ZERO, Vec3::Y)?, 0),
        Wall::fixed(WallShape::plane(Vec3::new(0.0, WIDTH, 0.0), -Vec3::Y)?, 0),
        Wall::fixed(
            WallShape::vertical_strip(xa, 0.0, xb, yc - OPENING / 2.0, 0.0, h)?,
            0,
        ),
        Wall::fixed(
            WallShape::vertical_strip(xa, WIDTH, xb, yc + OPENING / 2.0, 0.0, h)?,
            0,
        ),
        Wall::fixed(
            WallShape::vertical_strip(xb, yc - OPENING / 2.0, xe, yc - OPENING / 2.0, 0.0, h)?,
            0,
        ),
        Wall::fixed(
            WallShape::vertical_strip(xb, yc + OPENING / 2.0, xe, yc + OPENING / 2.0, 0.0, h)?,
            0,
        ),
        Wall::fixed(WallShape::plane(Vec3::new(xe, 0.0, 0.0), -Vec3::X)?, 0),
    ])
}

fn square_packing() -> Vec<Vec3> {
    let r = DIAMETER / 2.0;
    let pitch = DIAMETER * 1.01;
    let (nx, ny) = (42, 20);
    let x0 = 0.01 + r;
    let y0 = (WIDTH - (ny - 1) as f64 * pitch) / 2.0;
    let mut out = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            out.push(Vec3::new(x0 + i as f64 * pitch, y0 + j as f64 * pitch, r));
        }
    }
    out
}

fn packed_into_funnel() -> Vec<Vec3> {
    let r = DIAMETER / 2.0;
    let pitch = DIAMETER * 1.001;
    let row = pitch * 3f64.sqrt() / 2.0;
    let yc = WIDTH / 2.0;
    let xe = LENGTH + FUNNEL_LENGTH + CHANNEL_LENGTH;
    let fits = |x: f64, y: f64| -> bool {
        let margin = 1e-4;
        if x < r + margin || x > xe - r - margin || y < r + margin || y > WIDTH - r - margin {
            return false;
        }
        if x > LENGTH {
            // between the 45° walls: distance to each wall line ≥ r
            let half_gap = (WIDTH / 2.0 - (x - LENGTH)).max(OPENING / 2.0);
            if x < LENGTH + FUNNEL_LENGTH {
                let d = (WIDTH / 2.0 - (x - LENGTH) - (y - yc).abs()) / 2f64.sqrt();
                if d < r + margin {
                    return false;
                }
            }
            if (y - yc).abs() > half_gap - r - margin {
                return false;
            }
        }
        true
    };
    let mut candidates = Vec::new();
    let ny = (WIDTH / row) as usize + 1;
    let nx = (xe / pitch) as usize + 2;
    for j in 0..ny {
        let y = r + 1e-4 + j as f64 * row;
        for i in 0..nx {
            let x = xe - r - 1e-4 - i as f64 * pitch - if j % 2 == 1 { pitch / 2.0 } else { 0.0 };
            if fits(x, y) {
                candidates.push(Vec3::new(x, y, r));
            }
        }
    }
    // downstream first; ties broken by y so the order is deterministic
    candidates.sort_by(|a, b| b.x.total_cmp(&a.x).then(a.y.total_cmp(&b.y)));
    candidates.truncate(COUNT);
    candidates
}

/// The anchor scene at Young's modulus `young_modulus` (Pa) with dt = 0.5 r √(ρ/E) (the
/// anchors' step) and the effects gravity, belt, friction, rotation, damping.
pub fn anchor_scene(young_modulus: f64, start: TableStart) -> Result<Scene> {
    let position = match start {
        TableStart::SquarePacking => square_packing(),
        TableStart::PackedIntoFunnel => packed_into_funnel(),
    };
    let n = position.len();
    let particles = ParticleInit::at_rest(position, vec![DIAMETER / 2.0; n]);
    let effects = EffectSet::of(&[
        Effect::Gravity,
        Effect::Belt,
        Effect::Friction,
        Effect::Rotation,
        Effect::Damping,
    ]);
    let mut scene = Scene::new(particles, vec![glass(young_modulus)], walls()?, effects);
    scene.time_step = Some(0.5 * DIAMETER / 2.0 * (2230.0 / young_modulus).sqrt());
    Ok(scene)
}
