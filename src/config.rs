//! Plain configuration structs for the plugin group: the arena, spawning, the solver and the
//! effects a scene calls for. Each is a `Resource` once the plugins are added, so systems and
//! users read (and change) the live settings in one place.

use std::fmt;
use std::str::FromStr;

use bevy::math::DVec2;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

/// The axis-aligned rectangle the circles live in, bounded by walls.
#[derive(Resource, Reflect, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[reflect(Resource, Debug)]
pub struct Arena {
    /// Lower-left corner.
    pub min: DVec2,
    /// Upper-right corner.
    pub max: DVec2,
}

impl Default for Arena {
    /// A 16:9 arena, 16 units wide, centred on the origin (the seed's window shape).
    fn default() -> Self {
        Self::centered(DVec2::new(16.0, 9.0))
    }
}

impl Arena {
    /// An arena of the given size centred on the origin.
    pub fn centered(size: DVec2) -> Self {
        Self {
            min: -size / 2.0,
            max: size / 2.0,
        }
    }

    /// Width and height.
    pub fn size(&self) -> DVec2 {
        self.max - self.min
    }

    /// Area of the arena.
    pub fn area(&self) -> f64 {
        let s = self.size();
        s.x * s.y
    }

    /// Centre of the arena.
    pub fn center(&self) -> DVec2 {
        (self.min + self.max) / 2.0
    }

    /// Whether a point lies inside or on the boundary.
    pub fn contains(&self, p: DVec2) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }
}

/// How a spawned circle's mass is chosen.
#[derive(Reflect, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum MassModel {
    /// Mass proportional to area: `density · π r²`.
    Area {
        /// Mass per unit area.
        density: f64,
    },
    /// Every circle has this mass (the seed's assumption).
    Equal(f64),
}

impl Default for MassModel {
    fn default() -> Self {
        Self::Area { density: 1.0 }
    }
}

impl MassModel {
    /// The mass of a circle of radius `r` under this model.
    pub fn mass_of(self, r: f64) -> f64 {
        match self {
            Self::Area { density } => density * std::f64::consts::PI * r * r,
            Self::Equal(m) => m,
        }
    }
}

/// Random placement of circles: how many, how big, how fast. Seeded and reproducible.
#[derive(Resource, Reflect, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[reflect(Resource, Debug)]
#[serde(default, deny_unknown_fields)]
pub struct SpawnConfig {
    /// How many circles to place (ignored when `area_fraction` is set).
    pub count: usize,
    /// Fill this fraction of the arena's area instead of placing `count` circles.
    pub area_fraction: Option<f64>,
    /// Smallest and largest radius; radii are drawn uniformly in between.
    pub radius: (f64, f64),
    /// Smallest and largest speed; directions are uniform.
    pub speed: (f64, f64),
    /// Seed of the random generator: the same seed gives the same circles.
    pub seed: u64,
    /// How masses are assigned.
    pub mass: MassModel,
    /// Placement attempts per circle before it is given up as not fitting.
    pub attempts_per_circle: u32,
}

impl Default for SpawnConfig {
    /// The seed exercise: 32 circles of random radius, speed and direction.
    fn default() -> Self {
        Self {
            count: 32,
            area_fraction: None,
            radius: (0.2, 0.6),
            speed: (1.0, 4.0),
            seed: 1,
            mass: MassModel::default(),
            attempts_per_circle: 200,
        }
    }
}

impl SpawnConfig {
    /// How many circles to place in `arena`: `count`, or as many as make up `area_fraction` of
    /// its area on average (`E[r²] = (a² + ab + b²) / 3` for radii uniform in `[a, b]`).
    pub fn target_count(&self, arena: &Arena) -> usize {
        let Some(fraction) = self.area_fraction else {
            return self.count;
        };
        let (a, b) = self.radius;
        let mean_square = (a * a + a * b + b * b) / 3.0;
        let n = fraction * arena.area() / (std::f64::consts::PI * mean_square);
        if n.is_finite() && n > 0.0 {
            n.round() as usize
        } else {
            0
        }
    }
}

/// How one fixed step of simulated time is advanced.
#[derive(Resource, Reflect, Clone, Copy, Debug, PartialEq, Eq, Default)]
#[reflect(Resource, Debug)]
pub enum Solver {
    /// Move, then push overlapping pairs apart and apply the elastic impulse (the seed's method).
    #[default]
    Discrete,
    /// `Discrete` run `N` times per step with `dt / N`.
    Substeps(u32),
    /// Continuous within each step: hits resolved in time order, bounded work per step.
    Swept,
    /// Event-driven across steps: every hit at its exact time; the reference.
    Exact,
}

impl Solver {
    /// How many times the step schedule runs per fixed step.
    pub fn substeps(self) -> u32 {
        match self {
            Self::Substeps(n) => n.max(1),
            _ => 1,
        }
    }

