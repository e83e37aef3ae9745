//! Sleeping under the time-stepped solvers (`discrete`, `substeps=N`, `soft`): [`SleepPlugin`]
//! schedules `update_sleep` before each step when the scene calls for it (gravity on and
//! [`SleepConfig::enabled`]). Circles touching each other form islands ([`Islands`]); an
//! island whose circles have all been slower than the sleep speed for the sleep time falls
//! asleep (looked for a few times per sleep time, [`CHECKS_PER_SLEEP_TIME`]; velocities
//! zeroed; the solvers then leave its circles where they are, as immovable circles at rest).
//! A sleeping circle wakes, with every sleeping circle joined to it, before the step in which
//! a circle that is not at rest may touch it (within what that circle travels in a step), or
//! when your code writes its position, velocity, radius or mass.
//! Any change of the effects, the arena, the segment walls or the solver wakes every circle.
//!
//! At rest means within `speed · time` radii of where the circle last moved (its anchor):
//! displacement rather than velocity, since the discrete solvers' resting contacts shake by
//! what gravity gives in a substep while going nowhere.

use bevy::ecs::schedule::ScheduleLabel;
use bevy::ecs::system::SystemParam;
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::base::arena::Arena;
use crate::base::collision_layers::CircleFilters;
use crate::base::components::{AngularVelocity, Mass, Position, Radius, Sleep, Velocity};
use crate::base::config::{Effects, SleepConfig, Solver};
use crate::base::segment::Segments;
use crate::step::effects::{Effect, register_effect};
use crate::step::schedule::{CircleSystems, StepTotals};
pub use islands::{IslandScratch, Islands, Resting, TOUCHING, fall_asleep, wake_touched};

pub mod islands;

/// Puts circles at rest to sleep and wakes them, under the time-stepped solvers.
#[derive(Clone, Copy, Debug, Default)]
pub struct SleepPlugin;

impl Plugin for SleepPlugin {
    fn build(&self, app: &mut App) {
        app.register_type::<Sleep>()
            .init_resource::<Sleeping>()
            .add_systems(
                FixedUpdate,
                wake_everyone
                    .before(CircleSystems::Sleep)
                    .run_if(settings_changed),
            );
        register_effect(app, Effect::Sleep, &[FixedUpdate.intern()], || {
            update_sleep.in_set(CircleSystems::Sleep).into_configs()
        });
    }
}

/// How many circles sleep, as of the last step.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Sleeping {
    /// Circles asleep.
    pub count: usize,
}

/// The settings a change of which wakes every circle.
#[derive(SystemParam)]
struct Settings<'w> {
    effects: Res<'w, Effects>,
    arena: Res<'w, Arena>,
    segments: Res<'w, Segments>,
    solver: Res<'w, Solver>,
}

/// Whether the settings changed since the last step (not counting the first: a resumed run
/// keeps the sleep it was checkpointed with).
fn settings_changed(mut seen: Local<bool>, settings: Settings) -> bool {
    let changed = settings.effects.is_changed()
        || settings.arena.is_changed()
        || settings.segments.is_changed()
        || settings.solver.is_changed();
    let first = !std::mem::replace(&mut *seen, true);
    changed && !first
}

/// Wakes every circle.
fn wake_everyone(mut circles: Query<&mut Sleep>, mut sleeping: ResMut<Sleeping>) {
    for mut sleep in &mut circles {
        if sleep.asleep {
            *sleep = Sleep::default();
        }
    }
    sleeping.count = 0;
}

/// Brings a circle's time at rest up to date after a step of `dt`: it rests while it stays
/// within `speed · time` radii of its anchor, and moves its anchor (starting over) when not.
fn rest(sleep: &mut Sleep, config: &SleepConfig, position: DVec2, r: f64, dt: f64) {
    if position.distance(sleep.anchor) <= config.speed * config.time * r {
        sleep.slow_for += dt;
    } else {
        sleep.anchor = position;
        sleep.slow_for = 0.0;
    }
}

/// Checks for islands to put to sleep per sleep time: an island at rest sleeps at most a
/// fifth of the sleep time late, and the steps between pay only for waking.
pub const CHECKS_PER_SLEEP_TIME: f64 = 5.0;

/// Every how many steps of `dt` an island at rest for `time` is looked for.
fn check_every(time: f64, dt: f64) -> u64 {
    let steps = (time / CHECKS_PER_SLEEP_TIME / dt).floor();
    if steps >= 1.0 {
        steps.min(1e6) as u64
    } else {
        1
    }
}

/// Buffers reused from step to step: the circles as the kernels see them, and theirs.
type SleepScratch = (Vec<Resting>, IslandScratch);

/// The circles as sleeping reads and writes them: change detection on what user code may write.
type SleepingCircles<'w, 's> = Query<
    'w,
    's,
    (
        Ref<'static, Position>,
        Mut<'static, Velocity>,
        Ref<'static, Radius>,
        Ref<'static, Mass>,
        &'static mut Sleep,
        Option<Mut<'static, AngularVelocity>>,
    ),
