//! The course's method, `discrete` and `substeps=N`: the step's forces, integration and walls
//! (`crate::step`), then circle-circle collisions. [`DiscretePlugin`] registers the step:
//! [`CircleStep`] run once per substep over `dt / substeps`. [`CollidePlugin`] schedules the collision
//! system when the scene calls for collisions: it gathers the circles into the `pass`'s flat
//! arrays, which finds overlapping pairs with the broad phase and resolves each with the
//! contact kernel (both in `crate::collision`), and scatters the result back. On a periodic
//! arena pairs interact across the seam through the minimum image.

pub(crate) mod pass;

use bevy::ecs::schedule::ScheduleLabel;
use bevy::prelude::*;

use crate::base::arena::Arena;
use crate::base::collision_layers::CircleFilters;
use crate::base::components::{Restitution, SolverCircles};
use crate::base::config::{Effects, Solver};
use crate::base::hits::{CircleHit, HitLog, PairCollisions};
use crate::base::order::CircleOrder;
use crate::step::bodies::GatherOwn;
use crate::step::effects::{Effect, register_effect};
use crate::step::schedule::{
    CircleStep, CircleSystems, SolverStep, StepDt, SubstepStart, register_solver,
};
use pass::{ContactScratch, resolve_all_contacts};

/// The discrete solvers, `discrete` and `substeps=N`: [`CircleStep`] (forces, integration,
/// walls, collisions, each from its own plugin) run once per substep.
#[derive(Clone, Copy, Debug, Default)]
pub struct DiscretePlugin;

impl Plugin for DiscretePlugin {
    fn build(&self, app: &mut App) {
        let step = SolverStep {
            advances: Solver::is_discrete,
            schedule: CircleStep.intern(),
            runs: Solver::substeps,
        };
        let sets = (
            CircleSystems::Integrate,
            CircleSystems::Boundary,
            CircleSystems::Collide,
        );
        register_solver(app, step, sets.chain());
    }
}

/// Resolves overlaps between circles: separation plus restitution impulse (`effects.restitution`),
/// in [`CircleSystems::Collide`]. Without collisions in the scene (or with this plugin disabled)
/// there is no broad phase at all.
#[derive(Clone, Copy, Debug, Default)]
pub struct CollidePlugin;

impl Plugin for CollidePlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<PairCollisions>()
            .add_message::<CircleHit>();
        register_effect(app, Effect::Collisions, &[CircleStep.intern()], || {
            collide_circles
                .in_set(CircleSystems::Collide)
                .into_configs()
        });
    }
}

/// Gathers the circles (with their layers, if any circle has them), resolves their contacts
/// with [`resolve_all_contacts`] and writes back what changed; with `effects.hit_messages`,
/// writes a [`CircleHit`] per collision.
#[allow(clippy::too_many_arguments)]
fn collide_circles(
    arena: Res<Arena>,
    effects: Res<Effects>,
    clock: (Res<StepDt>, Res<SubstepStart>),
    mut counted: ResMut<PairCollisions>,
    mut scratch: Local<ContactScratch>,
    mut log: Local<HitLog>,
    mut messages: MessageWriter<CircleHit>,
    (own_restitution, filters): (Query<(), With<Restitution>>, CircleFilters),
    (order, mut circles): (Res<CircleOrder>, SolverCircles),
) {
    let own = GatherOwn {
        restitution: (!own_restitution.is_empty()).then_some(effects.restitution),
        filters: &filters,
    };
    scratch.bodies.gather(&order, &circles, &own, |_, _| {});
    let record = effects.hit_messages.then_some(&mut *log);
    let stats = resolve_all_contacts(&mut scratch, &arena, effects.restitution, record);
    counted.count += stats.collisions;
    counted.virial += stats.virial;
    counted.immovable_work += stats.immovable_work;
    counted.immovable_impulse += stats.immovable_impulse;
    let bodies = &scratch.bodies;
    if effects.hit_messages {
        let (dt, start) = clock;
        log.send_circle_hits(|i| bodies.entity[i as usize], start.0 + dt.0, &mut messages);
    }
    if stats.contacts > 0 {
        bodies.write_back(&order, &mut circles, &arena);
    }
}
