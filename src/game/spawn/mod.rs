//! Spawning circles: [`SpawnPlugin`] places them at startup and on [`Respawn`] requests, and
//! drops circles in one at a time while the simulation runs ([`DropConfig`]). Where they go is
//! worked out by [`place_circles`], a plain function over plain data.

use bevy::math::DVec2;
use bevy::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::base::arena::Arena;
use crate::base::circle::CircleState;
use crate::base::components::Position;
use crate::base::components::Radius;
use crate::base::config::{DropConfig, SpawnConfig};
use crate::base::segment::Segments;
use crate::step::schedule::CircleSystems;
use crate::step::schedule::{StepTotals, StopRequest};

mod place;

pub use place::{STOP_POLL_PLACED, place_circles, place_circles_until};
use place::{hue_to_rgb, sample_between};

/// Asks for all circles to be replaced by a fresh placement from the current [`SpawnConfig`]
/// (after changing its `count`, say). Handled in `PreUpdate`, so it works while paused.
#[derive(Message, Clone, Copy, Debug, Default)]
pub struct Respawn;

/// How the last placement went: what was asked for and what fit.
#[derive(Resource, Clone, Debug, Default, PartialEq, Eq)]
pub struct SpawnReport {
    /// Circles requested.
    pub requested: usize,
    /// Circles placed (all spawned, unless a stop [interrupted](Self::interrupted) the
    /// spawning).
    pub placed: usize,
    /// Increases with every placement, so observers can tell a reset happened.
    pub generation: u64,
    /// Why no random circles were placed, when the rules could not be followed (a compression
    /// that jammed, say).
    pub refused: Option<String>,
    /// Whether a [`StopRequest`] ended the placement (no random circles were placed) or the
    /// spawning (circles after the last batch were not spawned).
    pub interrupted: bool,
}

/// Circles a scene places exactly, before the random ones.
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct FixedCircles(pub Vec<CircleState>);

/// Spawns the [`FixedCircles`] and random circles from a [`SpawnConfig`] at startup and on
/// every [`Respawn`].
#[derive(Clone, Debug, Default)]
pub struct SpawnPlugin {
    /// Random circles to place.
    pub config: SpawnConfig,
    /// Circles to place exactly as given.
    pub circles: Vec<CircleState>,
    /// Circles to drop in one at a time while it runs.
    pub drop: Option<DropConfig>,
}

impl Plugin for SpawnPlugin {
    fn build(&self, app: &mut App) {
        if let Some(drop) = self.drop {
            app.insert_resource(drop);
        }
        app.register_type::<SpawnConfig>()
            .register_type::<DropConfig>()
            .insert_resource(self.config.clone())
            .insert_resource(FixedCircles(self.circles.clone()))
            .init_resource::<SpawnReport>()
            .init_resource::<Dropped>()
            .add_message::<Respawn>()
            .add_systems(Startup, spawn_circles.in_set(CircleSystems::Spawn))
            .add_systems(
                FixedUpdate,
                drop_circles
                    .run_if(resource_exists::<DropConfig>)
                    .before(CircleSystems::Step),
            )
            .add_systems(
                PreUpdate,
                respawn_circles
                    .run_if(on_message::<Respawn>)
                    .in_set(CircleSystems::Spawn),
            );
    }
}

/// What a placement reads, and the report it writes.
#[derive(bevy::ecs::system::SystemParam)]
struct Placing<'w> {
    arena: Res<'w, Arena>,
    config: Res<'w, SpawnConfig>,
    fixed: Res<'w, FixedCircles>,
    segments: Option<Res<'w, Segments>>,
    report: ResMut<'w, SpawnReport>,
    /// Asked while placing, so a signal does not wait for millions of circles.
    stop: Option<Res<'w, StopRequest>>,
}

