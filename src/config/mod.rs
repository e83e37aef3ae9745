//! Plain configuration structs for the plugin group: spawning, the solver, the effects a scene
//! calls for, and [`CirclesConfig`] holding them with the [`Arena`]. Each is a `Resource` once
//! the plugins are added, so systems and users read (and change) the live settings in one
//! place. Each has one `check`, used by scene files, the command line and spawning alike, and
//! the limits they check against are the constants here.

use std::fmt;
use std::str::FromStr;

use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use crate::arena::Arena;
use crate::circle::CircleState;
use crate::error::FieldError;
pub use crate::range::{MAX_MAGNITUDE, MIN_MASS, check_magnitude, check_mass, check_vector};
use crate::segment::Segments;
pub use drop::DropConfig;
pub use effects::Effects;

mod drop;
mod effects;

/// Most circles any input may ask for: random spawns and particle files alike. Checked before
/// anything is allocated, so a file claiming 10¹¹ circles fails at once; and small enough that
/// reading a whole file of this many circles, only to refuse it for an overlap in its last
/// line, stays under 1 GB of memory.
pub const MAX_CIRCLES: usize = 5_000_000;
/// Smallest and largest fixed step in seconds: below 1 ns the fixed clock (nanoseconds) cannot
/// represent it; above a minute nothing sensible is being simulated.
pub const DT_RANGE: (f64, f64) = (1e-9, 60.0);
/// Most substeps `substeps=N` may ask for.
pub const MAX_SUBSTEPS: u32 = 1024;
/// Smallest radius, as a fraction of the arena's smaller side: below it the solvers' rounding
/// of positions is the size of the circle, and ratios of radii overflow.
pub const MIN_RADIUS_FRACTION: f64 = 1e-9;
/// Most placement attempts per circle a spawn rule may ask for: beyond a few hundred, misses
/// mean the arena is full, and more tries only make a full arena slower to give up on.
pub const MAX_ATTEMPTS_PER_CIRCLE: u32 = 10_000;
/// Densest area fraction random placement is asked for (0.907 is the densest packing of equal
/// disks; placement by rejection stalls long before it).
pub const MAX_AREA_FRACTION: f64 = 0.9;

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

    /// Whether masses from this model are positive and finite.
    pub fn check(self) -> Result<(), FieldError> {
        match self {
            Self::Area { density } => {
                if density > 0.0 {
                    check_magnitude("mass", density)
                } else {
                    Err(FieldError::new(
                        "mass",
                        format!("Area density must be positive, got {density:?}"),
                    ))
                }
            }
            Self::Equal(m) => check_mass("mass", m),
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
        // An overflowing estimate saturates to usize::MAX, which the count check refuses.
        if n > 0.0 { n.round() as usize } else { 0 }
    }

    /// Whether these rules can place circles in `arena`: ranges ordered, finite and positive
    /// where they must be, and no more than [`MAX_CIRCLES`] asked for. Fields are named
    /// relative to the spawn rules (`radius`, `count`, …).
    pub fn check(&self, arena: &Arena) -> Result<(), FieldError> {
        let (r0, r1) = self.radius;
        if !(r0.is_finite() && r1.is_finite() && r0 > 0.0 && r0 <= r1) {
            return Err(FieldError::new(
                "radius",
                format!("must be (min, max) with 0 < min <= max, got ({r0}, {r1})"),
            ));
        }
        let smallest = min_radius(arena);
        if r0 < smallest {
            return Err(FieldError::new(
                "radius",
                format!(
                    "must be at least {MIN_RADIUS_FRACTION:?} of the arena's smaller side \
                     ({smallest:?}), got ({r0:?}, {r1:?})"
                ),
            ));
        }
        check_magnitude("radius", r1)?;
        for r in [r0, r1] {
            check_mass("mass", self.mass.mass_of(r)).map_err(|e| {
                FieldError::new(
                    "mass",
                    format!("gives a circle of radius {r:?} a mass that {}", e.message),
                )
            })?;
        }
        let (s0, s1) = self.speed;
        check_magnitude("speed", s1)?;
        if !(s0.is_finite() && s1.is_finite() && s0 >= 0.0 && s0 <= s1) {
            return Err(FieldError::new(
                "speed",
                format!("must be (min, max) with 0 <= min <= max, got ({s0}, {s1})"),
            ));
        }
        if let Some(phi) = self.area_fraction
            && !(phi.is_finite() && phi > 0.0 && phi <= MAX_AREA_FRACTION)
        {
            return Err(FieldError::new(
                "area_fraction",
                format!(
                    "must be in (0, {MAX_AREA_FRACTION}] (0.907 is the densest packing), got {phi}"
                ),
            ));
        }
        let n = self.target_count(arena);
        if n > MAX_CIRCLES {
            return Err(FieldError::new(
                "count",
                format!("asks for {n} circles; at most {MAX_CIRCLES} are supported"),
            ));
        }
        if !(1..=MAX_ATTEMPTS_PER_CIRCLE).contains(&self.attempts_per_circle) {
            return Err(FieldError::new(
                "attempts_per_circle",
                format!(
                    "must be from 1 to {MAX_ATTEMPTS_PER_CIRCLE}, got {}",
                    self.attempts_per_circle
                ),
            ));
        }
        Ok(())
    }
}

