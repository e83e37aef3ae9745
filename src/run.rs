//! Headless batch runs: build a `MinimalPlugins` app from a configuration, step it a given number
//! of fixed steps as fast as it goes, and report what happened ([`Report`], the JSON that
//! `moving_circles run --report` writes; its fields are a contract other tools rely on).

use std::time::Instant;

use bevy::ecs::schedule::SingleThreadedExecutor;
use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use serde::Serialize;

use crate::CirclesPlugins;
use crate::collide::collision_space;
use crate::components::{Mass, Position, Radius, Tint, Velocity};
use crate::config::{Arena, Boundary, CirclesConfig, Effects};
use crate::diagnostics::{CollisionCounters, Overlaps, Pressure, Totals, relative_change};
use crate::effects::Effect;
use crate::exact::EngineState;
use crate::spawn::{CircleInit, SpawnReport};

/// A headless app for `config`, past `Startup` (circles spawned), in which every `update()`
/// advances exactly one fixed step.
///
/// Every schedule runs on the single-threaded executor: a headless step is a chain of systems
/// with nothing to overlap, and the multi-threaded executor's thread wake-ups in each of the
/// dozen schedules of an `update()` cost more than the stepping of 10 000 circles without
/// collisions (measured: `step_effects/walls_only/10000` 534 µs before, see the README).
/// Kernels that do parallelise (the pair scan) still use the task pools.
pub fn headless_app(config: CirclesConfig) -> App {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, CirclesPlugins::new(config)))
        .insert_resource(TimeUpdateStrategy::FixedTimesteps(1));
    app.finish();
    app.cleanup();
    for (_, schedule) in app.world_mut().resource_mut::<Schedules>().iter_mut() {
        schedule.set_executor(SingleThreadedExecutor::new());
    }
    app.update();
    app
}

/// Every circle's state, in query order.
pub fn snapshot(world: &mut World) -> Vec<CircleInit> {
    world
        .query::<(&Position, &Velocity, &Radius, &Mass, &Tint)>()
        .iter(world)
        .map(|(p, v, r, m, t)| CircleInit {
            position: p.0,
            velocity: v.0,
            radius: r.0,
            mass: m.0,
            tint: t.0,
        })
        .collect()
}

fn totals(world: &mut World) -> Totals {
    let arena = *world.resource::<Arena>();
    let gravity = world.resource::<Effects>().gravity;
    let circles = snapshot(world);
    Totals::measure(
        circles.iter().map(|c| (c.position, c.velocity, c.mass)),
        &arena,
        gravity,
    )
}

/// What a headless run did. Field names and meanings are stable (DESIGN.md).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    /// Where the circles came from (scene or particle file).
    pub source: String,
    /// Number of circles.
    pub n: usize,
    /// Circles the spawn rules asked for (random plus explicit).
    pub requested: usize,
    /// Solver name, e.g. `discrete` or `substeps=4`.
    pub solver: String,
    /// `walls` or `periodic`.
    pub boundary: String,
    /// The effects that had systems.
    pub effects: Vec<String>,
    /// Fixed step in seconds.
    pub dt: f64,
    /// Fixed steps advanced.
    pub steps: u64,
    /// Simulated seconds advanced.
    pub sim_seconds: f64,
    /// Wall-clock seconds of stepping only (not loading or spawning).
    pub wall_seconds: f64,
    /// `wall_seconds / steps` in milliseconds.
    pub ms_per_step: f64,
    /// Mechanical energy (kinetic, plus potential under gravity) at the start.
    pub energy_initial: f64,
    /// Mechanical energy at the end.
    pub energy_final: f64,
    /// `(final - initial) / |initial|`, or the absolute change when the initial energy is 0.
    pub energy_drift: f64,
    /// Total momentum `[x, y]` at the start.
    pub momentum_initial: [f64; 2],
    /// Total momentum at the end.
    pub momentum_final: [f64; 2],
    /// Deepest overlap after any (sampled) step, as a fraction of the pair's smaller radius.
    pub max_penetration: f64,
    /// Mean overlap of the overlapping pairs seen after (sampled) steps, same units.
    pub mean_penetration: f64,
    /// Centres outside the arena at the end.
    pub escaped: usize,
    /// Circles with a non-finite position or velocity at the end.
    pub non_finite: usize,
    /// Circle-circle collisions (impulses).
    pub pair_collisions: u64,
    /// Wall hits.
    pub wall_collisions: u64,
    /// Compressibility factor `P·A / (N·kT)` from the collisional virial.
    pub z: Option<f64>,
    /// Compressibility factor from the momentum the walls took up (walls only).
    pub z_wall: Option<f64>,
    /// Steps of `swept` / `exact` whose event budget ran out (rest of the step free flight).
    pub budget_exhausted: u64,
}

