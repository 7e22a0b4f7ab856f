//! Shared fixtures of the rigid-body tests and benches: the default cartridge as a clump of
//! 632 beads (from `Cartridge().bead_clump(632)`, see tests/data/make_cartridge_clump.py), as
//! an exact parry shape and as the analytic body of revolution, all with their mass
//! properties.
#![allow(dead_code)]

use demfem::rigid::{
    BeadClump, ExactShape, MassProperties, RevolutionProfile, RevolutionShape, RigidScene,
    RigidSceneConfig, RigidShape,
};
use nalgebra::{UnitQuaternion, Vector3};

/// Density of the paper's glass, kg/m³.
pub const GLASS_DENSITY: f64 = 2230.0;

/// Mass of the default cartridge from Python (`Cartridge().mass`), kg.
pub const CARTRIDGE_MASS: f64 = 0.004_941_142_604_323_21;

/// The 632-bead clump of the default cartridge, its mass properties from the beads.
pub fn cartridge_clump() -> (BeadClump, MassProperties) {
    let text = include_str!("../data/cartridge_clump_632.csv");
    let (mut centers, mut radii, mut masses) = (Vec::new(), Vec::new(), Vec::new());
    for line in text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
    {
        let v: Vec<f64> = line
            .split(',')
            .map(|x| x.trim().parse::<f64>().unwrap())
            .collect();
        centers.push(Vector3::new(v[0], v[1], v[2]));
        radii.push(v[3]);
        masses.push(v[4]);
    }
    BeadClump::from_beads(&centers, &radii, &masses).unwrap()
}

/// The default cartridge as an exact shape with its exact mass properties.
pub fn cartridge_exact() -> (ExactShape, MassProperties) {
    let profile = RevolutionProfile::default_cartridge();
    let mass = profile.mass_properties(GLASS_DENSITY).unwrap();
    let shape = ExactShape::from_profile(&profile, mass.center_of_mass.z).unwrap();
    (shape, mass)
}

/// The default cartridge as the analytic body of revolution with its exact mass properties.
pub fn cartridge_revolution() -> (RevolutionShape, MassProperties) {
    let profile = RevolutionProfile::default_cartridge();
    let mass = profile.mass_properties(GLASS_DENSITY).unwrap();
    let shape = RevolutionShape::from_profile(&profile, mass.center_of_mass.z).unwrap();
    (shape, mass)
}

/// Any representation ("clump", "revolution", else the exact parry shape), as a scene shape.
pub fn cartridge(kind: &str) -> (RigidShape, MassProperties) {
    match kind {
        "clump" => {
            let (c, m) = cartridge_clump();
            (RigidShape::Clump(c), m)
        }
        "revolution" => {
            let (r, m) = cartridge_revolution();
            (RigidShape::Revolution(r), m)
        }
        _ => {
            let (e, m) = cartridge_exact();
            (RigidShape::Exact(e), m)
        }
    }
}

/// Height of the centre of mass above the cartridge's bottom end, m (exact geometry).
pub fn com_height() -> f64 {
    RevolutionProfile::default_cartridge()
        .mass_properties(GLASS_DENSITY)
        .unwrap()
        .center_of_mass
        .z
}

/// Angle between the body axis (body z) and world z, degrees.
pub fn tilt_degrees(q: &UnitQuaternion<f64>) -> f64 {
    (q * Vector3::z()).z.clamp(-1.0, 1.0).acos().to_degrees()
}

/// Stable time-step limit (s) of a scene with `config` holding one cartridge of `kind`
/// ("clump" or "exact") at rest at the origin: the probe the tests size their steps with.
pub fn time_step_limit_of(config: RigidSceneConfig, kind: &str) -> f64 {
    let (shape, mass) = cartridge(kind);
    let mut probe = RigidScene::new(config).unwrap();
    let id = probe.add_shape(shape, mass).unwrap();
    probe
        .add_body(
            id,
            Vector3::zeros(),
            UnitQuaternion::identity(),
            Vector3::zeros(),
            Vector3::zeros(),
        )
        .unwrap();
    probe.time_step_limit().unwrap()
}
