//! Circles as the rest of a game sees them: every circle entity that has a `Transform` (a
//! game's own sprite or mesh, the render plugin's sprites; children follow through Bevy's
//! propagation) gets its [`Position`] copied into the transform's `x` and `y` once per frame,
//! after the fixed steps, smoothed between steps as [`Smoothing`] says.
//!
//! The fixed step runs at its own rate (60 Hz by default) and a display at its own (144 Hz,
//! say): copying the last step's position would show each position for one, two or three
//! frames, a judder. [`Smoothing::Interpolate`] shows instead the point between the last two
//! steps' positions that the time left over after them (`Time<Fixed>::overstep_fraction`)
//! reaches, one step behind the simulation; [`Smoothing::Extrapolate`] carries the last
//! position on along its velocity, with no lag but overshooting at a bounce.
//!
//! A [`Position`] written outside the step (a teleport by a game system) is shown where it was
//! put, never smeared from the old place: each step's start is read when the step begins, and a
//! position that is not the one the last step ended at is shown as it is. Circles without a
//! `Transform` (a headless run's) cost nothing here.
//!
//! The copy runs in `RunFixedMainLoopSystems::AfterFixedMainLoop`, with or without the render
//! plugin, and writes only `x` and `y`: `z`, rotation and scale stay the game's. A
//! [`Smoothing`] component chooses for one circle, [`DefaultSmoothing`] (or
//! [`TransformSyncPlugin`]'s `smoothing`) for the rest. A teleport is a position written from
//! `Update`, or from `FixedUpdate` ordered before
//! [`CircleSystems::Step`].
//! `tests/suite/transform_sync.rs` checks all of it headless at 144 frames a second.
//!
//! ```
//! use bevy::math::DVec2;
//! use bevy::prelude::*;
//! use moving_circles::prelude::*;
//!
//! fn spawn_ball(mut commands: Commands, mut meshes: ResMut<Assets<Mesh>>) {
//!     commands.spawn((
//!         Radius(0.5),
//!         Position(DVec2::new(0.0, 2.0)),
//!         Velocity(DVec2::new(3.0, 0.0)),
//!         Mesh2d(meshes.add(Circle::new(0.5))), // Mesh2d brings a Transform: it follows the ball
//!         Smoothing::Extrapolate,               // this one without the step's lag
//!     ));
//! }
//! # bevy::ecs::system::assert_is_system(spawn_ball);
//! ```

use bevy::math::DVec2;
use bevy::prelude::*;

use crate::base::components::{Position, Velocity};
use crate::step::schedule::{CircleSystems, run_circle_step};

/// How a circle's `Transform` follows its [`Position`] between fixed steps. As a component it
/// chooses for one circle; circles without it follow [`DefaultSmoothing`].
#[derive(Component, Reflect, Clone, Copy, Debug, Default, PartialEq, Eq)]
#[reflect(Component, Default, Debug)]
pub enum Smoothing {
    /// Between the positions of the last two steps, by the time left over after them: smooth,
    /// one step behind.
    #[default]
    Interpolate,
    /// From the last step's position along its velocity by the time left over: no lag, but a
    /// bounce overshoots for a frame.
    Extrapolate,
    /// The last step's position as it is.
    Off,
}

/// The [`Smoothing`] of circles that do not carry their own.
#[derive(Resource, Reflect, Clone, Copy, Debug, Default, PartialEq, Eq)]
#[reflect(Resource, Default, Debug)]
pub struct DefaultSmoothing(pub Smoothing);

/// Where a circle was when the last fixed step began and where that step left it, kept for
/// circles that have a `Transform`.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct StepEnds {
    /// The position at the start of the last step.
    pub start: DVec2,
    /// The position at its end.
    pub end: DVec2,
}

impl StepEnds {
    /// Where a circle now at `now` with `velocity` is shown, `fraction` of a step of `dt`
    /// seconds after the last step's end.
    pub fn shown(
        self,
        now: DVec2,
        velocity: DVec2,
        smoothing: Smoothing,
        fraction: f64,
        dt: f64,
    ) -> DVec2 {
        if now != self.end {
            // Moved since the step ended: a teleport, shown where it was put.
            return now;
        }
        match smoothing {
            Smoothing::Interpolate => self.start.lerp(self.end, fraction),
            Smoothing::Extrapolate => self.end + velocity * (fraction * dt),
            Smoothing::Off => self.end,
        }
    }
}

