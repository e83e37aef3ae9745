//! Plain configuration structs for the plugin group: spawning, the solver and its tuning, the
//! effects a scene calls for, and [`CirclesConfig`] holding them with the [`Arena`]. Each is a `Resource` once
//! the plugins are added, so systems and users read (and change) the live settings in one
//! place. Each has one `check`, used by scene files, the command line and spawning alike, and
//! the limits they check against are the constants here.

use std::fmt;
use std::str::FromStr;

use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use crate::base::arena::Arena;
use crate::base::circle::CircleState;
use crate::base::error::FieldError;
pub use crate::base::range::{MAX_MAGNITUDE, MIN_MASS, check_magnitude, check_mass, check_vector};
use crate::base::segment::Segments;
pub use drop::DropConfig;
pub use effects::{Combine, Effects, MAX_FRICTION, SleepConfig};
pub use soft::SoftConfig;
pub use spawn::{
    MAX_AREA_FRACTION, MAX_ATTEMPTS_PER_CIRCLE, MAX_PACK_CIRCLES, MIN_RADIUS_FRACTION, MassModel,
    Placement, SpawnConfig, min_radius,
};

mod drop;
mod effects;
mod soft;
mod spawn;

/// Most circles any input may ask for: random spawns and particle files alike. Checked before
/// anything is allocated, so a file claiming 10¹¹ circles fails at once; and small enough that
/// reading a whole file of this many circles, only to refuse it for an overlap in its last
/// line, stays under 1 GB of memory.
pub const MAX_CIRCLES: usize = 5_000_000;
/// Smallest and largest fixed step in seconds: below 1 ns the fixed clock (nanoseconds) cannot
/// represent it; above a minute nothing sensible is being simulated.
pub const DT_RANGE: (f64, f64) = (1e-9, 60.0);
/// Most substeps `substeps=N` (and `soft=N`) may ask for.
pub const MAX_SUBSTEPS: u32 = 1024;
/// Substeps of `soft` when the name gives none (Box2D v3's default).
pub const SOFT_SUBSTEPS: u32 = 4;

/// How one fixed step of simulated time is advanced. Written in scenes and on the command line
/// as `discrete`, `substeps=N`, `soft` (or `soft=N`), `swept` or `exact`.
///
/// ```
/// use moving_circles::base::config::Solver;
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
    /// The contact solver for games and piles: persistent soft contacts, warm started and
    /// solved `N` times per step with relaxation and a restitution pass ([`SoftConfig`]).
    Soft(u32),
}

impl Solver {
    /// How many substeps one fixed step takes: the step schedule's runs for `substeps=N`, the
    /// contact solver's substeps for `soft=N`, 1 for the others.
    pub fn substeps(self) -> u32 {
        match self {
            Self::Substeps(n) | Self::Soft(n) => n.max(1),
            _ => 1,
        }
    }

    /// Whether this solver advances time continuously (`swept`, `exact`) rather than by moving
    /// and then fixing overlaps.
    pub fn is_continuous(self) -> bool {
        matches!(self, Self::Swept | Self::Exact)
    }

    /// Whether this is the course's method, `discrete` or `substeps=N`: the step schedule run
    /// once per substep.
    pub fn is_discrete(self) -> bool {
        matches!(self, Self::Discrete | Self::Substeps(_))
    }

    /// Whether this is the contact solver, `soft` at any substeps.
    pub fn is_soft(self) -> bool {
        matches!(self, Self::Soft(_))
    }

    /// Whether this solver keeps one event engine from step to step (`exact`; `swept` builds
    /// one afresh each step).
    pub fn keeps_engine(self) -> bool {
        self == Self::Exact
    }

    /// Whether this solver models friction and rolling resistance (the contact solver); the
    /// others ignore them.
    pub fn models_friction(self) -> bool {
        self.is_soft()
    }

    /// Whether this solver models rough hits (a tangential restitution above -1: the event
    /// engine); the others ignore them.
    pub fn models_rough_hits(self) -> bool {
        self.is_continuous()
    }

    /// The solver every study measures the others against: `exact`.
    pub const REFERENCE: Solver = Solver::Exact;

    /// The solvers the app switches between (keys `1` to `5`, and the live panel's buttons).
    pub const APP_CHOICES: [Solver; 5] = [
        Solver::Discrete,
        Solver::Substeps(8),
        Solver::Swept,
        Solver::Exact,
        Solver::Soft(SOFT_SUBSTEPS),
    ];

