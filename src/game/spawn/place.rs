//! Seeded, non-overlapping placement of circles: random spots, the sites of a triangular
//! lattice, or random spots compressed (`pack`).
//!
//! Placement is rejection sampling against a uniform [`Grid`] of the circles already placed, so
//! each attempt checks a 3×3 block of cells instead of every circle: 100k circles place in well
//! under a second. Work is bounded: each circle gets `attempts_per_circle` tries; when an arena
//! is full the remaining circles are skipped and the shortfall is reported, never looped on.

use bevy::math::DVec2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::base::arena::Arena;
use crate::base::circle::CircleState;
use crate::base::config::{Placement, SpawnConfig};
use crate::base::error::FieldError;
use crate::base::grid::{CellMembers, Grid};
use crate::base::lattice::lattice_sites;
use crate::base::segment::{Segment, SegmentCells};
use crate::solvers::exact::pack::{PACK_START_FRACTION, compress};

/// Places up to [`SpawnConfig::target_count`] non-overlapping circles inside `arena`, largest
/// first, around the `fixed` circles already there (which are not returned) and clear of the
/// segment walls.
///
/// Returns the circles that fit, which is fewer than requested when the arena is too full, or
/// which field of the arena or the rules ([`SpawnConfig::check`]) makes placing impossible.
/// The same config always gives the same circles.
///
/// ```
/// use moving_circles::prelude::*;
/// use moving_circles::game::spawn::place_circles;
///
/// let config = SpawnConfig { count: 100, ..SpawnConfig::default() };
/// let circles = place_circles(&Arena::default(), &config, &[], &[]).unwrap();
/// assert_eq!(circles.len(), 100);
/// assert_eq!(circles, place_circles(&Arena::default(), &config, &[], &[]).unwrap());
/// ```
pub fn place_circles(
    arena: &Arena,
    config: &SpawnConfig,
    fixed: &[CircleState],
    segments: &[Segment],
) -> Result<Vec<CircleState>, FieldError> {
    // Never stopped, so always some.
    place_circles_until(arena, config, fixed, segments, || false).map(Option::unwrap_or_default)
}

/// Circles a placement tries between two looks at [`place_circles_until`]'s stop request.
pub const STOP_POLL_PLACED: usize = 4096;

