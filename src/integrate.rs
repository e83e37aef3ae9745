//! Free flight: `x += v·dt` over the step's `dt` ([`StepDt`]), in [`CircleSystems::Integrate`].

use bevy::prelude::*;

use crate::components::{Position, Sleep, Velocity};
use crate::schedule::{CircleStep, CircleSystems, StepDt};

/// Moves every circle along its velocity for one (sub)step.
#[derive(Clone, Copy, Debug, Default)]
pub struct IntegratePlugin;

impl Plugin for IntegratePlugin {
    fn build(&self, app: &mut App) {
        app.register_type::<Position>()
            .register_type::<Velocity>()
            .add_systems(
                CircleStep,
                integrate_positions.in_set(CircleSystems::Integrate),
            );
    }
}

/// `x += v·dt` for every circle awake. Each circle is independent, so this runs in parallel.
fn integrate_positions(dt: Res<StepDt>, mut circles: Query<(&mut Position, &Velocity, &Sleep)>) {
    let dt = dt.0;
    circles
        .par_iter_mut()
        .for_each(|(mut position, velocity, sleep)| {
            if !sleep.asleep {
                position.0 += velocity.0 * dt;
            }
        });
}