    /// The settings the accuracy study compares on its gases, cheapest first by design (the
    /// measurement decides); the last, `exact`, is the reference.
    pub const STUDY: [Solver; 9] = [
        Solver::Discrete,
        Solver::Substeps(2),
        Solver::Substeps(4),
        Solver::Substeps(8),
        Solver::Substeps(16),
        Solver::Soft(4),
        Solver::Soft(8),
        Solver::Swept,
        Solver::Exact,
    ];

    /// The settings the accuracy study runs its piles under: the course's, the contact solver
    /// at two substep counts and the event-driven ones.
    pub const PILE_STUDY: [Solver; 7] = [
        Solver::Discrete,
        Solver::Substeps(4),
        Solver::Substeps(16),
        Solver::Soft(4),
        Solver::Soft(8),
        Solver::Swept,
        Solver::Exact,
    ];
}

impl fmt::Display for Solver {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Discrete => write!(f, "discrete"),
            Self::Substeps(n) => write!(f, "substeps={n}"),
            Self::Swept => write!(f, "swept"),
            Self::Exact => write!(f, "exact"),
            Self::Soft(SOFT_SUBSTEPS) => write!(f, "soft"),
            Self::Soft(n) => write!(f, "soft={n}"),
        }
    }
}

/// Why a solver name could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ParseSolverError {
    /// Not one of the solvers' names.
    #[error(
        "unknown solver `{0}`: expected `discrete`, `substeps=N`, `soft`, `soft=N` (N from 1 to {max}), `swept` or `exact`",
        max = MAX_SUBSTEPS
    )]
    Unknown(String),
    /// `substeps=N` or `soft=N` with an `N` that is not a whole number in range.
    #[error(
        "the substeps in `substeps=N` and `soft=N` must be a whole number, N from 1 to {max}, got `{0}`",
        max = MAX_SUBSTEPS
    )]
    Count(String),
}

