//! The sites of a triangular lattice fitted to a rectangle: how dense states are made, since
//! random placement stalls near area fraction 0.5. Plain functions over plain data.

use bevy::math::DVec2;

/// Centres for `n` equal circles of radius `r` on a triangular lattice in the rectangle at
/// `origin` of this `size`: rows of `cols` sites `a` apart, every other row shifted by `a/2`,
/// rows `b` apart. On a periodic rectangle the lattice wraps around (an even number of rows);
/// with walls it fits inside `[origin + r, origin + size - r]`. Of all the shapes with room for
/// `n` sites, the one whose closest sites are farthest apart is taken, so the lattice is as near
/// to equilateral as the rectangle allows.
///
/// Returns every site, row by row (at least `n`), or, when even the best shape puts two sites
/// closer than `2r`, the largest radius it could take.
pub fn lattice_sites(
    origin: DVec2,
    size: DVec2,
    periodic: bool,
    n: usize,
    r: f64,
) -> Result<Vec<DVec2>, f64> {
    if n == 0 {
        return Ok(Vec::new());
    }
    let Some(fit) = fit(size, periodic, n, r) else {
        return Err(largest_radius(size, periodic, n, r));
    };
    let mut sites = Vec::with_capacity(fit.cols * fit.rows);
    for j in 0..fit.rows {
        let shift = if j % 2 == 1 { 0.5 } else { 0.0 };
        for i in 0..fit.cols {
            let step = DVec2::new(i as f64 + 0.25 + shift, j as f64 + 0.5);
            sites.push(origin + fit.corner + step * fit.spacing);
        }
    }
    Ok(sites)
}

/// Whether [`lattice_sites`] fits `n` circles of radius `r` in a rectangle of this `size`; if
/// not, the largest radius it would fit (without making the sites).
pub fn lattice_fits(size: DVec2, periodic: bool, n: usize, r: f64) -> Result<(), f64> {
    if n == 0 || fit(size, periodic, n, r).is_some() {
        Ok(())
    } else {
        Err(largest_radius(size, periodic, n, r))
    }
}

/// The largest radius below `r` at which `n` circles fit. With walls the room shrinks as the
/// radius grows, so it is searched for (fitting only gets harder with the radius).
fn largest_radius(size: DVec2, periodic: bool, n: usize, r: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, r);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if fit(size, periodic, n, mid).is_some() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// A lattice that fits: its corner relative to the rectangle's, its spacings (along a row,
/// between rows) and its shape.
struct Fit {
    corner: DVec2,
    spacing: DVec2,
    cols: usize,
    rows: usize,
}

/// The lattice for `n` circles of radius `r`, if it fits.
fn fit(size: DVec2, periodic: bool, n: usize, r: f64) -> Option<Fit> {
    let (corner, room) = if periodic {
        (DVec2::ZERO, size)
    } else {
        (DVec2::splat(r), size - DVec2::splat(2.0 * r))
    };
    if !(room.x > 0.0 && room.y > 0.0) {
        return None;
    }
    let (cols, rows) = best_shape(room, periodic, n);
    let spacing = room / DVec2::new(cols as f64, rows as f64);
    // A hair of slack: sites exactly 2r apart touch, which the solvers accept.
    (closest(spacing.x, spacing.y, cols, rows) >= 2.0 * r * (1.0 - 1e-12)).then_some(Fit {
        corner,
        spacing,
        cols,
        rows,
    })
}

/// The distance between the closest sites of a lattice with spacing `a` along rows and `b`
/// between them: neighbours in a row, in the next row (half a spacing along) or two rows on
/// (straight above, which a flat lattice brings closest).
fn closest(a: f64, b: f64, cols: usize, rows: usize) -> f64 {
    let along = if cols > 1 { a } else { f64::INFINITY };
    let next_row = if rows > 1 {
        (0.25 * a * a + b * b).sqrt()
    } else {
        f64::INFINITY
    };
    let two_rows = if rows > 2 { 2.0 * b } else { f64::INFINITY };
    along.min(next_row).min(two_rows)
}

