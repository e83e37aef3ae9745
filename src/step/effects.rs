//! The effects a scene can call for, and the registry that keeps exactly those in the schedule.
//!
//! Each effect's plugin (gravity and drag in `forces`, walls, segment walls and periodic edges in
//! `boundary`, collisions in `collide`) owns its systems and hands a recipe for them to
//! [`register_effect`]. The recipe is used at once if the configuration calls for the effect,
//! and again by [`reconcile_effects`] when a change of the effects, the arena or the segment
//! walls switches it on; switching it off removes its systems. This module names no system, so it imports none.

use bevy::ecs::intern::Interned;
use bevy::ecs::schedule::{ScheduleCleanupPolicy, ScheduleConfigs, ScheduleLabel};
use bevy::ecs::system::ScheduleSystem;
use bevy::platform::collections::{HashMap, HashSet};
use bevy::prelude::*;

use crate::base::arena::{Arena, Boundary};
use crate::base::config::Effects;
use crate::base::segment::Segments;

/// One schedulable effect.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Effect {
    /// Constant acceleration.
    Gravity,
    /// Linear drag.
    Drag,
    /// Segment walls inside the arena.
    Segments,
    /// Solid walls.
    Walls,
    /// Periodic edges.
    Periodic,
    /// Circle-circle collisions.
    Collisions,
    /// Circles at rest fall asleep (under gravity).
    Sleep,
}

/// The system set holding one effect's systems.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct EffectSystems(pub Effect);

impl Effect {
    /// Every effect, in schedule order.
    pub const ALL: [Effect; 7] = [
        Effect::Gravity,
        Effect::Drag,
        Effect::Segments,
        Effect::Walls,
        Effect::Periodic,
        Effect::Collisions,
        Effect::Sleep,
    ];

    /// Whether `effects` on an arena with this `boundary` and these `segments` calls for this
    /// effect (segment walls need an arena that is not periodic).
    pub fn is_called_for(self, effects: &Effects, boundary: Boundary, segments: &Segments) -> bool {
        match self {
            Effect::Gravity => effects.gravity.is_some(),
            Effect::Drag => effects.drag.is_some(),
            Effect::Segments => boundary != Boundary::Periodic && !segments.is_empty(),
            Effect::Walls => boundary == Boundary::Walls,
            Effect::Periodic => boundary == Boundary::Periodic,
            Effect::Collisions => effects.collisions,
            Effect::Sleep => effects.sleep.enabled && effects.gravity.is_some(),
        }
    }

    /// The effects `effects` on an arena with this `boundary` and these `segments` calls for,
    /// in schedule order.
    ///
    /// ```
    /// use moving_circles::prelude::*;
    ///
    /// let effects = Effects { collisions: false, ..Effects::default() };
    /// let none = Segments::default();
    /// assert_eq!(Effect::called_for(&effects, Boundary::Walls, &none), [Effect::Walls]);
    /// ```
    pub fn called_for(effects: &Effects, boundary: Boundary, segments: &Segments) -> Vec<Effect> {
        Self::ALL
            .into_iter()
            .filter(|e| e.is_called_for(effects, boundary, segments))
            .collect()
    }

    /// Lower-case name, as reports list it.
    pub fn name(self) -> &'static str {
        match self {
            Effect::Gravity => "gravity",
            Effect::Drag => "drag",
            Effect::Segments => "segments",
            Effect::Walls => "walls",
            Effect::Periodic => "periodic",
            Effect::Collisions => "collisions",
            Effect::Sleep => "sleep",
        }
    }
}

/// Makes an effect's systems, already placed in their sets (the registry adds
/// [`EffectSystems`]).
pub type SystemsRecipe = fn() -> ScheduleConfigs<ScheduleSystem>;

#[derive(Clone, Debug)]
struct Recipe {
    schedules: Vec<Interned<dyn ScheduleLabel>>,
    systems: SystemsRecipe,
}

/// The effects whose plugins are present (each with the recipes of its systems: the effect's
/// own plugin's, and a solver's that takes the effect in its own schedule), and the ones whose
/// systems are in the schedule right now.
#[derive(Resource, Default)]
pub struct EffectRegistry {
    recipes: HashMap<Effect, Vec<Recipe>>,
    scheduled: HashSet<Effect>,
}

impl EffectRegistry {
    /// Whether `effect`'s systems are in the schedule.
    pub fn is_scheduled(&self, effect: Effect) -> bool {
        self.scheduled.contains(&effect)
    }

    /// Whether `effect`'s plugin registered it (a disabled plugin never schedules anything).
    pub fn is_registered(&self, effect: Effect) -> bool {
        self.recipes.contains_key(&effect)
    }
}

/// Registers `effect`'s systems, made by `systems`, for `schedules`; adds them now if the app's
/// [`Effects`], [`Arena`] and [`Segments`] call for the effect. What an effect plugin calls from
/// `build`, and a solver's plugin for an effect it takes in its own schedule (drag, under
/// `swept` and `exact`).
pub fn register_effect(
    app: &mut App,
    effect: Effect,
    schedules: &[Interned<dyn ScheduleLabel>],
    systems: SystemsRecipe,
) {
    let world = app.world();
    let none = Segments::default();
    let segments = world.get_resource::<Segments>().unwrap_or(&none);
    let called_for = world
        .get_resource::<Effects>()
        .zip(world.get_resource::<Arena>())
        .is_some_and(|(effects, arena)| effect.is_called_for(effects, arena.boundary, segments));
    if called_for {
        for &label in schedules {
            app.add_systems(label, systems().in_set(EffectSystems(effect)));
        }
    }
    let mut registry = app.world_mut().get_resource_or_init::<EffectRegistry>();
    registry.recipes.entry(effect).or_default().push(Recipe {
        schedules: schedules.to_vec(),
        systems,
    });
    if called_for {
        registry.scheduled.insert(effect);
    }
}

/// Makes the schedules hold exactly the systems of the registered effects that the world's
/// [`Effects`], [`Arena`] and [`Segments`] call for: adds the missing ones and removes the rest.
/// [`StepPlugin`](crate::step::schedule::StepPlugin) runs it before a fixed step whenever one of them
/// changed (game code, a reloaded scene, the panel): the one path by which the schedule follows.
pub fn reconcile_effects(world: &mut World) {
    let effects = *world.resource::<Effects>();
    let boundary = world.resource::<Arena>().boundary;
    let segments = world
        .get_resource::<Segments>()
        .cloned()
        .unwrap_or_default();
    let registry = world.get_resource_or_init::<EffectRegistry>();
    let recipes = registry.recipes.clone();
    let scheduled = registry.scheduled.clone();
    let wanted: HashSet<Effect> = recipes
        .keys()
        .copied()
        .filter(|e| e.is_called_for(&effects, boundary, &segments))
        .collect();
    let mut labels: Vec<Interned<dyn ScheduleLabel>> = Vec::new();
    for recipe in recipes.values().flatten() {
        for label in &recipe.schedules {
            if !labels.contains(label) {
                labels.push(*label);
            }
        }
    }
    for label in labels {
        world.schedule_scope(label, |world, schedule| {
            for &effect in scheduled.difference(&wanted) {
                if !recipes[&effect]
                    .iter()
                    .any(|r| r.schedules.contains(&label))
                {
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
                for recipe in recipes[&effect].iter() {
                    if recipe.schedules.contains(&label) {
                        schedule.add_systems((recipe.systems)().in_set(EffectSystems(effect)));
                    }
                }
            }
        });
    }
    world.resource_mut::<EffectRegistry>().scheduled = wanted;
}
