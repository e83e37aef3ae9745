//! The Lubachevsky–Stillinger compression behind the `pack` placement: circles placed loosely
//! fly and grow under the event engine until they reach the radii asked for, so dense states
//! (a liquid near freezing, a polycrystal) can be started from without overlap.

use bevy::math::DVec2;

use super::engine::EventEngine;
use crate::base::arena::Arena;
use crate::base::circle::CircleState;

/// The area fraction a `pack` placement places circles at before compressing them.
pub const PACK_START_FRACTION: f64 = 0.25;
/// How fast the largest diameter grows during a compression, as a fraction of the circles'
/// speed. Slower packs more orderly, and costs more collisions.
pub const PACK_GROWTH: f64 = 0.02;
/// Stages of a compression: after each the speeds are scaled back to where they started (the
/// bounces off growing surfaces heat the circles, which would slow the compression down).
pub const PACK_STAGES: u32 = 20;
/// Events per circle one stage may take before the compression is given up as jammed: a
/// compression to 0.85 takes about 13 per stage, one to 0.88 about 80 on average.
pub const PACK_EVENTS_PER_CIRCLE: u64 = 2_000;

/// A compression that jammed (collisions came faster than [`PACK_EVENTS_PER_CIRCLE`] allows)
/// before the circles reached their radii.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Jammed {
    /// The area fraction it reached.
    pub reached: f64,
    /// The area fraction it was asked for.
    pub target: f64,
}

/// Grows `loose` circles (clear of each other and of the walls, if any) by `scale` under
/// Lubachevsky–Stillinger dynamics: each flies at the largest loose diameter per unit time in
/// the direction of its own velocity (or, at rest, one of its own), while the radii grow at
/// [`PACK_GROWTH`] of that. Returns the circles at their grown radii, each with its own speed
/// again in the direction the compression left it moving; or `None` if `stop` said so (asked
/// at each stage and every [`STOP_POLL_EVENTS`](super::engine::STOP_POLL_EVENTS) events).
pub fn compress(
    loose: &[CircleState],
    arena: &Arena,
    scale: f64,
    stop: impl Fn() -> bool,
) -> Result<Option<Vec<CircleState>>, Jammed> {
    assert!(scale >= 1.0 && scale.is_finite());
    let n = loose.len();
    let largest = loose.iter().map(|c| c.radius).fold(0.0, f64::max);
    let speed = 2.0 * largest;
    let moving: Vec<CircleState> = loose
        .iter()
        .enumerate()
        .map(|(i, c)| {
            // At rest: a golden-angle turn per circle.
            let direction = c
                .velocity
                .try_normalize()
                .unwrap_or_else(|| DVec2::from_angle(2.399_963 * i as f64));
            CircleState {
                velocity: direction * speed,
                ..*c
            }
        })
        .collect();
    let until = (scale - 1.0) / PACK_GROWTH;
    let mut engine = EventEngine::growing(&moving, arena, PACK_GROWTH, until);
    let budget = PACK_EVENTS_PER_CIRCLE.saturating_mul(n as u64);
    for stage in 1..=PACK_STAGES {
        let end = until * f64::from(stage) / f64::from(PACK_STAGES);
        if stop() {
            return Ok(None);
        }
        if engine.advance_until_stopped(end, budget, &stop).is_err() {
            if stop() {
                return Ok(None);
            }
            let fraction = arena.area_fraction(loose.iter().map(|c| c.radius));
            let grown = |t: f64| fraction * (1.0 + PACK_GROWTH * t).powi(2);
            return Err(Jammed {
                reached: grown(engine.now()),
                target: grown(until),
            });
        }
        let mean_square = (0..n)
            .map(|i| engine.velocity(i).length_squared())
            .sum::<f64>();
        if mean_square > 0.0 {
            engine.rescale_speeds(speed / (mean_square / n as f64).sqrt());
        }
    }
    Ok(Some(
        loose
            .iter()
            .enumerate()
            .map(|(i, c)| CircleState {
                position: engine.position(i),
                velocity: engine.velocity(i).normalize_or_zero() * c.velocity.length(),
                radius: c.radius * scale,
                ..*c
            })
            .collect(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::arena::Boundary;

    #[test]
    fn a_compression_asked_to_stop_gives_up_and_one_never_asked_grows_the_circles() {
        let arena = Arena::unit_square(Boundary::Periodic);
        let loose: Vec<CircleState> = (0..400)
            .map(|i| {
                let at = DVec2::new((i % 20) as f64 + 0.5, (i / 20) as f64 + 0.5) / 20.0;
                CircleState::new(at, DVec2::from_angle(i as f64), 0.01)
            })
            .collect();
        assert_eq!(compress(&loose, &arena, 1.5, || true), Ok(None));
        let grown = compress(&loose, &arena, 1.5, || false).unwrap().unwrap();
        assert!(grown.iter().all(|c| c.radius == 0.015));
    }
}
