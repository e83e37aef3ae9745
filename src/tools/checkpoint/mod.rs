//! Checkpoints: the whole state of a headless run between two steps — the settings, every
//! circle, the counters and clocks, what the report has gathered, and the `exact` engine with
//! its pending events, and what code gave circles of their own — so that `run --resume` goes
//! on bit for bit as the run would have (a game whose circles gained components goes on from
//! the same state, its circles perhaps in another query order: see `own`).
//! Written by `run --checkpoint` through [`write_atomically`](crate::tools::io::write_atomically) in
//! a compact binary form (postcard) that ends in a checksum (`bytes`); read back with a size
//! limit, the checksum and every value checked, so a damaged or forged file is an error naming
//! the file, never a panic.

use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use crate::base::arena::Arena;
use crate::base::circle::{CircleState, snapshot_with_entities};
use crate::base::components::Sleep;
use crate::base::config::{
    CirclesConfig, DropConfig, Effects, MAX_CIRCLES, MassModel, SoftConfig, Solver, SpawnConfig,
    min_radius,
};
use crate::base::error::InputError;
use crate::base::hits::PairCollisions;
use crate::base::order::serials_of;
use crate::base::range::check_mass;
use crate::base::segment::Segments;
use crate::game::spawn::{Dropped, SpawnReport};
use crate::solvers::exact::EngineState;
use crate::solvers::exact::engine::EngineSnapshot;
use crate::solvers::soft::{CacheSnapshot, SoftState};
use crate::step::boundary::WallCollisions;
use crate::step::schedule::StepTotals;
use crate::step::sleep::Sleeping;
use crate::tools::run::{Progress, headless_app};
use crate::tools::scene::check::check_motion;
use bytes::FORMAT;
use own::OwnParts;

/// Most bytes a checkpoint may have: the most circles an input may ask for, each with its
/// engine state, fit.
pub const MAX_CHECKPOINT_BYTES: u64 = 2 << 30;

/// A run's whole state between two steps.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Checkpoint {
    format: String,
    /// The scene or particle file the run began from.
    pub source: String,
    arena: Arena,
    solver: Solver,
    effects: Effects,
    soft: SoftConfig,
    dt: f64,
    segments: Segments,
    drop: Option<DropConfig>,
    /// The spawn rules' mass model, which gives dropped circles their mass.
    mass: MassModel,
    dropped: usize,
    requested: usize,
    circles: Vec<CircleState>,
    /// Each circle's sleep, in the order of `circles`.
    sleep: Vec<Sleep>,
    steps: StepTotals,
    pairs: PairCollisions,
    walls: WallCollisions,
    budget_exhausted: u64,
    progress: Progress,
    engine: Option<EngineSnapshot>,
    /// The `soft` solver's contacts and impulses, for warm starting.
    contacts: Option<CacheSnapshot>,
    /// What circles have of their own that code gave them (restitution, friction, inertia,
    /// layers, sensors), for those that have any.
    own: Vec<OwnParts>,
    /// Circles dropped when the run began ([`Progress::drops_before`]; last, so that it was
    /// added to the layout at its end).
    drops_before: usize,
}

impl Checkpoint {
    /// The state of the headless run in `world`, begun from `source`, with `progress`.
    pub fn take(world: &mut World, source: &str, progress: &Progress) -> Self {
        let with_entities = snapshot_with_entities(world);
        let setup = (
            *world.resource::<Arena>(),
            *world.resource::<Effects>(),
            *world.resource::<Solver>(),
        );
        let entities: Vec<Entity> = with_entities.iter().map(|(e, _)| *e).collect();
        let own = own::gather(world, &entities);
        let state = world.resource::<EngineState>();
        // A restored engine has no layers: where circles have them it is not kept, and the
        // resumed run builds one (as the next step would on seeing them changed).
        let engine = if own.iter().all(|p| p.layers.is_none()) {
            state.snapshot(setup, world.resource::<Segments>(), &with_entities)
        } else {
            None
        };
        let budget_exhausted = state.budget_exhausted;
        let circles: Vec<CircleState> = with_entities.into_iter().map(|(_, c)| c).collect();
        let contacts = if world.resource::<Solver>().is_soft() {
            world
                .resource::<SoftState>()
                .snapshot(&serials_of(world, &entities))
        } else {
            None
        };
        Self {
            format: FORMAT.to_owned(),
            source: source.to_owned(),
            arena: *world.resource::<Arena>(),
            solver: *world.resource::<Solver>(),
            effects: *world.resource::<Effects>(),
            soft: *world.resource::<SoftConfig>(),
            dt: world.resource::<Time<Fixed>>().timestep().as_secs_f64(),
            segments: world.resource::<Segments>().clone(),
            drop: world.get_resource::<DropConfig>().copied(),
            mass: world.resource::<SpawnConfig>().mass,
            dropped: world.resource::<Dropped>().count,
            requested: world.resource::<SpawnReport>().requested,
            sleep: entities
                .iter()
                .zip(&circles)
                .map(|(&e, c)| {
                    // A sleeper your code set moving or turning since the last step wakes in
                    // the next one: written awake, as that step makes it (the reader refuses
                    // a sleeper that moves).
                    let sleep = world.get::<Sleep>(e).copied().unwrap_or_default();
                    let stirred =
                        c.velocity != bevy::math::DVec2::ZERO || c.angular_velocity != 0.0;
                    if sleep.asleep && stirred {
                        Sleep::default()
                    } else {
                        sleep
                    }
                })
                .collect(),
            circles,
            steps: *world.resource::<StepTotals>(),
            pairs: *world.resource::<PairCollisions>(),
            walls: *world.resource::<WallCollisions>(),
            budget_exhausted,
            // What the progress knows of its last sample is not kept (a resumed run has not
            // sampled), so a checkpoint equals itself read back.
            progress: Progress {
                last_sample: None,
                ..*progress
            },
            engine,
            contacts,
            own,
            drops_before: progress.drops_before,
        }
    }

