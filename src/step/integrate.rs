//! Free flight: `x += v·dt`, and each circle turned by its angular velocity, over the step's
//! `dt` ([`StepDt`]), in [`CircleSystems::Integrate`].

use bevy::prelude::*;

use crate::base::components::{AngularVelocity, Position, Rotation, Sleep, SpinCircles, Velocity};
use crate::step::schedule::{CircleStep, CircleSystems, StepDt};

/// Moves every circle along its velocity for one (sub)step.
#[derive(Clone, Copy, Debug, Default)]
pub struct IntegratePlugin;

impl Plugin for IntegratePlugin {
    fn build(&self, app: &mut App) {
        app.register_type::<Position>()
            .register_type::<Velocity>()
            .register_type::<Rotation>()
            .register_type::<AngularVelocity>()
            .register_type::<crate::base::components::Inertia>()
            .add_systems(
                CircleStep,
                integrate_positions.in_set(CircleSystems::Integrate),
            );
    }
}

/// The circles as free flight moves them: where they are and how they turn.
type Flying = (
    &'static mut Position,
    &'static Velocity,
    &'static Sleep,
    Option<(&'static mut Rotation, &'static AngularVelocity)>,
);

/// `x += v·dt` for every circle awake, and its rotation turned by `ω·dt` (only circles that
/// turn are written). Each circle is independent, so this runs in parallel.
fn integrate_positions(dt: Res<StepDt>, mut circles: Query<Flying>) {
    let dt = dt.0;
    circles
        .par_iter_mut()
        .for_each(|(mut position, velocity, sleep, spin)| {
            if sleep.asleep {
                return;
            }
            position.0 += velocity.0 * dt;
            if let Some((mut rotation, spin)) = spin
                && spin.0 != 0.0
            {
                *rotation = rotation.turned(spin.0 * dt);
            }
        });
}

/// Turns every circle awake by its angular velocity over `dt` (for a solver that moves the
/// circles itself and changes no spin: `swept`, `exact`); a circle asleep stops turning, as
/// under the other solvers.
pub fn turn_circles(circles: &mut SpinCircles, dt: f64) {
    // Most scenes turn nothing: a look that writes nothing finds out cheaply.
    if !circles.iter().any(|(w, ..)| w.is_some_and(|w| w.0 != 0.0)) {
        return;
    }
    for (spin, rotation, _, _, sleep) in circles.iter_mut() {
        let (Some(mut spin), Some(mut rotation)) = (spin, rotation) else {
            continue;
        };
        if spin.0 == 0.0 {
            continue;
        }
        if sleep.asleep {
            spin.0 = 0.0;
        } else {
            *rotation = rotation.turned(spin.0 * dt);
        }
    }
}
