//! The force effects: [`GravityPlugin`] (`v += g·dt`, under the discrete solvers; `swept` and
//! `exact` fly parabolas and `soft` integrates gravity in its substeps) and [`DragPlugin`]
//! (`v *= exp(-drag·dt)`, under the discrete solvers; `swept` and `exact` schedule the same
//! system in their own step, and `soft` applies it itself), in [`CircleSystems::Forces`]
//! before the move. Each schedules its system
//! only when the scene calls for it (`effects.gravity`, `effects.drag`). Immovable circles
//! (static and kinematic) and sleeping ones are left alone.

use bevy::ecs::schedule::{ScheduleConfigs, ScheduleLabel};
use bevy::ecs::system::ScheduleSystem;
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::base::components::{Mass, Sleep, Velocity};
use crate::base::config::Effects;
use crate::step::effects::{Effect, EffectSystems, register_effect};
use crate::step::schedule::{CircleStep, CircleSystems, StepDt};

/// Constant acceleration `effects.gravity`.
#[derive(Clone, Copy, Debug, Default)]
pub struct GravityPlugin;

impl Plugin for GravityPlugin {
    fn build(&self, app: &mut App) {
        // Gravity changes velocity before the move (semi-implicit Euler) in the discrete
        // substep; the event engine flies its parabolas exactly, and the soft solver integrates
        // it in its own substeps.
        register_effect(app, Effect::Gravity, &[CircleStep.intern()], || {
            apply_gravity.in_set(CircleSystems::Forces).into_configs()
        });
    }
}

/// Linear drag at the rate `effects.drag` (1/s), after gravity.
#[derive(Clone, Copy, Debug, Default)]
pub struct DragPlugin;

impl Plugin for DragPlugin {
    fn build(&self, app: &mut App) {
        register_effect(app, Effect::Drag, &[CircleStep.intern()], drag_systems);
    }
}

/// Drag's system, in [`CircleSystems::Forces`] after gravity: what [`DragPlugin`] schedules in
/// [`CircleStep`], and a solver that takes drag from outside in its own schedule.
pub(crate) fn drag_systems() -> ScheduleConfigs<ScheduleSystem> {
    apply_drag
        .in_set(CircleSystems::Forces)
        .after(EffectSystems(Effect::Gravity))
        .into_configs()
}

/// `v += g·dt` for every movable circle.
fn apply_gravity(
    effects: Res<Effects>,
    dt: Res<StepDt>,
    mut circles: Query<(&mut Velocity, &Mass, &Sleep)>,
) {
    let Some(g) = effects.gravity else { return };
    let dv = g * dt.0;
    circles.par_iter_mut().for_each(|(mut v, m, sleep)| {
        if !m.is_immovable() && !sleep.asleep {
            v.0 += dv;
        }
    });
}

/// `v *= exp(-drag·dt)`: the exact solution of `v' = -drag·v` over the step, so it can never
/// overshoot and reverse a velocity however large `dt` is. Immovable circles keep theirs, and
/// sleepers at rest are not written (a write wakes them); a sleeper your code set moving, which
/// this step wakes, is dragged like any moving circle.
fn apply_drag(
    effects: Res<Effects>,
    dt: Res<StepDt>,
    mut circles: Query<(&mut Velocity, &Mass, &Sleep)>,
) {
    let Some(drag) = effects.drag else { return };
    let factor = (-drag * dt.0).exp();
    circles.par_iter_mut().for_each(|(mut v, m, sleep)| {
        if !m.is_immovable() && (!sleep.asleep || v.0 != DVec2::ZERO) {
            v.0 *= factor;
        }
    });
}
