//! Radii that grow while the circles fly: the event engine as a Lubachevsky–Stillinger
//! compression. Every radius is `radius·(1 + growth·t)`; pairs meet where their gap closes
//! against the growth, and bounce apart in the frame of their growing surfaces (faster than
//! they came, so a compression heats the circles).

use super::{EventEngine, cell_width};
use crate::base::arena::Arena;
use crate::base::circle::CircleState;

impl EventEngine {
    /// An elastic engine whose circles all grow, radius `r` at `r·(1 + growth·t)`, with cells
    /// wide enough for the radii at `1 + growth·until`. No segment walls; only
    /// [`EventEngine::advance_to`] and [`EventEngine::drift_to`] know about the growth (a
    /// snapshot of it restores without).
    pub fn growing(circles: &[CircleState], arena: &Arena, growth: f64, until: f64) -> Self {
        assert!(growth >= 0.0 && growth.is_finite() && until >= 0.0);
        let scale = 1.0 + growth * until;
        let grown: Vec<CircleState> = circles
            .iter()
            .map(|c| CircleState {
                radius: c.radius * scale,
                ..*c
            })
            .collect();
        let width = cell_width(arena, &grown, &[]);
        let largest = grown.iter().map(|c| c.radius).fold(0.0, f64::max);
        // Cells a largest grown diameter wide hold every circle: none is kept out as large
        // (its reach would be worked out for the radius it starts with).
        let mut engine =
            Self::with_cells(circles, arena, &[], (1.0, 1.0), width.max(2.0 * largest));
        // Predicted once more with the growth: N predictions against the few hundred events
        // per circle a compression takes.
        engine.growth = growth;
        engine.predict_all();
        engine
    }

    /// Multiplies every velocity by `factor` now (a thermostat: a compression heats the
    /// circles), and predicts every circle again.
    pub fn rescale_speeds(&mut self, factor: f64) {
        for i in 0..self.len() {
            self.advance_circle(i, self.now);
            self.motion[i].vel *= factor;
            self.counter[i] += 1;
        }
        self.predict_all();
    }

    /// Circle `i`'s radius now.
    pub fn radius_now(&self, i: usize) -> f64 {
        self.motion[i].radius * (1.0 + self.growth * self.now)
    }
}

#[cfg(test)]
mod tests {
    use bevy::math::DVec2;

    use super::*;
    use crate::base::arena::Boundary;

    #[test]
    fn circles_at_rest_grow_into_each_other_and_part_at_twice_the_growth() {
        // Radii 0.1 growing at 0.5 per unit time (0.05 each), 0.4 apart: the sum 0.2 + 0.1·t
        // reaches 0.4 at t = 2.
        let arena = Arena::unit_square(Boundary::Periodic);
        let circles = [
            CircleState::new(DVec2::new(0.3, 0.5), DVec2::ZERO, 0.1),
            CircleState::new(DVec2::new(0.7, 0.5), DVec2::ZERO, 0.1),
        ];
        let mut engine = EventEngine::growing(&circles, &arena, 0.5, 2.5);
        engine.advance_to(1.999, u64::MAX).unwrap();
        assert_eq!(engine.stats().pair_collisions, 0);
        engine.advance_to(2.001, u64::MAX).unwrap();
        assert_eq!(engine.stats().pair_collisions, 1);
        // Apart in the frame of their surfaces, which close at 0.1: 0.2 apart in all.
        let parting = engine.velocity(1) - engine.velocity(0);
        assert!(
            (parting - DVec2::new(0.2, 0.0)).length() < 1e-15,
            "{parting}"
        );
        assert!((engine.radius_now(0) - 0.1 * (1.0 + 0.5 * 2.001)).abs() < 1e-15);
    }

    #[test]
    fn a_growing_circle_at_rest_meets_the_nearer_wall() {
        // Radius 0.1 growing at 1 (0.1 per unit time), its edge 0.2 from the left wall.
        let arena = Arena::unit_square(Boundary::Walls);
        let circles = [CircleState::new(DVec2::new(0.3, 0.5), DVec2::ZERO, 0.1)];
        let mut engine = EventEngine::growing(&circles, &arena, 1.0, 3.0);
        engine.advance_to(1.999, u64::MAX).unwrap();
        assert_eq!(engine.stats().wall_collisions, 0);
        engine.advance_to(2.001, u64::MAX).unwrap();
        assert_eq!(engine.stats().wall_collisions, 1);
        // Off a wall closing in at 0.1: away at 0.2.
        assert!((engine.velocity(0) - DVec2::new(0.2, 0.0)).length() < 1e-15);
    }
}