/// Copies each circle's [`Position`] into its `Transform` after the fixed steps, smoothed; part
/// of [`CirclesPlugins`](crate::CirclesPlugins).
#[derive(Clone, Copy, Debug, Default)]
pub struct TransformSyncPlugin {
    /// The smoothing of circles without a [`Smoothing`] of their own.
    pub smoothing: Smoothing,
}

impl Plugin for TransformSyncPlugin {
    fn build(&self, app: &mut App) {
        app.register_type::<Smoothing>()
            .register_type::<DefaultSmoothing>()
            .insert_resource(DefaultSmoothing(self.smoothing))
            .add_systems(
                FixedUpdate,
                (
                    // In the step's own set, so after whatever a game orders before the
                    // step (a teleport then is the step's start, not a slide from the old
                    // place).
                    record_step_start
                        .in_set(CircleSystems::Step)
                        .before(run_circle_step),
                    record_step_end.after(CircleSystems::Diagnostics),
                ),
            )
            .add_systems(
                RunFixedMainLoop,
                (track_new_circles, sync_transforms)
                    .chain()
                    .in_set(RunFixedMainLoopSystems::AfterFixedMainLoop),
            );
    }
}

/// The position each tracked circle starts the step from (a teleport before the step included).
fn record_step_start(mut circles: Query<(&Position, &mut StepEnds)>) {
    circles.par_iter_mut().for_each(|(position, mut ends)| {
        ends.start = position.0;
    });
}

/// The position the step left each tracked circle at.
fn record_step_end(mut circles: Query<(&Position, &mut StepEnds)>) {
    circles.par_iter_mut().for_each(|(position, mut ends)| {
        ends.end = position.0;
    });
}

/// Circles with a `Transform` not tracked yet.
type Untracked = (With<Transform>, Without<StepEnds>);

/// Starts tracking circles that have gained a `Transform`, from where they are.
fn track_new_circles(mut commands: Commands, new: Query<(Entity, &Position), Untracked>) {
    for (entity, position) in &new {
        let here = StepEnds {
            start: position.0,
            end: position.0,
        };
        commands.entity(entity).insert(here);
    }
}

/// Writes each tracked circle's shown position into its `Transform` (`x` and `y`; `z`, rotation
/// and scale are the game's), touching only the transforms that change.
fn sync_transforms(
    fixed: Res<Time<Fixed>>,
    default: Res<DefaultSmoothing>,
    mut circles: Query<(
        &Position,
        &Velocity,
        &StepEnds,
        Option<&Smoothing>,
        &mut Transform,
    )>,
) {
    let fraction = fixed.overstep_fraction_f64();
    let dt = fixed.timestep().as_secs_f64();
    circles
        .par_iter_mut()
        .for_each(|(position, velocity, ends, smoothing, mut transform)| {
            let smoothing = smoothing.copied().unwrap_or(default.0);
            let shown = ends
                .shown(position.0, velocity.0, smoothing, fraction, dt)
                .as_vec2();
            if transform.translation.truncate() != shown {
                transform.translation.x = shown.x;
                transform.translation.y = shown.y;
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    const ENDS: StepEnds = StepEnds {
        start: DVec2::new(1.0, 2.0),
        end: DVec2::new(3.0, 6.0),
    };

    #[test]
    fn interpolation_runs_from_the_start_of_the_step_to_its_end() {
        let v = DVec2::new(120.0, 240.0);
        let at = |f| ENDS.shown(ENDS.end, v, Smoothing::Interpolate, f, 1.0 / 60.0);
        assert_eq!(at(0.0), ENDS.start);
        assert_eq!(at(0.5), DVec2::new(2.0, 4.0));
        assert_eq!(at(1.0), ENDS.end);
    }

    #[test]
    fn extrapolation_goes_on_along_the_velocity() {
        let v = DVec2::new(60.0, -120.0);
        let at = ENDS.shown(ENDS.end, v, Smoothing::Extrapolate, 0.5, 1.0 / 60.0);
        assert!((at - DVec2::new(3.5, 5.0)).length() < 1e-12);
        let off = ENDS.shown(ENDS.end, v, Smoothing::Off, 0.5, 1.0 / 60.0);
        assert_eq!(off, ENDS.end);
    }

    #[test]
    fn a_position_moved_after_the_step_is_shown_where_it_was_put() {
        let put = DVec2::new(-50.0, 7.0);
        for smoothing in [
            Smoothing::Interpolate,
            Smoothing::Extrapolate,
            Smoothing::Off,
        ] {
            assert_eq!(ENDS.shown(put, DVec2::X, smoothing, 0.7, 0.1), put);
        }
    }
}