/// The smallest radius a circle in `arena` may have ([`MIN_RADIUS_FRACTION`] of its smaller
/// side).
pub fn min_radius(arena: &Arena) -> f64 {
    MIN_RADIUS_FRACTION * arena.size().min_element()
}

/// How one fixed step of simulated time is advanced. Written in scenes and on the command line
/// as `discrete`, `substeps=N`, `swept` or `exact`.
///
/// ```
/// use moving_circles::config::Solver;
///
/// let solver: Solver = "substeps=4".parse().unwrap();
/// assert_eq!((solver, solver.substeps()), (Solver::Substeps(4), 4));
/// assert_eq!(Solver::Exact.to_string(), "exact");
/// assert!("substeps=0".parse::<Solver>().is_err());
/// ```
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
    "unknown solver `{0}`: expected `discrete`, `substeps=N` (N from 1 to {max}), `swept` or `exact`",
    max = MAX_SUBSTEPS
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
                    Ok(n) if (1..=MAX_SUBSTEPS).contains(&n) => Ok(Self::Substeps(n)),
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

/// Everything [`CirclesPlugins`](crate::CirclesPlugins) needs, in one value. Scene files
/// ([`crate::scene`]) are read into this.
#[derive(Clone, Debug, PartialEq)]
pub struct CirclesConfig {
    /// The arena and its edges.
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
    pub circles: Vec<CircleState>,
    /// Segment walls inside the arena (only on an arena with walls).
    pub segments: Segments,
    /// Circles dropped in one at a time while it runs, if any.
    pub drop: Option<DropConfig>,
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
            segments: Segments::default(),
            drop: None,
        }
    }
}

impl CirclesConfig {
    /// Whether the settings can be simulated: a usable arena and step, usable effects, mass
    /// model and spawn rules. (Explicit circles are checked where they are read, since only the
    /// file knows where each came from.)
    pub fn check(&self) -> Result<(), FieldError> {
        let (dt_min, dt_max) = DT_RANGE;
        if !(self.dt.is_finite() && self.dt >= dt_min && self.dt <= dt_max) {
            return Err(FieldError::new(
                "dt",
                format!(
                    "must be between {dt_min} and {dt_max} seconds, got {}",
                    self.dt
                ),
            ));
        }
        self.arena.check()?;
        self.effects.check()?;
        self.spawn.mass.check()?;
        self.segments.check(&self.arena)?;
        if let Some(drop) = &self.drop {
            drop.check(&self.arena).map_err(|e| e.within("drop"))?;
        }
        self.spawn.check(&self.arena).map_err(|e| e.within("spawn"))
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
