//! The contact solver for games and piles, `soft` (`soft=N` for `N` substeps, 4 by default):
//! Box2D v3's soft step for circles. Where `discrete` resolves each overlap once, after the
//! fact, `soft` keeps every contact that may close during the step (`contacts.rs`: speculative,
//! so a circle at game speed does not tunnel), makes each a damped spring stiff enough to hold
//! a stack ([`Softness`]), starts each from last step's impulse (warm starting), and solves
//! them all `N` times per step, relaxing after each substep and bouncing once at the end above
//! a restitution threshold (`solve.rs`). Tuned by [`SoftConfig`].
//!
//! [`SoftPlugin`] registers the solver's step, [`SoftStep`], and adds one system to it: gather the circles, step the kernel
//! (`soft_step`), write back what changed. It integrates gravity and drag itself in every
//! substep, and handles the arena's walls, segment walls and collisions, so the effect plugins
//! add nothing to this schedule: what a scene calls for is what the kernel is told to do.

pub(crate) mod bodies;
pub(crate) mod cache;
pub(crate) mod colours;
pub(crate) mod contacts;
pub(crate) mod friction;
mod rules;
pub(crate) mod sequential;
pub(crate) mod solve;
pub(crate) mod stats;

use bevy::ecs::schedule::ScheduleLabel;
use bevy::ecs::system::SystemParam;
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::base::arena::Arena;
use crate::base::collision_layers::CircleFilters;
use crate::base::components::{Friction, Restitution, SolverCircles, SpinCircles};
use crate::base::config::{Effects, SoftConfig, Solver};
use crate::base::hits::PairCollisions;
use crate::base::hits::{CircleHit, HitLog, WallHit};
use crate::base::order::CircleOrder;
use crate::base::segment::{SegmentCells, Segments};
use crate::step::bodies::GatherOwn;
use crate::step::boundary::WallCollisions;
use crate::step::schedule::{SolverStep, StepDt, register_solver};
pub(crate) use bodies::Bodies;
pub use bodies::Softness;
pub use cache::CacheSnapshot;
pub(crate) use cache::ContactCache;
pub(crate) use solve::{SoftParams, SoftScratch, soft_step};
pub(crate) use stats::SoftStats;

/// The schedule of one step of the contact solver: your forces in
/// [`CircleSystems::Forces`](crate::step::schedule::CircleSystems::Forces), then [`SoftSystems`], which integrates gravity and drag itself in
/// every substep.
#[derive(ScheduleLabel, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SoftStep;

/// The contact solver's step itself, in [`SoftStep`] after the forces.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SoftSystems;

/// The contact solver `soft`: its step in [`SoftStep`], run once a fixed step (its substeps
/// are its own).
#[derive(Clone, Copy, Debug, Default)]
pub struct SoftPlugin;

impl Plugin for SoftPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<SoftState>()
            .init_resource::<Segments>()
            .init_resource::<SoftConfig>()
            .init_resource::<PairCollisions>()
            .init_resource::<WallCollisions>()
            .register_type::<Friction>()
            .add_message::<CircleHit>()
            .add_message::<WallHit>();
        let step = SolverStep {
            advances: Solver::is_soft,
            schedule: SoftStep.intern(),
            runs: |_| 1,
        };
        register_solver(app, step, SoftSystems);
        app.add_systems(SoftStep, step_soft.in_set(SoftSystems));
    }
}

/// What the `soft` solver keeps between steps: each contact's impulse (for warm starting), the
/// segment walls' cells, and its buffers.
#[derive(Resource, Default)]
pub struct SoftState {
    cache: ContactCache,
    scratch: SoftScratch,
    bodies: Bodies,
    segment_cells: Option<(Arena, Segments, SegmentCells)>,
    log: HitLog,
    /// What the last step did.
    pub last: SoftStats,
}

impl SoftState {
    /// The contacts and impulses the next step warm starts from.
    pub(crate) fn contacts(&self) -> &ContactCache {
        &self.cache
    }

    /// [`SoftState::contacts`], to put back.
    pub(crate) fn contacts_mut(&mut self) -> &mut ContactCache {
        &mut self.cache
    }

    /// The contact cache as data for a checkpoint of the circles of these `serials` (in the
    /// checkpoint's order), or `None` before the first step.
    pub fn snapshot(&self, serials: &[u64]) -> Option<CacheSnapshot> {
        self.cache.snapshot(serials)
    }

    /// Puts back the contact cache of a checkpoint for the circles of these `serials` (in the
    /// checkpoint's order), so that the next step warm starts as the run would have.
    pub fn restore(&mut self, snapshot: &CacheSnapshot, serials: &[u64]) -> Result<(), String> {
        self.cache = ContactCache::restore(snapshot, serials)?;
        Ok(())
    }
}

/// The segment walls' cells for `segments` in `arena` kept in `kept`, listed again only when
/// either changed.
fn segment_cells<'a>(
    kept: &'a mut Option<(Arena, Segments, SegmentCells)>,
    arena: &Arena,
    segments: &Segments,
) -> &'a SegmentCells {
    let stale = !matches!(kept, Some((a, s, _)) if a == arena && s == segments);
    if stale {
        let cells = SegmentCells::over_arena(&segments.0, arena);
        *kept = Some((*arena, segments.clone(), cells));
    }
    &kept.as_ref().expect("set above").2
}