>;

/// The entities of [`SleepingCircles`], in its order (the same components).
type SleepingOnly = (
    With<Position>,
    With<Velocity>,
    With<Radius>,
    With<Mass>,
    With<Sleep>,
);

/// Before each step of a time-stepped solver: wakes sleeping circles that your code moved,
/// advances every awake circle's time at rest, wakes the sleeping circles a circle not at rest
/// touches ([`wake_touched`], every step) and puts islands at rest to sleep ([`fall_asleep`],
/// every [`check_every`] steps, counted from the run's first). A step with no circle asleep
/// and none at rest, or none awake and none moved, looks at each circle once and does nothing
/// else.
fn update_sleep(
    settings: (Res<Effects>, Res<Arena>, Res<Solver>, Res<Time<Fixed>>),
    totals: Res<StepTotals>,
    mut sleeping: ResMut<Sleeping>,
    mut scratch: Local<SleepScratch>,
    (mut circles, entities, filters): (SleepingCircles, Query<Entity, SleepingOnly>, CircleFilters),
) {
    let (effects, arena, solver, time) = settings;
    if solver.is_continuous() {
        return; // the event engine rests its circles itself
    }
    let config = effects.sleep;
    let dt = time.timestep().as_secs_f64();
    let fall = 0.5 * effects.gravity.map_or(0.0, |g| g.length()) * dt * dt;
    let (resting, islands) = &mut *scratch;
    resting.clear();
    let (mut stirring, mut asleep, mut ready) = (false, 0usize, false);
    for (position, velocity, radius, mass, mut sleep, spin) in &mut circles {
        let movable = !mass.is_immovable();
        let moved = |changed: bool, added: bool| changed && !added;
        let spun = spin
            .as_ref()
            .is_some_and(|w| moved(w.is_changed(), w.is_added()));
        if sleep.asleep
            && (moved(position.is_changed(), position.is_added())
                || moved(velocity.is_changed(), velocity.is_added())
                || moved(radius.is_changed(), radius.is_added())
                || moved(mass.is_changed(), mass.is_added())
                || spun)
        {
            *sleep = Sleep::default();
        }
        // An immovable circle that moves or turns (a paddle, a wheel) drives what it touches.
        let turning = spin.as_ref().is_some_and(|w| w.0 != 0.0);
        let pushing = !movable && (velocity.0 != DVec2::ZERO || turning);
        if movable && !sleep.asleep {
            rest(&mut sleep, &config, position.0, radius.0, dt);
            // A circle spinning in place is not at rest: its surface moves (radii per second).
            if spin.as_ref().is_some_and(|w| w.0.abs() > config.speed) {
                (sleep.anchor, sleep.slow_for) = (position.0, 0.0);
            }
            ready |= sleep.slow_for >= config.time;
            stirring |= sleep.slow_for < config.time;
        }
        stirring |= pushing;
        asleep += usize::from(sleep.asleep);
        let travel = if sleep.asleep {
            0.0
        } else {
            velocity.0.length() * dt + if movable { fall } else { 0.0 }
        };
        resting.push(Resting {
            position: position.0,
            radius: radius.0,
            movable,
            pushing,
            sleep: *sleep,
            travel,
        });
    }
    // Layers only if a circle has them, from a query of their own (the same circles in the
    // same order: an entity in the loop above costs a scene without layers 1.5 % of a pile's
    // step).
    islands.layers = filters.gather(entities);
    debug_assert!(islands.layers.is_empty() || islands.layers.len() == resting.len());
    let mut changed = false;
    if asleep > 0 && stirring {
        changed |= !wake_touched(resting, &arena, config.time, islands).is_empty();
    }
    if ready && totals.steps.is_multiple_of(check_every(config.time, dt)) {
        changed |= !fall_asleep(resting, &arena, config.time, islands).is_empty();
    }
    if changed {
        for (i, (_, mut velocity, _, _, mut sleep, spin)) in circles.iter_mut().enumerate() {
            if *sleep != resting[i].sleep {
                *sleep = resting[i].sleep;
                if sleep.asleep && velocity.0 != DVec2::ZERO {
                    velocity.0 = DVec2::ZERO;
                }
                if let Some(mut spin) = spin
                    && sleep.asleep
                    && spin.0 != 0.0
                {
                    spin.0 = 0.0;
                }
            }
        }
    }
    sleeping.count = resting.iter().filter(|c| c.sleep.asleep).count();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn islands_are_looked_for_a_few_times_per_sleep_time_and_at_least_every_step() {
        assert_eq!(check_every(0.5, 1.0 / 60.0), 6);
        assert_eq!(check_every(0.5, 0.5), 1);
        assert_eq!(check_every(0.0, 1.0 / 60.0), 1);
        assert_eq!(check_every(f64::INFINITY, 1.0 / 60.0), 1_000_000);
    }
}
