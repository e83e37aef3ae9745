//! The region the circles live in: [`Arena`], a rectangle whose edges are walls, periodic or
//! open ([`Boundary`]), and the geometry every solver reads from it: containment, the
//! displacement between two points (the minimum image on a periodic arena) and wrapping back
//! inside.

use std::fmt;
use std::str::FromStr;

use bevy::math::DVec2;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use crate::base::error::FieldError;
use crate::base::range::{MAX_MAGNITUDE, in_range};

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
    /// No edges: circles fly out of the rectangle and on, and meet wherever they are. Walls, if
    /// any, come from segment walls and immovable circles. The rectangle is where the circles
    /// are placed and what the grids cover: circles far outside it share the edge cells, correct
    /// but slower, so it should hold where the circles mostly are.
    Open,
}

impl fmt::Display for Boundary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Walls => "walls",
            Self::Periodic => "periodic",
            Self::Open => "open",
        })
    }
}

impl FromStr for Boundary {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "walls" => Ok(Self::Walls),
            "periodic" => Ok(Self::Periodic),
            "open" => Ok(Self::Open),
            other => Err(format!(
                "unknown boundary `{other}`: expected `walls`, `periodic` or `open`"
            )),
        }
    }
}

/// The axis-aligned rectangle the circles live in, and what its edges do.
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::base::arena::{Arena, Boundary};
///
/// let walls = Arena::centered(DVec2::new(4.0, 2.0));
/// assert_eq!(walls.offset(DVec2::new(-1.9, 0.0), DVec2::new(1.9, 0.0)).x, 3.8);
/// // On a periodic arena the shortest way between those points crosses the seam.
/// let periodic = walls.with_boundary(Boundary::Periodic);
/// assert!((periodic.offset(DVec2::new(-1.9, 0.0), DVec2::new(1.9, 0.0)).x + 0.2).abs() < 1e-12);
/// ```
#[derive(Resource, Reflect, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[reflect(Resource, Debug)]
pub struct Arena {
    /// Lower-left corner.
    pub min: DVec2,
    /// Upper-right corner.
    pub max: DVec2,
    /// Walls, periodic edges or none.
    #[serde(default)]
    pub boundary: Boundary,
}

impl Default for Arena {
    /// A 16:9 arena with walls, 16 units wide, centred on the origin (the seed's window shape).
    fn default() -> Self {
        Self::centered(DVec2::new(16.0, 9.0))
    }
}

impl Arena {
    /// An arena with walls of the given size, centred on the origin.
    pub fn centered(size: DVec2) -> Self {
        Self {
            min: -size / 2.0,
            max: size / 2.0,
            boundary: Boundary::Walls,
        }
    }

    /// The unit square `[0, 1]²` of the plain-text particle format.
    pub fn unit_square(boundary: Boundary) -> Self {
        Self {
            min: DVec2::ZERO,
            max: DVec2::ONE,
            boundary,
        }
    }

    /// The same rectangle with other edges.
    pub fn with_boundary(self, boundary: Boundary) -> Self {
        Self { boundary, ..self }
    }

    /// Whether the edges are periodic.
    #[inline]
    pub fn is_periodic(&self) -> bool {
        self.boundary == Boundary::Periodic
    }

    /// Whether the arena has no edges at all: circles may be anywhere.
    #[inline]
    pub fn is_open(&self) -> bool {
        self.boundary == Boundary::Open
    }

    /// Whether the edges are walls that circles bounce off (and stay within).
    #[inline]
    pub fn has_walls(&self) -> bool {
        self.boundary == Boundary::Walls
    }

    /// Width and height.
    #[inline]
    pub fn size(&self) -> DVec2 {
        self.max - self.min
    }

    /// Area of the arena.
    pub fn area(&self) -> f64 {
        let s = self.size();
        s.x * s.y
    }