/// [`place_circles`], asking `stop` every [`STOP_POLL_PLACED`] circles (and through a `pack`
/// compression) whether to give up: `None` when it did. Millions of circles take seconds to
/// place, which a signal must not wait for.
pub fn place_circles_until(
    arena: &Arena,
    config: &SpawnConfig,
    fixed: &[CircleState],
    segments: &[Segment],
    stop: impl Fn() -> bool,
) -> Result<Option<Vec<CircleState>>, FieldError> {
    arena.check()?;
    config.check(arena).map_err(|e| e.within("spawn"))?;
    let (r_min, r_max) = config.radius;
    let (s_min, s_max) = config.speed;

    let count = config.target_count(arena);
    let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
    // Largest first: big circles are the hard ones to fit once the arena fills up.
    let mut radii: Vec<f64> = Vec::with_capacity(count);
    for drawn in 0..count {
        if drawn % STOP_POLL_PLACED == 0 && stop() {
            return Ok(None);
        }
        radii.push(rng.random_range(r_min..=r_max));
    }
    radii.sort_by(|a, b| b.total_cmp(a));
    if stop() {
        return Ok(None);
    }
    // A compression places the circles shrunk by `loose` first, then grows them back.
    let loose = match config.placement {
        Placement::Pack => pack_start(arena, config, &radii, (fixed, segments))?,
        _ => 1.0,
    };

    // Fixed circles can be larger than any random one; the grid's cells must span the largest.
    let largest = fixed.iter().map(|c| c.radius).fold(r_max, f64::max);
    let mut grid = PlacementGrid::new(arena, largest, count + fixed.len());
    let walls = SegmentCells::over_arena(segments, arena);
    let mut placed: Vec<CircleState> = Vec::with_capacity(count + fixed.len());
    for circle in fixed {
        grid.insert(circle.position, placed.len());
        placed.push(*circle);
    }
    let mut sites = match config.placement {
        Placement::Random | Placement::Pack => Vec::new(),
        Placement::Lattice => {
            // The check above made sure the lattice fits.
            let sites = lattice_sites(arena.min, arena.size(), arena.is_periodic(), count, r_min)
                .unwrap_or_default();
            // `count` of the sites at random, kept in row order.
            let take = count.min(sites.len());
            let mut chosen = rand::seq::index::sample(&mut rng, sites.len(), take).into_vec();
            chosen.sort_unstable();
            chosen.into_iter().map(|k| sites[k]).collect()
        }
    }
    .into_iter();
    // The radii of the circles placed, in order.
    let mut drawn = Vec::with_capacity(count);
    for (tried, grown) in radii.into_iter().enumerate() {
        if tried % STOP_POLL_PLACED == 0 && stop() {
            return Ok(None);
        }
        let r = grown * loose;
        let lo = arena.min + DVec2::splat(r);
        let hi = arena.max - DVec2::splat(r);
        if lo.x > hi.x || lo.y > hi.y {
            continue; // larger than the arena
        }
        let free = |p: &DVec2| {
            !grid.overlaps_any(*p, r, &placed) && walls.first_touched(segments, *p, r).is_none()
        };
        let spot = match config.placement {
            Placement::Random | Placement::Pack => (0..config.attempts_per_circle)
                .map(|_| {
                    DVec2::new(
                        sample_between(&mut rng, lo.x, hi.x),
                        sample_between(&mut rng, lo.y, hi.y),
                    )
                })
                .find(free),
            // A site a fixed circle or a segment wall takes is left empty.
            Placement::Lattice => sites.next().filter(free),
        };
        let Some(position) = spot else { continue };
        let speed = sample_between(&mut rng, s_min, s_max);
        let angle = rng.random_range(0.0..std::f64::consts::TAU);
        grid.insert(position, placed.len());
        drawn.push(grown);
        placed.push(CircleState {
            position,
            velocity: DVec2::from_angle(angle) * speed,
            radius: r,
            mass: config.mass.mass_of(grown),
            tint: hue_to_rgb(rng.random_range(0.0..1.0)),
            angular_velocity: 0.0,
            rotation: 0.0,
        });
    }
    let mut random = placed.split_off(fixed.len());
    if loose < 1.0 {
        match grow_back(arena, config, (&random, &drawn, loose), &stop)? {
            Some(grown) => random = grown,
            None => return Ok(None),
        }
    }
    // Spawn in row-major cell order, so circles near each other in space are near each other in
    // memory: the collision pass then walks its arrays mostly in order (at 1M circles this is the
    // difference between cache hits and misses; see docs/performance.md).
    random.sort_by_cached_key(|c| {
        let (x, y) = grid.cell_of(c.position);
        (y, x)
    });
    Ok(Some(random))
}

/// The densest packing of equal disks in the plane covers this much of it (hexagonal, π/√12):
/// no compression gets past it, and walls and mixed radii jam it sooner.
pub const DENSEST_PACKING: f64 = 0.906_899_682_117_108_9;

/// How much a `pack` placement (of `config`) shrinks circles of these `radii` to place them at
/// [`PACK_START_FRACTION`] of the area at most, or why it cannot pack around what is there, or
/// cannot reach that area fraction at all (refused at once, before minutes of compression).
fn pack_start(
    arena: &Arena,
    config: &SpawnConfig,
    radii: &[f64],
    (fixed, segments): (&[CircleState], &[Segment]),
) -> Result<f64, FieldError> {
    if !fixed.is_empty() || !segments.is_empty() {
        return Err(FieldError::new(
            "placement",
            "`pack` compresses the spawned circles alone and would press them into the scene's \
             fixed circles and segment walls: use `random` or `lattice` with those",
        )
        .within("spawn"));
    }
    let fraction = arena.area_fraction(radii.iter().copied());
    if fraction > DENSEST_PACKING {
        let field = match config.area_fraction {
            Some(_) => "area_fraction",
            None => "count",
        };
        return Err(FieldError::new(
            field,
            format!(
                "the circles would cover {fraction:.4} of the arena; no packing of disks covers \
                 more than {DENSEST_PACKING:.4}, so a compression cannot get there: ask for \
                 fewer or smaller circles"
            ),
        )
        .within("spawn"));
    }
    Ok((PACK_START_FRACTION / fraction).sqrt().min(1.0))
}