/// Spawns the [`FixedCircles`], then random circles placed from the [`SpawnConfig`] around them
/// and clear of the [`Segments`].
fn spawn_circles(mut commands: Commands, placing: Placing) {
    let Placing {
        arena,
        config,
        fixed,
        segments,
        mut report,
        stop,
    } = placing;
    let requested = config.target_count(&arena);
    let walls = segments.as_ref().map_or(&[][..], |s| &s.0[..]);
    let stopped = || stop.as_ref().is_some_and(|s| s.raised());
    let (random, refused) = match place_circles_until(&arena, &config, &fixed.0, walls, stopped) {
        Ok(circles) => (circles, None),
        Err(e) => {
            error!("cannot spawn circles: {e}");
            (Some(Vec::new()), Some(e.to_string()))
        }
    };
    let interrupted = random.is_none() || stopped();
    let random = random.filter(|_| !interrupted).unwrap_or_default();
    if random.len() < requested && !interrupted {
        warn!(
            "placed {} of {requested} random circles: the arena has no room for more without overlap",
            random.len()
        );
    }
    *report = SpawnReport {
        requested: requested + fixed.0.len(),
        placed: random.len() + fixed.0.len(),
        generation: report.generation + 1,
        refused,
        interrupted,
    };
    let mut circles = fixed.0.clone();
    circles.extend(random);
    let stop = stop.map(|s| s.clone());
    commands.queue(move |world: &mut World| spawn_until(world, &circles, stop));
}

/// Spawns `circles` in batches, asking `stop` between them: millions of entities take a
/// second or more to spawn. A stop leaves the rest unspawned and the placement marked
/// [interrupted](SpawnReport::interrupted).
fn spawn_until(world: &mut World, circles: &[CircleState], stop: Option<StopRequest>) {
    for batch in circles.chunks(STOP_POLL_PLACED) {
        if stop.as_ref().is_some_and(StopRequest::raised) {
            world.resource_mut::<SpawnReport>().interrupted = true;
            return;
        }
        world.spawn_batch(batch.iter().map(CircleState::bundle));
    }
}

/// How many circles the [`DropConfig`] has dropped since the last (re)spawn.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Dropped {
    /// Circles dropped.
    pub count: usize,
    /// The [`SpawnReport::generation`] the count belongs to.
    pub generation: u64,
}

/// Drops the next circle of the [`DropConfig`] when its time has come and its spot is free of
/// circles and segment walls (else it waits for a later step).
fn drop_circles(
    mut commands: Commands,
    rules: (Res<DropConfig>, Res<SpawnConfig>),
    totals: Res<StepTotals>,
    report: Res<SpawnReport>,
    segments: Option<Res<Segments>>,
    mut dropped: ResMut<Dropped>,
    circles: Query<(&Position, &Radius)>,
) {
    let (config, spawn) = rules;
    if dropped.generation != report.generation {
        *dropped = Dropped {
            count: 0,
            generation: report.generation,
        };
    }
    let due = dropped.count as f64 * config.every;
    if dropped.count >= config.count || totals.sim_seconds + 1e-9 * config.every < due {
        return;
    }
    let circle = nth_drop(&config, &spawn, dropped.count);
    let (p, r) = (circle.position, circle.radius);
    let taken = circles
        .iter()
        .any(|(q, s)| p.distance_squared(q.0) < (r + s.0) * (r + s.0));
    let walled = segments.is_some_and(|s| s.0.iter().any(|s| s.distance(p) < r));
    if taken || walled {
        return;
    }
    commands.spawn(circle.bundle());
    dropped.count += 1;
}

/// The `k`-th circle `config` drops (from 0), as it enters: where, how fast, how heavy. Each
/// drop has its own random stream, so a drop that waits for its spot tries the same spot again,
/// and what the drops brought in can be counted afterwards from their number alone.
pub fn nth_drop(config: &DropConfig, spawn: &SpawnConfig, k: usize) -> CircleState {
    let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
    rng.set_stream(k as u64);
    let dx = sample_between(&mut rng, -config.spread, config.spread);
    CircleState {
        position: config.position + DVec2::new(dx, 0.0),
        velocity: config.velocity,
        radius: config.radius,
        mass: spawn.mass.mass_of(config.radius),
        tint: hue_to_rgb(rng.random_range(0.0..1.0)),
        angular_velocity: 0.0,
        rotation: 0.0,
    }
}

/// Despawns every circle and places a fresh set.
fn respawn_circles(
    mut commands: Commands,
    mut requests: MessageReader<Respawn>,
    circles: Query<Entity, With<Radius>>,
    placing: Placing,
) {
    requests.clear();
    for entity in &circles {
        commands.entity(entity).despawn();
    }
    spawn_circles(commands, placing);
}