impl FromStr for Solver {
    type Err = ParseSolverError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim() {
            "discrete" => Ok(Self::Discrete),
            "swept" => Ok(Self::Swept),
            "exact" => Ok(Self::Exact),
            "soft" => Ok(Self::Soft(SOFT_SUBSTEPS)),
            other => {
                let (make, n): (fn(u32) -> Self, _) = match other.split_once('=') {
                    Some(("substeps", n)) => (Self::Substeps, n),
                    Some(("soft", n)) => (Self::Soft, n),
                    _ => return Err(ParseSolverError::Unknown(s.to_owned())),
                };
                match n.trim().parse::<u32>() {
                    Ok(n) if (1..=MAX_SUBSTEPS).contains(&n) => Ok(make(n)),
                    _ => Err(ParseSolverError::Count(s.to_owned())),
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
/// ([`crate::tools::scene`]) are read into this.
///
/// # An open arena
///
/// A game that wants no enclosing walls takes
/// [`Boundary::Open`](crate::base::arena::Boundary::Open): circles fly out of the arena's
/// rectangle and on, and meet each other wherever they are; walls then come from segment walls
/// and immovable circles. The rectangle is still where random circles are placed and what the
/// grids cover (segment walls must lie in it): circles far outside it share its edge cells,
/// which is correct but slower, so size it to where the action mostly is. Under every solver a
/// circle that leaves flies on undisturbed, a pair meets 12 units past the rectangle's edge, a
/// V of segment walls holds a ball while another falls away for good, and a checkpoint with
/// every circle 30 m below the rectangle resumes bit for bit (`tests/suite/open_arena.rs`).
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::prelude::*;
///
/// let config = CirclesConfig {
///     arena: Arena::centered(DVec2::new(40.0, 30.0)).with_boundary(Boundary::Open),
///     segments: Segments(vec![Segment::new(DVec2::new(-10.0, -5.0), DVec2::new(10.0, -5.0))]),
///     effects: Effects { gravity: Some(DVec2::new(0.0, -9.81)), ..Effects::default() },
///     ..CirclesConfig::default()
/// };
/// assert!(config.check().is_ok());
/// ```
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
    /// Segment walls inside the arena's rectangle (walled or open; a periodic arena takes none).
    /// Circles bounce off them under every solver with the arena walls' rule
    /// (`effects.wall_restitution`, combined with a circle's own), turned to the normal at the
    /// wall's nearest point (at an end: from the end to the centre), so a horizontal or
    /// vertical segment behaves exactly like an arena wall. `swept` and `exact` hit a face or an
    /// end at its exact time of impact, so nothing tunnels through a wall of no thickness; a
    /// discrete step sees only where circles end up, and a circle moving 10 diameters a step
    /// goes straight through (`tests/suite/segments.rs`). None: no segment system.
    pub segments: Segments,
    /// Circles dropped in one at a time while it runs, if any.
    pub drop: Option<DropConfig>,
    /// How the `soft` solver's contacts behave.
    pub soft: SoftConfig,
}

impl Default for CirclesConfig {
    /// Nothing spawned, in a 16:9 arena with walls, stepped at 60 Hz with the `discrete` solver:
    /// what the plugin group starts from when a game asks for nothing. The app and the command
    /// line start from the classic scene instead ([`scene::classic`](crate::tools::scene::classic)).
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
            soft: SoftConfig::default(),
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
        // The fixed clock counts whole nanoseconds: a step it would change by more than a
        // millionth (below about half a millisecond, one not near a whole number of them) is
        // refused, not run as another.
        let clock = std::time::Duration::from_secs_f64(self.dt).as_secs_f64();
        if (clock - self.dt).abs() > 1e-6 * self.dt {
            return Err(FieldError::new(
                "dt",
                format!(
                    "the fixed clock counts whole nanoseconds, so {} s would run as {clock} s; \
                     give a step within a millionth of a whole number of nanoseconds",
                    self.dt
                ),
            ));
        }
        self.arena.check()?;
        self.effects.check()?;
        self.soft.check()?;
        self.spawn.mass.check()?;
        self.segments.check(&self.arena)?;
        if let Some(drop) = &self.drop {
            drop.check(&self.arena, self.spawn.mass)
                .map_err(|e| e.within("drop"))?;
        }
        self.spawn
            .check(&self.arena)
            .map_err(|e| e.within("spawn"))?;
        self.check_gravity_scale()
    }

    /// The smallest radius of a circle that moves: of the random circles (if any are placed),
    /// the explicit ones and the dropped ones; `None` if none moves.
    pub fn least_moving_radius(&self) -> Option<f64> {
        let placed = self.spawn.count > 0 || self.spawn.area_fraction.is_some();
        let random = placed.then_some(self.spawn.radius.0);
        let explicit = self
            .circles
            .iter()
            .filter(|c| c.mass.is_finite())
            .map(|c| c.radius);
        let dropped = self.drop.map(|d| d.radius);
        random
            .into_iter()
            .chain(explicit)
            .chain(dropped)
            .reduce(f64::min)
    }

    /// Whether gravity is weak enough for the step and the circles: a circle of the least
    /// radius `r` falls its own radius in about `√(r/g)`, and a step of more than
    /// [`MAX_FALLS_PER_STEP`] of those is refused. The event solvers' work per step grows with
    /// that number (a circle bouncing on a floor), and past it rounding in their event times
    /// reaches the energy; the time-stepped solvers move a circle half a million radii a step
    /// there.
    pub fn check_gravity_scale(&self) -> Result<(), FieldError> {
        let (Some(g), Some(r)) = (self.effects.gravity, self.least_moving_radius()) else {
            return Ok(());
        };
        let falls = self.dt * (g.length() / r).sqrt();
        if falls <= MAX_FALLS_PER_STEP {
            return Ok(());
        }
        let limit = r * (MAX_FALLS_PER_STEP / self.dt).powi(2);
        Err(FieldError::new(
            "effects.gravity",
            format!(
                "|g| = {:e} is too strong for a step of {} s and circles of radius {r}: one would \
                 fall its radius {falls:.0} times a step, at most {MAX_FALLS_PER_STEP}; here \
                 |g| may be at most {limit:.3e} (a shorter dt or larger circles allow more)",
                g.length(),
                self.dt
            ),
        ))
    }
}

/// Most times a circle of the least radius may fall its own radius (`√(r/g)`) in one step
/// ([`CirclesConfig::check`]).
pub const MAX_FALLS_PER_STEP: f64 = 1000.0;

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
            Solver::Soft(4),
            Solver::Soft(12),
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
            "soft=0",
            "soft=",
            "soft=2000",
            "substeps",
        ] {
            let err = bad.parse::<Solver>().unwrap_err();
            assert!(err.to_string().contains(&format!("`{bad}`")), "{err}");
        }
    }
}
