//! How circles are spawned: [`SpawnConfig`] (how many, how big, how fast, where), the
//! [`MassModel`] and the [`Placement`] (random spots, or a lattice for dense states), with the
//! limits their one `check` holds them to.

use std::str::FromStr;

use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use super::MAX_CIRCLES;
use crate::base::arena::Arena;
use crate::base::error::FieldError;
use crate::base::lattice::lattice_fits;
use crate::base::range::{check_magnitude, check_mass};

/// Smallest radius, as a fraction of the arena's smaller side: below it the solvers' rounding
/// of positions is the size of the circle, and ratios of radii overflow.
pub const MIN_RADIUS_FRACTION: f64 = 1e-9;
/// Most placement attempts per circle a spawn rule may ask for: beyond a few hundred, misses
/// mean the arena is full, and more tries only make a full arena slower to give up on.
pub const MAX_ATTEMPTS_PER_CIRCLE: u32 = 10_000;
/// Most circles a `pack` placement compresses: about 20 s of compression, and a jam is refused
/// within a few minutes (a stage may take 2000 events per circle before it counts as jammed).
/// Past it, `lattice` fills equal circles at once.
pub const MAX_PACK_CIRCLES: usize = 100_000;
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

/// Placement of circles: how many, how big, how fast, where. Seeded and reproducible.
#[derive(Resource, Reflect, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[reflect(Resource, Debug)]
#[serde(default, deny_unknown_fields)]
pub struct SpawnConfig {
    /// How many circles to place (ignored when `area_fraction` is set); none by default.
    pub count: usize,
    /// Fill this fraction of the arena's area instead of placing `count` circles.
    pub area_fraction: Option<f64>,
    /// Smallest and largest radius; radii are drawn uniformly in between.
    pub radius: (f64, f64),
    /// Smallest and largest speed; directions are uniform.
    pub speed: (f64, f64),
    /// Seed of the random generator: the same seed gives the same circles.
    pub seed: u64,
    /// How masses are assigned. Not read from a scene, whose top-level `mass` gives the masses
    /// of spawned and placed circles alike: a `mass` inside a scene's `spawn` is refused, not
    /// overwritten.
    #[serde(skip)]
    pub mass: MassModel,
    /// Placement attempts per circle before it is given up as not fitting.
    pub attempts_per_circle: u32,
    /// Random spots, the sites of a triangular lattice, or random spots compressed (the last
    /// two for dense states).
    pub placement: Placement,
}

/// Where spawned circles go.
#[derive(Reflect, Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Placement {
    /// Random spots, each circle tried `attempts_per_circle` times: any radii, but a box fills
    /// up near area fraction 0.5 and the rest are skipped.
    #[default]
    Random,
    /// Sites of a triangular lattice fitted to the arena (taken at random when there are more
    /// sites than circles), for equal radii: any area fraction up to the lattice's densest
    /// (about 0.88 in a square box). Velocities are random, so the crystal melts when run.
    Lattice,
    /// Random spots at a quarter of the area (or less), then a Lubachevsky–Stillinger
    /// compression under the event engine grows the circles to their radii: any radii, any area
    /// fraction a compression reaches before it jams (0.85 for equal disks, polycrystalline). A
    /// scene's fixed circles and segment walls are not compressed, so they cannot be packed
    /// around.
    Pack,
}

impl FromStr for Placement {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "random" => Ok(Self::Random),
            "lattice" => Ok(Self::Lattice),
            "pack" => Ok(Self::Pack),
            other => Err(format!(
                "unknown placement `{other}`: expected `random`, `lattice` or `pack`"
            )),
        }
    }
}

impl Default for SpawnConfig {
    /// No circles: the radii, speeds and seed of the course's exercise, for a `count` or an
    /// `area_fraction` to place (the classic scene places 32).
    fn default() -> Self {
        Self {
            count: 0,
            area_fraction: None,
            radius: (0.2, 0.6),
            speed: (1.0, 4.0),
            seed: 1,
            mass: MassModel::default(),
            attempts_per_circle: 200,
            placement: Placement::Random,
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
        if self.placement == Placement::Lattice && r0 != r1 {
            return Err(FieldError::new(
                "radius",
                format!("must be one radius (r, r) for a lattice, got ({r0}, {r1})"),
            ));
        }
        let n = self.target_count(arena);
        if n > MAX_CIRCLES {
            return Err(FieldError::new(
                "count",
                format!("asks for {n} circles; at most {MAX_CIRCLES} are supported"),
            ));
        }
        if self.placement == Placement::Lattice {
            self.check_lattice(arena, n, r0)?;
        }
        if self.placement == Placement::Pack && n > MAX_PACK_CIRCLES {
            return Err(FieldError::new(
                "count",
                format!(
                    "asks `pack` to compress {n} circles; it compresses at most \
                     {MAX_PACK_CIRCLES} (about 20 s); `lattice` places more equal circles at once"
                ),
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

    /// Whether a triangular lattice of `n` circles of radius `r` fits `arena`; if not, says how
    /// dense a lattice it takes.
    fn check_lattice(&self, arena: &Arena, n: usize, r: f64) -> Result<(), FieldError> {
        lattice_fits(arena.size(), arena.is_periodic(), n, r).map_err(|largest| {
            let field = match self.area_fraction {
                Some(_) => "area_fraction",
                None => "count",
            };
            let densest = n as f64 * std::f64::consts::PI * largest * largest / arena.area();
            FieldError::new(
                field,
                format!(
                    "a triangular lattice of {n} circles of radius {r} does not fit the arena: \
                     it takes radius {largest:.6} at most (area fraction {densest:.4})"
                ),
            )
        })
    }
}

/// The smallest radius a circle in `arena` may have ([`MIN_RADIUS_FRACTION`] of its smaller
/// side).
pub fn min_radius(arena: &Arena) -> f64 {
    MIN_RADIUS_FRACTION * arena.size().min_element()
}