/// The settings a `soft` step reads.
#[derive(SystemParam)]
struct SoftSetup<'w> {
    solver: Res<'w, Solver>,
    arena: Res<'w, Arena>,
    effects: Res<'w, Effects>,
    segments: Res<'w, Segments>,
    config: Res<'w, SoftConfig>,
    dt: Res<'w, StepDt>,
}

/// Whether any circle has its own restitution, and any its own friction.
type Own<'w, 's> = (
    Query<'w, 's, (), With<Restitution>>,
    Query<'w, 's, (), With<Friction>>,
);

/// Gathers the circles into [`Bodies`], advances them one step with [`soft_step`], writes back
/// what changed, counts collisions and wall hits and, with `effects.hit_messages`, writes
/// their messages.
fn step_soft(
    setup: SoftSetup,
    mut state: ResMut<SoftState>,
    (own, filters): (Own, CircleFilters),
    counted: (ResMut<PairCollisions>, ResMut<WallCollisions>),
    mut messages: (MessageWriter<CircleHit>, MessageWriter<WallHit>),
    (order, mut circles, mut spins): (Res<CircleOrder>, SolverCircles, SpinCircles),
) {
    let SoftSetup {
        solver,
        arena,
        effects,
        segments,
        config,
        dt,
    } = setup;
    let SoftState {
        cache,
        scratch,
        bodies,
        segment_cells: kept_cells,
        log,
        last,
    } = &mut *state;
    let per_circle = (!own.0.is_empty(), !own.1.is_empty());
    let gather = GatherOwn {
        restitution: per_circle.0.then_some(effects.restitution),
        filters: &filters,
    };
    bodies.circles.gather(&order, &circles, &gather, |_, _| {});
    bodies.beside_gathered(order.serials());
    // Spin only where something may turn: friction, or a circle turning already.
    let spinning = effects.has_friction()
        || per_circle.1
        || spins.iter().any(|(w, ..)| w.is_some_and(|w| w.0 != 0.0));
    if spinning {
        gather_spin(bodies, &spins, per_circle.1);
    }
    // Everything asleep or static: nothing can move this step.
    let moving = |i: usize| {
        bodies.inv_mass[i] > 0.0
            || bodies.velocity[i] != DVec2::ZERO
            || bodies.angular_velocity.get(i).is_some_and(|&w| w != 0.0)
    };
    if !(0..bodies.len()).any(moving) {
        *last = SoftStats::default();
        return;
    }
    let params = SoftParams {
        dt: dt.0,
        substeps: solver.substeps(),
        gravity: effects.gravity.unwrap_or_default(),
        drag: effects.drag.unwrap_or(0.0),
        restitution: (effects.restitution, effects.wall_restitution),
        collisions: effects.collisions,
        friction: (effects.friction, effects.wall_friction),
        combine: effects.friction_combine,
        rolling_resistance: effects.rolling_resistance,
        config: *config,
    };
    let cells = segment_cells(kept_cells, &arena, &segments);
    log.clear();
    let record = effects.hit_messages.then_some(&mut *log);
    let stats = soft_step(
        bodies,
        &arena,
        (&segments.0, cells),
        &params,
        (scratch, cache),
        record,
    );
    *last = stats;
    let (mut pairs, mut walls) = counted;
    pairs.count += stats.collisions;
    pairs.virial += stats.virial;
    pairs.immovable_work += stats.immovable_work;
    pairs.immovable_impulse += stats.immovable_impulse;
    walls.count = walls.count.saturating_add(stats.wall_hits);
    walls.impulse += stats.wall_impulse;
    if effects.hit_messages {
        let entity = |i: u32| bodies.entity[i as usize];
        log.send_circle_hits(entity, 0.0, &mut messages.0);
        log.send_wall_hits(entity, 0.0, &mut messages.1);
    }
    bodies.circles.write_back(&order, &mut circles, &arena);
    if !bodies.angular_velocity.is_empty() {
        write_back_spin(bodies, &mut spins);
    }
}

/// Each circle's spin (and own friction, when `own_friction`) into `bodies`, by entity.
fn gather_spin(bodies: &mut Bodies, spins: &SpinCircles, own_friction: bool) {
    bodies.start_turning();
    for i in 0..bodies.len() {
        let entity = bodies.entity[i];
        let (spin, rotation, friction, own) = match spins.get(entity) {
            Ok((spin, rotation, friction, own, _)) => (spin, rotation, friction, own),
            Err(_) => (None, None, None, None),
        };
        if let (Some(spin), Some(rotation)) = (spin, rotation) {
            bodies.turning(i, (spin.0, rotation.0), own.map(|i| i.0));
        }
        if own_friction {
            bodies.friction.push(friction.map_or(f64::NAN, |own| own.0));
        }
    }
}

/// Each circle's new spin and rotation from `bodies`, written only where they changed.
fn write_back_spin(bodies: &Bodies, spins: &mut SpinCircles) {
    for (i, &entity) in bodies.entity.iter().enumerate() {
        let Ok((Some(mut spin), Some(mut rotation), ..)) = spins.get_mut(entity) else {
            continue;
        };
        let (w, angle) = (bodies.angular_velocity[i], bodies.rotation[i]);
        if spin.0 != w {
            spin.0 = w;
        }
        if rotation.0 != angle {
            rotation.0 = angle;
        }
    }
}