    /// The fraction of the arena's area that circles of these radii cover (overlaps counted
    /// twice).
    pub fn area_fraction(&self, radii: impl IntoIterator<Item = f64>) -> f64 {
        radii.into_iter().map(|r| r * r).sum::<f64>() * std::f64::consts::PI / self.area()
    }

    /// Centre of the arena.
    pub fn center(&self) -> DVec2 {
        (self.min + self.max) / 2.0
    }

    /// Whether a point lies inside or on the boundary.
    #[inline]
    pub fn contains(&self, p: DVec2) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// The displacement from `a` to `b`: the minimum image on a periodic arena.
    #[inline]
    pub fn offset(&self, a: DVec2, b: DVec2) -> DVec2 {
        match self.boundary {
            Boundary::Walls | Boundary::Open => b - a,
            Boundary::Periodic => minimum_image(b - a, self.size()),
        }
    }

    /// `p` moved into `[min, max)` on both axes by whole periods.
    pub fn wrap(&self, p: DVec2) -> DVec2 {
        let wrapped = self.min + (p - self.min).rem_euclid(self.size());
        // rem_euclid can round up to exactly `size`; that point is `min` again.
        DVec2::select(wrapped.cmpge(self.max), self.min, wrapped)
    }

    /// Whether the rectangle is usable: finite, with `min < max` on both axes.
    pub fn check(&self) -> Result<(), FieldError> {
        let size = self.size();
        if in_range(self.min) && in_range(self.max) && size.x > 0.0 && size.y > 0.0 {
            Ok(())
        } else {
            Err(FieldError::new(
                "arena",
                format!(
                    "expected corners within ±{MAX_MAGNITUDE:e} with min < max on both axes, \
                     got min ({:?}, {:?}) max ({:?}, {:?})",
                    self.min.x, self.min.y, self.max.x, self.max.y
                ),
            ))
        }
    }
}

/// The shortest displacement `d` can stand for on a periodic arena of this size (minimum image).
///
/// Displacements between wrapped positions are within one box size, which one conditional
/// shift per axis handles; anything larger falls back to rounding (`round` is a libm call,
/// and this sits in the innermost loop of the periodic broad phase).
#[inline]
pub fn minimum_image(d: DVec2, size: DVec2) -> DVec2 {
    let half = size * 0.5;
    let mut r = d;
    for axis in 0..2 {
        if r[axis] > half[axis] {
            r[axis] -= size[axis];
        } else if r[axis] < -half[axis] {
            r[axis] += size[axis];
        }
        if r[axis].abs() > half[axis] {
            return d - size * (d / size).round();
        }
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrapping_lands_inside_and_minimum_image_is_shortest() {
        let arena = Arena::unit_square(Boundary::Periodic);
        for p in [
            DVec2::new(1.2, -0.3),
            DVec2::new(-1e-9, 1.0),
            DVec2::new(7.5, 3.25),
        ] {
            let w = arena.wrap(p);
            assert!(
                w.cmpge(DVec2::ZERO).all() && w.cmplt(DVec2::ONE).all(),
                "{p} → {w}"
            );
        }
        let d = arena.offset(DVec2::new(0.05, 0.9), DVec2::new(0.95, 0.1));
        assert!((d - DVec2::new(-0.1, 0.2)).length() < 1e-12, "{d}");
        assert_eq!(
            arena
                .with_boundary(Boundary::Walls)
                .offset(DVec2::ZERO, DVec2::ONE),
            DVec2::ONE
        );
    }

    #[test]
    fn an_empty_or_infinite_rectangle_is_refused() {
        assert!(Arena::default().check().is_ok());
        for size in [DVec2::new(0.0, 1.0), DVec2::new(1.0, f64::INFINITY)] {
            let err = Arena::centered(size).check().unwrap_err();
            assert_eq!(err.field, "arena");
        }
    }

    #[test]
    fn boundary_names_round_trip() {
        for b in [Boundary::Walls, Boundary::Periodic] {
            assert_eq!(b.to_string().parse::<Boundary>(), Ok(b));
        }
        assert!("wall".parse::<Boundary>().is_err());
    }
}