    /// Every circle, in spawn order.
    pub fn circles(&self) -> &[CircleState] {
        &self.circles
    }

    /// The arena the circles are in.
    pub fn arena(&self) -> &Arena {
        &self.arena
    }

    /// The segment walls.
    pub fn segments(&self) -> &Segments {
        &self.segments
    }

    /// The solver the run goes on with.
    pub fn solver(&self) -> Solver {
        self.solver
    }

    /// The fixed step, in seconds.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The fixed steps the run had advanced.
    pub fn steps(&self) -> u64 {
        self.steps.steps
    }

    /// Whether the settings and every value are usable (the settings through the same checks
    /// as a scene's; circles within the physical range). Says what is wrong. What the reader
    /// applies, and what `moving_circles run` applies before it writes one.
    pub(crate) fn check(&self) -> Result<(), String> {
        let describe =
            |e: crate::base::error::FieldError| format!("field `{}`: {}", e.field, e.message);
        self.config().check().map_err(describe)?;
        if self.circles.len() > MAX_CIRCLES {
            return Err(format!(
                "holds {} circles; at most {MAX_CIRCLES} are supported",
                self.circles.len()
            ));
        }
        if self.sleep.len() != self.circles.len() {
            return Err(format!(
                "holds the sleep of {} circles for {}",
                self.sleep.len(),
                self.circles.len()
            ));
        }
        if let Some(i) = self
            .sleep
            .iter()
            .position(|s| !(s.slow_for >= 0.0 && s.slow_for.is_finite()))
        {
            return Err(format!(
                "circle {i} has been at rest for {} s",
                self.sleep[i].slow_for
            ));
        }
        for (i, c) in self.circles.iter().enumerate() {
            // Immovable circles (static pegs, kinematic paddles) have an infinite mass.
            match c.mass {
                f64::INFINITY => Ok(()),
                m => check_mass("mass", m),
            }
            .map_err(|e| e.within(&format!("circles[{i}]")))
            .map_err(describe)?;
            // The radii a scene may give (a radius below the rounding of positions has
            // overlaps no float can measure).
            let radii = min_radius(&self.arena)..=0.5 * self.arena.size().min_element();
            if !radii.contains(&c.radius) {
                return Err(format!(
                    "circle {i} has an impossible radius {:?}",
                    c.radius
                ));
            }
            check_motion(c)
                .map_err(|e| e.within(&format!("circles[{i}]")))
                .map_err(describe)?;
            // A circle asleep is at rest (every solver stops one it puts to sleep): one moving
            // or turning would drive its neighbours, a turning one like a wheel.
            let (v, w) = (c.velocity, c.angular_velocity);
            if self.sleep[i].asleep && (w != 0.0 || v != bevy::math::DVec2::ZERO) {
                let how = if w != 0.0 {
                    format!("turns at {w:?}")
                } else {
                    format!("moves at {v}")
                };
                return Err(format!("circle {i} is asleep but {how}"));
            }
            // Every step ends with each centre inside (put back or wrapped): one outside means
            // the circle or the arena was changed. An open arena lets circles go anywhere.
            if !self.arena.is_open() && !self.arena.contains(c.position) {
                return Err(format!("circle {i} at {} is outside the arena", c.position));
            }
        }
        if self.drops_before > self.dropped {
            return Err(format!(
                "{} circles dropped when the run began, more than the {} dropped since",
                self.drops_before, self.dropped
            ));
        }
        let p = &self.progress;
        let numbers = [
            self.steps.sim_seconds,
            self.pairs.virial,
            self.walls.impulse,
            p.before.kinetic_energy,
            p.before.rotational_energy,
            p.before.angular_momentum,
            p.before.potential_energy,
            p.before.momentum.x,
            p.before.momentum.y,
            p.overlaps.max,
            p.overlaps.sum,
        ];
        if numbers.iter().any(|x| !x.is_finite()) {
            return Err("a counter or total is not finite".to_owned());
        }
        // Energies of motion and of turning are never below zero (that of height may be, in an
        // open arena), and their sum is the report's first energy (the fuzz target's find: two
        // of -1.2e308 summed to -∞, which every report of the run then carried).
        let b = &p.before;
        if b.kinetic_energy < 0.0 || b.rotational_energy < 0.0 || !b.energy().is_finite() {
            return Err("its first energies are below zero or sum past the range".to_owned());
        }
        // The clock is the sum of `steps` steps of `dt`, to the rounding of such a sum: a clock
        // run backwards or far ahead would change how finely event times resolve.
        let clock = self.steps.steps as f64 * self.dt;
        let rounding = (self.steps.steps as f64 + 1.0) * f64::EPSILON * clock;
        if (self.steps.sim_seconds - clock).abs() > rounding {
            return Err(format!(
                "its clock {:?} s is not {} steps of {:?} s",
                self.steps.sim_seconds, self.steps.steps, self.dt
            ));
        }
        own::check(&self.own, self.circles.len())?;
        // No engine under `exact` is a build a signal stopped: the next step builds one.
        if self.engine.is_some() && !self.solver.keeps_engine() {
            return Err("the engine state does not match the solver".to_owned());
        }
        if let Some(contacts) = &self.contacts {
            if !self.solver.is_soft() {
                return Err("it holds soft contacts for another solver".to_owned());
            }
            contacts.check(&self.circles)?;
            if let Some(k) = contacts
                .segments()
                .find(|&k| k as usize >= self.segments.0.len())
            {
                return Err(format!(
                    "a cached contact names segment wall {k}, which is not there"
                ));
            }
        }
        Ok(())
    }

