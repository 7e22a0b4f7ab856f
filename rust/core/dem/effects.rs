//! The effects a scene names (DESIGN §3). The step runs only the passes of the named effects,
//! and a scene whose data needs an effect it did not name is refused with
//! [`DemfemError::Effect`](crate::error::DemfemError::Effect).
//!
//! | effect | what it switches on |
//! |---|---|
//! | `gravity` | the body force m g |
//! | `belt` | wall surface velocities enter the contact velocity |
//! | `moving_walls` | prescribed wall motion (constant velocity, harmonic) |
//! | `friction` | tangential springs with history and the Coulomb cap |
//! | `rotation` | torques and angular velocities |
//! | `damping` | restitution dashpots (normal and tangential) |
//! | `rolling_resistance` | constant rolling-resistance torque (needs `rotation`) |
//! | `planar` | upright-cartridge kinematics: particle–particle forces act in the xy plane only, rotation only about z, so centres stay in the layer set by gravity and the floor |

use crate::error::{DemfemError, Result};

/// One effect a scene can name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u16)]
pub enum Effect {
    /// Body force m g.
    Gravity = 1,
    /// Wall surface velocities (conveyor belt).
    Belt = 2,
    /// Prescribed wall motion.
    MovingWalls = 4,
    /// Tangential contact forces with history and Coulomb cap.
    Friction = 8,
    /// Torques and angular velocities.
    Rotation = 16,
    /// Restitution damping.
    Damping = 32,
    /// Constant-torque rolling resistance.
    RollingResistance = 64,
    /// Centres kept in one layer (see module docs).
    Planar = 128,
}

impl Effect {
    /// Every effect, in a fixed order.
    pub const ALL: [Effect; 8] = [
        Effect::Gravity,
        Effect::Belt,
        Effect::MovingWalls,
        Effect::Friction,
        Effect::Rotation,
        Effect::Damping,
        Effect::RollingResistance,
        Effect::Planar,
    ];

    /// The scene-file name of the effect.
    pub fn name(self) -> &'static str {
        match self {
            Effect::Gravity => "gravity",
            Effect::Belt => "belt",
            Effect::MovingWalls => "moving_walls",
            Effect::Friction => "friction",
            Effect::Rotation => "rotation",
            Effect::Damping => "damping",
            Effect::RollingResistance => "rolling_resistance",
            Effect::Planar => "planar",
        }
    }

    /// Parse a scene-file name; unknown names are an [`DemfemError::Effect`].
    pub fn parse(name: &str) -> Result<Effect> {
        Effect::ALL
            .iter()
            .copied()
            .find(|e| e.name() == name)
            .ok_or_else(|| {
                let known: Vec<&str> = Effect::ALL.iter().map(|e| e.name()).collect();
                DemfemError::Effect(format!(
                    "unknown effect '{name}'; known: {}",
                    known.join(", ")
                ))
            })
    }
}

/// A set of effects (bit set).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub struct EffectSet(u16);

impl EffectSet {
    /// No effect at all.
    pub const fn empty() -> Self {
        EffectSet(0)
    }

    /// Build from a list.
    pub fn of(effects: &[Effect]) -> Self {
        EffectSet(effects.iter().fold(0, |acc, e| acc | *e as u16))
    }

    /// Parse a list of names.
    pub fn parse<S: AsRef<str>>(names: &[S]) -> Result<Self> {
        let mut set = EffectSet::empty();
        for n in names {
            set = set.with(Effect::parse(n.as_ref())?);
        }
        Ok(set)
    }

    /// This set plus `e`.
    pub const fn with(self, e: Effect) -> Self {
        EffectSet(self.0 | e as u16)
    }

    /// This set without `e`.
    pub const fn without(self, e: Effect) -> Self {
        EffectSet(self.0 & !(e as u16))
    }

    /// Whether `e` is in the set.
    #[inline]
    pub const fn has(self, e: Effect) -> bool {
        self.0 & e as u16 != 0
    }

    /// Names of the effects in the set, in [`Effect::ALL`] order.
    pub fn names(self) -> Vec<&'static str> {
        Effect::ALL
            .iter()
            .filter(|e| self.has(**e))
            .map(|e| e.name())
            .collect()
    }

    /// Raw bits (for checkpoints).
    pub fn bits(self) -> u16 {
        self.0
    }
}