/// The `loose` circles grown back to their `radii` by a compression, each keeping its speed in
/// the direction the compression left it moving. A jammed compression is an error naming what
/// was asked for and how far it got; `None` if `stop` ended it.
fn grow_back(
    arena: &Arena,
    config: &SpawnConfig,
    (loose, radii, shrunk): (&[CircleState], &[f64], f64),
    stop: impl Fn() -> bool,
) -> Result<Option<Vec<CircleState>>, FieldError> {
    let packed = compress(loose, arena, 1.0 / shrunk, stop).map_err(|jam| {
        let field = match config.area_fraction {
            Some(_) => "area_fraction",
            None => "count",
        };
        FieldError::new(
            field,
            format!(
                "a compression to area fraction {:.4} jammed at {:.4}: ask for fewer or smaller \
                 circles",
                jam.target, jam.reached
            ),
        )
        .within("spawn")
    })?;
    // The radii drawn, not the shrunk ones grown back (which can differ by rounding).
    Ok(packed.map(|mut packed| {
        for (c, &r) in packed.iter_mut().zip(radii) {
            c.radius = r;
        }
        packed
    }))
}

pub(super) fn sample_between(rng: &mut impl Rng, lo: f64, hi: f64) -> f64 {
    if lo < hi {
        rng.random_range(lo..=hi)
    } else {
        lo
    }
}

/// A bright, saturated colour of the given hue in [0, 1).
pub(super) fn hue_to_rgb(hue: f64) -> [u8; 3] {
    let h = hue * 6.0;
    let x = 1.0 - (h % 2.0 - 1.0).abs();
    let (r, g, b) = match h as u32 {
        0 => (1.0, x, 0.0),
        1 => (x, 1.0, 0.0),
        2 => (0.0, 1.0, x),
        3 => (0.0, x, 1.0),
        4 => (x, 0.0, 1.0),
        _ => (1.0, 0.0, x),
    };
    // Lift towards white a little so dark blues stay visible on the dark arena.
    let lift = |c: f64| (255.0 * (0.3 + 0.7 * c)).round() as u8;
    [lift(r), lift(g), lift(b)]
}

/// Circles placed so far, bucketed into square cells at least as wide as the largest diameter,
/// so any overlap of a new circle is with a circle in its own or an adjacent cell.
struct PlacementGrid {
    grid: Grid,
    members: CellMembers,
}

impl PlacementGrid {
    fn new(arena: &Arena, r_max: f64, count: usize) -> Self {
        let size = arena.size();
        // Never more cells than about three per circle: a tiny radius in a big arena must not
        // allocate millions of empty cells, nor a long thin one a row of billions (hence the
        // longer side over the count as well as the area over it).
        let per = count.max(1) as f64;
        let cell = (2.0 * r_max)
            .max((size.x * size.y / per).sqrt())
            .max(size.max_element() / per);
        let cols = ((size.x / cell).ceil() as usize).max(1);
        let rows = ((size.y / cell).ceil() as usize).max(1);
        let grid = Grid::square(arena.min, cell, cols, rows);
        Self {
            members: CellMembers::new(grid.len(), count),
            grid,
        }
    }

    fn cell_of(&self, p: DVec2) -> (usize, usize) {
        self.grid.cell_of(p)
    }

    fn insert(&mut self, p: DVec2, index: usize) {
        let (x, y) = self.grid.cell_of(p);
        self.members.insert(index, self.grid.index(x, y));
    }