/// Overlaps of the current state (see [`Overlaps`]).
pub fn overlaps(world: &mut World) -> Overlaps {
    let arena = *world.resource::<Arena>();
    let boundary = world.resource::<Effects>().boundary;
    Overlaps::measure(&snapshot(world), collision_space(&arena, boundary))
}

/// Steps `app` `steps` times, calling `progress(done)` now and then, and reports. Overlaps are
/// measured after every step (every 10th above 10 000 circles), outside the timed stepping.
pub fn run_steps(app: &mut App, source: &str, steps: u64, mut progress: impl FnMut(u64)) -> Report {
    let before = totals(app.world_mut());
    let every = (steps / 200).max(1);
    let sample_every = if before.count <= 10_000 { 1 } else { 10 };
    let mut worst = Overlaps::default();
    let (mut overlap_sum, mut sampled_pairs) = (0.0, 0usize);
    let mut wall = std::time::Duration::ZERO;
    for step in 1..=steps {
        let start = Instant::now();
        app.update();
        wall += start.elapsed();
        if step % sample_every == 0 || step == steps {
            let o = overlaps(app.world_mut());
            worst.max = worst.max.max(o.max);
            overlap_sum += o.sum;
            sampled_pairs += o.pairs;
        }
        if step % every == 0 {
            progress(step);
        }
    }
    let wall_seconds = wall.as_secs_f64();
    let world = app.world_mut();
    let after = totals(world);
    let counters = *world.resource::<CollisionCounters>();
    let effects = *world.resource::<Effects>();
    let arena = *world.resource::<Arena>();
    let spawn = *world.resource::<SpawnReport>();
    let pressure = Pressure::measure(
        &counters,
        after.count,
        after.kinetic_energy,
        &arena,
        effects.boundary == Boundary::Walls,
    );
    Report {
        source: source.to_owned(),
        n: after.count,
        requested: spawn.requested,
        solver: world.resource::<crate::config::Solver>().to_string(),
        boundary: match effects.boundary {
            Boundary::Walls => "walls",
            Boundary::Periodic => "periodic",
        }
        .to_owned(),
        effects: Effect::called_for(&effects)
            .iter()
            .map(|e| format!("{e:?}").to_lowercase())
            .collect(),
        dt: world.resource::<Time<Fixed>>().timestep().as_secs_f64(),
        steps: counters.steps,
        sim_seconds: counters.sim_seconds,
        wall_seconds,
        ms_per_step: if steps > 0 {
            1e3 * wall_seconds / steps as f64
        } else {
            0.0
        },
        energy_initial: before.energy(),
        energy_final: after.energy(),
        energy_drift: relative_change(before.energy(), after.energy()),
        momentum_initial: before.momentum.to_array(),
        momentum_final: after.momentum.to_array(),
        max_penetration: worst.max,
        mean_penetration: if sampled_pairs == 0 {
            0.0
        } else {
            overlap_sum / sampled_pairs as f64
        },
        escaped: after.escaped,
        non_finite: after.non_finite,
        pair_collisions: counters.pair_collisions,
        wall_collisions: counters.wall_collisions,
        z: pressure.z_virial,
        z_wall: pressure.z_wall,
        budget_exhausted: world.resource::<EngineState>().budget_exhausted,
    }
}
