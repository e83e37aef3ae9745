//! The effects a scene can call for, each owning a system set in the [`CircleStep`] schedule,
//! so that exactly the called-for effects have systems — at startup (through the plugins) and
//! after a scene is hot-reloaded ([`reconcile_effects`] adds and removes systems).
//! Also the two force effects themselves: gravity and linear drag.

use bevy::ecs::intern::Interned;
use bevy::ecs::schedule::{ScheduleCleanupPolicy, ScheduleConfigs, ScheduleLabel};
use bevy::ecs::system::ScheduleSystem;
use bevy::platform::collections::HashSet;
use bevy::prelude::*;

use crate::boundary::{bounce_off_walls, wrap_around};
use crate::collide::collide_circles;
use crate::components::Velocity;
use crate::config::{Boundary, Effects};
use crate::schedule::{CircleStep, CircleSystems, ContinuousStep, StepDt};

/// One schedulable effect.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Effect {
    /// Constant acceleration.
    Gravity,
    /// Linear drag.
    Drag,
    /// Solid walls.
    Walls,
    /// Periodic edges.
    Periodic,
    /// Circle-circle collisions.
    Collisions,
}

/// The system set holding one effect's systems.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct EffectSystems(pub Effect);

impl Effect {
    /// Every effect, in schedule order.
    pub const ALL: [Effect; 5] = [
        Effect::Gravity,
        Effect::Drag,
        Effect::Walls,
        Effect::Periodic,
        Effect::Collisions,
    ];

    /// The effects `effects` calls for.
    pub fn called_for(effects: &Effects) -> Vec<Effect> {
        Self::ALL
            .into_iter()
            .filter(|e| match e {
                Effect::Gravity => effects.gravity.is_some(),
                Effect::Drag => effects.drag.is_some(),
                Effect::Walls => effects.boundary == Boundary::Walls,
                Effect::Periodic => effects.boundary == Boundary::Periodic,
                Effect::Collisions => effects.collisions,
            })
            .collect()
    }

    /// The schedules this effect has systems in: forces act under every solver; walls,
    /// periodic edges and collisions are the discrete solvers' (the continuous solvers handle
    /// them inside their own step).
    pub fn schedules(self) -> &'static [Interned<dyn ScheduleLabel>] {
        static BOTH: std::sync::LazyLock<[Interned<dyn ScheduleLabel>; 2]> =
            std::sync::LazyLock::new(|| [CircleStep.intern(), ContinuousStep.intern()]);
        static DISCRETE: std::sync::LazyLock<[Interned<dyn ScheduleLabel>; 1]> =
            std::sync::LazyLock::new(|| [CircleStep.intern()]);
        match self {
            Effect::Gravity | Effect::Drag => &*BOTH,
            _ => &*DISCRETE,
        }
    }

    /// This effect's systems, configured into their sets.
    pub fn systems(self) -> ScheduleConfigs<ScheduleSystem> {
        let set = EffectSystems(self);
        match self {
            // Forces change velocity before the move (semi-implicit Euler); gravity first.
            Effect::Gravity => apply_gravity
                .in_set(set)
                .in_set(CircleSystems::Forces)
                .into_configs(),
            Effect::Drag => apply_drag
                .in_set(set)
                .in_set(CircleSystems::Forces)
                .after(EffectSystems(Effect::Gravity))
                .into_configs(),
            Effect::Walls => bounce_off_walls
                .in_set(set)
                .in_set(CircleSystems::Boundary)
                .into_configs(),
            Effect::Periodic => wrap_around
                .in_set(set)
                .in_set(CircleSystems::Boundary)
                .into_configs(),
            Effect::Collisions => collide_circles
                .in_set(set)
                .in_set(CircleSystems::Collide)
                .into_configs(),
        }
    }
}

/// The effects whose systems are in the schedule right now.
#[derive(Resource, Clone, Debug, Default, PartialEq, Eq)]
pub struct ScheduledEffects(pub HashSet<Effect>);

/// Adds `effect`'s systems to an app being built (what the effect plugins call).
pub fn schedule_effect(app: &mut App, effect: Effect) {
    app.init_resource::<ScheduledEffects>();
    if app
        .world_mut()
        .resource_mut::<ScheduledEffects>()
        .0
        .insert(effect)
    {
        app.add_systems(CircleStep, effect.systems());
    }
}

/// Makes the schedule hold exactly the systems of the effects `effects` calls for: adds the
/// missing ones and removes the rest. Used when a scene is reloaded while running.
pub fn reconcile_effects(world: &mut World, effects: &Effects) {
    let wanted: HashSet<Effect> = Effect::called_for(effects).into_iter().collect();
    let scheduled = world.get_resource_or_init::<ScheduledEffects>().0.clone();
    for label in [CircleStep.intern(), ContinuousStep.intern()] {
        world.schedule_scope(label, |world, schedule| {
            for &effect in scheduled.difference(&wanted) {
                if !effect.schedules().contains(&label) {
                    continue;
                }
                if let Err(e) = schedule.remove_systems_in_set(
                    EffectSystems(effect),
                    world,
                    ScheduleCleanupPolicy::RemoveSystemsOnly,
                ) {
                    warn!("could not remove the {effect:?} systems: {e}");
                }
            }
            for &effect in wanted.difference(&scheduled) {
                if effect.schedules().contains(&label) {
                    schedule.add_systems(effect.systems());
                }
            }
        });
    }
    world.resource_mut::<ScheduledEffects>().0 = wanted;
}

/// Adds gravity (`effects.gravity`) to the schedule.
#[derive(Clone, Copy, Debug, Default)]
pub struct GravityPlugin;

impl Plugin for GravityPlugin {
    fn build(&self, app: &mut App) {
        schedule_effect(app, Effect::Gravity);
    }
}

/// Adds linear drag (`effects.drag`) to the schedule.
#[derive(Clone, Copy, Debug, Default)]
pub struct DragPlugin;

impl Plugin for DragPlugin {
    fn build(&self, app: &mut App) {
        schedule_effect(app, Effect::Drag);
    }
}

/// `v += g·dt` for every circle.
pub fn apply_gravity(effects: Res<Effects>, dt: Res<StepDt>, mut circles: Query<&mut Velocity>) {
    let Some(g) = effects.gravity else { return };
    let dv = g * dt.0;
    circles.par_iter_mut().for_each(|mut v| v.0 += dv);
}

/// `v *= exp(-drag·dt)`: the exact solution of `v' = -drag·v` over the step, so it can never
/// overshoot and reverse a velocity however large `dt` is.
pub fn apply_drag(effects: Res<Effects>, dt: Res<StepDt>, mut circles: Query<&mut Velocity>) {
    let Some(drag) = effects.drag else { return };
    let factor = (-drag * dt.0).exp();
    circles.par_iter_mut().for_each(|mut v| v.0 *= factor);
}