    fn overlaps_any(&self, p: DVec2, r: f64, placed: &[CircleState]) -> bool {
        let (x, y) = self.grid.cell_of(p);
        let (cells, len) = self.grid.block(x, y);
        cells[..len].iter().any(|&cell| {
            self.members.members(cell).any(|i| {
                let other = &placed[i];
                let reach = r + other.radius;
                p.distance_squared(other.position) < reach * reach
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_placement_grid_has_at_most_three_cells_per_circle_whatever_the_arena() {
        for (size, r_max, count) in [
            (DVec2::new(1e18, 9.0), 0.1, 32),
            (DVec2::new(9.0, 1e18), 0.1, 32),
            (DVec2::new(1e17, 1e17), 1e-6, 1000),
            (DVec2::new(16.0, 9.0), 0.1, 0),
            (DVec2::new(1e-9, 1e-9), 1e-12, 5_000_000),
        ] {
            let arena = Arena::centered(size);
            let grid = PlacementGrid::new(&arena, r_max, count).grid;
            assert!(
                grid.len() <= 3 * count.max(1) + 1,
                "{size} with {count} circles: {} cells",
                grid.len()
            );
        }
    }

    #[test]
    fn a_placement_asked_to_stop_places_nothing() {
        for placement in [Placement::Random, Placement::Lattice, Placement::Pack] {
            let config = SpawnConfig {
                count: 3 * STOP_POLL_PLACED,
                radius: (0.01, 0.01),
                placement,
                ..SpawnConfig::default()
            };
            let arena = Arena::default();
            let stopped = place_circles_until(&arena, &config, &[], &[], || true).unwrap();
            assert!(stopped.is_none(), "{placement:?}");
            let never = place_circles_until(&arena, &config, &[], &[], || false).unwrap();
            assert_eq!(never.unwrap().len(), 3 * STOP_POLL_PLACED, "{placement:?}");
        }
    }

    #[test]
    fn a_full_arena_places_what_fits_and_stops() {
        let arena = Arena::centered(DVec2::splat(2.0));
        let config = SpawnConfig {
            count: 1000,
            radius: (0.3, 0.3),
            ..Default::default()
        };
        let circles = place_circles(&arena, &config, &[], &[]).unwrap();
        // A 2×2 box holds at most 9 circles of radius 0.3 (3 per row at spacing 0.6 + walls).
        assert!(
            !circles.is_empty() && circles.len() <= 9,
            "{}",
            circles.len()
        );
    }

    #[test]
    fn a_circle_larger_than_the_arena_is_skipped() {
        let arena = Arena::centered(DVec2::splat(1.0));
        let config = SpawnConfig {
            count: 3,
            radius: (0.6, 0.6),
            ..Default::default()
        };
        assert!(place_circles(&arena, &config, &[], &[]).unwrap().is_empty());
    }

    #[test]
    fn bad_ranges_name_the_field() {
        let arena = Arena::default();
        let bad_radius = SpawnConfig {
            radius: (0.5, 0.1),
            ..Default::default()
        };
        let err = place_circles(&arena, &bad_radius, &[], &[]).unwrap_err();
        assert!(err.to_string().starts_with("spawn.radius"), "{err}");
        let bad_speed = SpawnConfig {
            speed: (f64::NAN, 1.0),
            ..Default::default()
        };
        let err = place_circles(&arena, &bad_speed, &[], &[]).unwrap_err();
        assert!(err.to_string().starts_with("spawn.speed"), "{err}");
    }

    #[test]
    fn a_compression_past_the_densest_packing_is_refused_at_once() {
        // 1000 circles of radius 0.1 in a unit square: 31 times its area.
        let arena = Arena::centered(DVec2::ONE);
        let overfull = SpawnConfig {
            count: 1000,
            radius: (0.1, 0.1),
            placement: Placement::Pack,
            ..Default::default()
        };
        let err = place_circles(&arena, &overfull, &[], &[])
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("spawn.count"), "{err}");
        assert!(
            err.contains("cover 31.4") && err.contains("0.9069"),
            "{err}"
        );
    }

    #[test]
    fn colours_are_bright_and_varied() {
        let a = hue_to_rgb(0.0);
        let b = hue_to_rgb(0.5);
        assert_ne!(a, b);
        assert!(a.iter().all(|&c| c >= 76));
    }
}