/// `(cols, rows)` with room for `n` sites whose closest sites are farthest apart (an even
/// number of rows on a periodic rectangle, so the shifted rows wrap around).
fn best_shape(size: DVec2, periodic: bool, n: usize) -> (usize, usize) {
    // Equilateral: b = a·√3/2, so cols/rows = (W/a)/(H/b) = W·√3 / (2H).
    let ideal = (n as f64 * size.x * 3f64.sqrt() / (2.0 * size.y)).sqrt();
    // Within [1, n] whatever the arena's shape (a float past usize::MAX saturates).
    let low = ((ideal / 2.0).floor() as usize).clamp(1, n.max(1));
    let high = ((ideal * 2.0).ceil() as usize).clamp(low, n.max(1));
    let shape = |cols: usize| {
        let mut rows = n.div_ceil(cols);
        if periodic && rows % 2 == 1 {
            rows += 1;
        }
        (cols, rows)
    };
    let spread = |(cols, rows): (usize, usize)| {
        closest(size.x / cols as f64, size.y / rows as f64, cols, rows)
    };
    (low..=high)
        .map(shape)
        .max_by(|&p, &q| spread(p).total_cmp(&spread(q)).then(q.0.cmp(&p.0)))
        .unwrap_or((1, 1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circles_too_big_for_the_rectangle_are_told_how_big_they_may_be() {
        let sites = lattice_sites(DVec2::ZERO, DVec2::ONE, true, 100, 0.04).unwrap();
        assert!(sites.len() >= 100);
        let largest = lattice_sites(DVec2::ZERO, DVec2::ONE, true, 100, 0.06).unwrap_err();
        assert!(largest > 0.04 && largest < 0.06);
    }

    /// The closest distance between any two sites (through the seam when periodic).
    fn closest_pair(sites: &[DVec2], size: DVec2, periodic: bool) -> f64 {
        let mut best = f64::INFINITY;
        for (k, &p) in sites.iter().enumerate() {
            for &q in &sites[k + 1..] {
                let mut d = q - p;
                if periodic {
                    d -= size * (d / size).round();
                }
                best = best.min(d.length());
            }
        }
        best
    }

    #[test]
    fn sites_are_at_least_a_diameter_apart_up_to_the_densest_fraction() {
        for (size, periodic) in [
            (DVec2::ONE, true),
            (DVec2::ONE, false),
            (DVec2::new(3.0, 1.0), true),
            (DVec2::new(1.0, 2.5), false),
        ] {
            for n in [1, 2, 7, 100, 500] {
                // The largest radius the lattice takes, then that radius placed.
                let r = lattice_sites(DVec2::ZERO, size, periodic, n, 10.0).unwrap_err();
                assert!(r > 0.0);
                let sites = lattice_sites(DVec2::ZERO, size, periodic, n, r).unwrap();
                assert!(sites.len() >= n);
                if sites.len() > 1 {
                    let gap = closest_pair(&sites, size, periodic);
                    assert!(
                        gap >= 2.0 * r * (1.0 - 1e-9),
                        "{size} {n}: {gap} < {}",
                        2.0 * r
                    );
                }
                for p in &sites {
                    let (lo, hi) = if periodic {
                        (DVec2::ZERO, size)
                    } else {
                        (DVec2::splat(r), size - DVec2::splat(r))
                    };
                    assert!(p.cmpge(lo).all() && p.cmple(hi).all(), "{p} outside");
                }
            }
        }
    }

    #[test]
    fn arenas_of_any_shape_get_an_answer() {
        for size in [
            DVec2::new(1e12, 1.0),
            DVec2::new(1.0, 1e12),
            DVec2::new(1e300, 1e-300),
        ] {
            for periodic in [true, false] {
                let fits = lattice_fits(size, periodic, 10, 1e-9);
                let sites = lattice_sites(DVec2::ZERO, size, periodic, 10, 1e-9);
                assert_eq!(fits.is_ok(), sites.is_ok(), "{size} {periodic}");
            }
        }
    }

    #[test]
    fn a_square_periodic_box_takes_4096_circles_past_area_fraction_0_85() {
        let r = lattice_sites(DVec2::ZERO, DVec2::ONE, true, 4096, 1.0).unwrap_err();
        let fraction = 4096.0 * std::f64::consts::PI * r * r;
        assert!(fraction > 0.85, "{fraction}");
    }
}