    /// The settings, with the circles as explicit circles and nothing random.
    fn config(&self) -> CirclesConfig {
        CirclesConfig {
            arena: self.arena,
            spawn: SpawnConfig {
                count: 0,
                mass: self.mass,
                ..SpawnConfig::default()
            },
            solver: self.solver,
            effects: self.effects,
            dt: self.dt,
            circles: self.circles.clone(),
            segments: self.segments.clone(),
            drop: self.drop,
            soft: self.soft,
        }
    }

    /// A headless app in the checkpoint's state, and the run's progress, ready for the next
    /// step. `origin` names the checkpoint in errors.
    pub fn resume(self, origin: &str) -> Result<(App, Progress), InputError> {
        let mut app = headless_app(self.config());
        let world = app.world_mut();
        world.insert_resource(self.steps);
        world.insert_resource(self.pairs);
        world.insert_resource(self.walls);
        world.resource_mut::<SpawnReport>().requested = self.requested;
        let generation = world.resource::<SpawnReport>().generation;
        world.insert_resource(Dropped {
            count: self.dropped,
            generation,
        });
        let circles = snapshot_with_entities(world);
        if circles.iter().map(|(_, c)| c).ne(self.circles.iter()) {
            return Err(InputError::whole(
                origin,
                "its circles did not come back as they were written",
            ));
        }
        let entities: Vec<Entity> = circles.iter().map(|&(e, _)| e).collect();
        own::apply(&self.own, world, &entities);
        for (&(entity, _), &sleep) in circles.iter().zip(&self.sleep) {
            if let Some(mut kept) = world.get_mut::<Sleep>(entity) {
                *kept = sleep;
            }
        }
        world.resource_mut::<Sleeping>().count = self.sleep.iter().filter(|s| s.asleep).count();
        if let Some(contacts) = &self.contacts {
            let serials = serials_of(world, &entities);
            world
                .resource_mut::<SoftState>()
                .restore(contacts, &serials)
                .map_err(|message| InputError::whole(origin, message))?;
        }
        let mut state = world.resource_mut::<EngineState>();
        state.budget_exhausted = self.budget_exhausted;
        if let Some(engine) = self.engine {
            let restitutions =
                own::restitutions(&self.own, circles.len(), self.effects.restitution);
            let setup = (self.arena, self.effects, &self.segments, restitutions);
            state
                .restore(engine, &circles, setup)
                .map_err(|message| InputError::whole(origin, message))?;
        }
        let progress = Progress {
            drops_before: self.drops_before,
            ..self.progress
        };
        Ok((app, progress))
    }
}

mod bytes;
mod own;
#[cfg(test)]
mod tests;