    /// Whether this solver advances time continuously (`swept`, `exact`) rather than by moving
    /// and then fixing overlaps.
    pub fn is_continuous(self) -> bool {
        matches!(self, Self::Swept | Self::Exact)
    }
}

impl fmt::Display for Solver {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Discrete => write!(f, "discrete"),
            Self::Substeps(n) => write!(f, "substeps={n}"),
            Self::Swept => write!(f, "swept"),
            Self::Exact => write!(f, "exact"),
        }
    }
}

/// Why a solver name could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "unknown solver `{0}`: expected `discrete`, `substeps=N` (N from 1 to 1024), `swept` or `exact`"
)]
pub struct ParseSolverError(pub String);

impl FromStr for Solver {
    type Err = ParseSolverError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let err = || ParseSolverError(s.to_owned());
        match s.trim() {
            "discrete" => Ok(Self::Discrete),
            "swept" => Ok(Self::Swept),
            "exact" => Ok(Self::Exact),
            other => {
                let n = other.strip_prefix("substeps=").ok_or_else(err)?;
                match n.parse::<u32>() {
                    Ok(n @ 1..=1024) => Ok(Self::Substeps(n)),
                    _ => Err(err()),
                }
            }
        }
    }
}

impl Serialize for Solver {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for Solver {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

/// What happens at the edges of the arena.
#[derive(Reflect, Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Boundary {
    /// Solid walls: circles bounce off them.
    #[default]
    Walls,
    /// Periodic: a circle leaving one side enters at the opposite one, and circles interact
    /// across the seam (minimum image).
    Periodic,
}

impl FromStr for Boundary {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "walls" => Ok(Self::Walls),
            "periodic" => Ok(Self::Periodic),
            other => Err(format!(
                "unknown boundary `{other}`: expected `walls` or `periodic`"
            )),
        }
    }
}

/// The effects a scene calls for. Only these get systems in the schedule: no gravity, no
/// gravity system; no collisions, no broad phase.
#[derive(Resource, Reflect, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[reflect(Resource, Debug)]
#[serde(default, deny_unknown_fields)]
pub struct Effects {
    /// Walls or periodic edges. Not read from a scene's `effects` (a scene sets it as
    /// `arena.boundary`), so writing it there is an unknown-field error, not silently ignored.
    #[serde(skip)]
    pub boundary: Boundary,
    /// Circle-circle collisions (broad phase, separation and impulse).
    pub collisions: bool,
    /// Constant acceleration, e.g. `(0, -9.81)`; `None` schedules no gravity system.
    pub gravity: Option<DVec2>,
    /// Linear drag rate in 1/s (`v' = -drag · v`); `None` schedules no drag system.
    pub drag: Option<f64>,
    /// Coefficient of restitution between circles: 1 is perfectly elastic.
    pub restitution: f64,
    /// Coefficient of restitution against the walls.
    pub wall_restitution: f64,
}

impl Default for Effects {
    fn default() -> Self {
        Self {
            boundary: Boundary::Walls,
            collisions: true,
            gravity: None,
            drag: None,
            restitution: 1.0,
            wall_restitution: 1.0,
        }
    }
}

/// Everything [`CirclesPlugins`](crate::CirclesPlugins) needs, in one value. Scene files
/// ([`crate::scene`]) are read into this.
#[derive(Clone, Debug, PartialEq)]
pub struct CirclesConfig {
    /// The walls.
    pub arena: Arena,
    /// Random initial circles.
    pub spawn: SpawnConfig,
    /// How a step is advanced.
    pub solver: Solver,
    /// What is simulated.
    pub effects: Effects,
    /// The fixed step in seconds.
    pub dt: f64,
    /// Circles placed exactly as given, before the random ones.
    pub circles: Vec<crate::spawn::CircleInit>,
}

impl Default for CirclesConfig {
    /// The seed: a 16:9 arena with 32 random circles, stepped at 60 Hz.
    fn default() -> Self {
        Self {
            arena: Arena::default(),
            spawn: SpawnConfig::default(),
            solver: Solver::default(),
            effects: Effects::default(),
            dt: 1.0 / 60.0,
            circles: Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solver_names_round_trip() {
        for s in [
            Solver::Discrete,
            Solver::Substeps(1),
            Solver::Substeps(16),
            Solver::Swept,
            Solver::Exact,
        ] {
            assert_eq!(s.to_string().parse::<Solver>(), Ok(s));
        }
    }

    #[test]
    fn bad_solver_names_are_rejected_with_the_name() {
        for bad in [
            "",
            "Discrete",
            "substeps=0",
            "substeps=x",
            "substeps=5000",
            "exacts",
        ] {
            let err = bad.parse::<Solver>().unwrap_err();
            assert!(err.to_string().contains(&format!("`{bad}`")), "{err}");
        }
    }
}
