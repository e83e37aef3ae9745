//! Sleeping under the time-stepped solvers (`discrete`, `substeps=N`, `soft`): [`SleepPlugin`]
//! schedules `update_sleep` before each step when the scene calls for it (gravity on and
//! [`SleepConfig::enabled`]). Circles touching each other form islands ([`Islands`]); an
//! island whose circles have all been slower than the sleep speed for the sleep time falls
//! asleep (velocities zeroed; the solvers then leave its circles where they are, as immovable
//! circles at rest), and a sleeping island wakes as soon as a circle that is not at rest
//! touches it, or your code writes one of its circles' position, velocity, radius or mass.
//! Any change of the effects, the arena, the segment walls or the solver wakes every circle.
//!
//! At rest means within `speed · time` radii of where the circle last moved (its anchor):
//! displacement rather than velocity, since the discrete solvers' resting contacts shake by
//! what gravity gives in a substep while going nowhere.

use bevy::ecs::schedule::ScheduleLabel;
use bevy::ecs::system::SystemParam;
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::arena::Arena;
use crate::collide::broad_phase::{CellList, overlapping_pairs};
use crate::components::{Mass, Position, Radius, Sleep, Velocity};
use crate::config::{Effects, SleepConfig, Solver};
use crate::effects::{Effect, register_effect};
use crate::schedule::CircleSystems;
use crate::segment::Segments;

/// Gap (in the smaller radius) within which two circles count as touching for an island.
pub const TOUCHING: f64 = 0.05;

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

/// Groups of circles joined by contacts: a union-find over circle indices.
#[derive(Clone, Debug, Default)]
pub struct Islands {
    parent: Vec<u32>,
}

impl Islands {
    /// `n` circles, each its own island.
    pub fn new(n: usize) -> Self {
        Self {
            parent: (0..n as u32).collect(),
        }
    }

    /// The island of circle `i` (its root).
    pub fn find(&mut self, i: usize) -> usize {
        let mut i = i as u32;
        while self.parent[i as usize] != i {
            let grand = self.parent[self.parent[i as usize] as usize];
            self.parent[i as usize] = grand;
            i = grand;
        }
        i as usize
    }

    /// Joins the islands of `i` and `j` (the smaller root leads, so the result does not depend
    /// on the order of the joins).
    pub fn join(&mut self, i: usize, j: usize) {
        let (a, b) = (self.find(i), self.find(j));
        if a != b {
            let (low, high) = if a < b { (a, b) } else { (b, a) };
            self.parent[high] = low as u32;
        }
    }
}

/// One circle as sleeping sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Resting {
    /// Centre.
    pub position: DVec2,
    /// Radius.
    pub radius: f64,
    /// Whether it can move (an immovable circle is in no island).
    pub movable: bool,
    /// Whether it is immovable and moving: a kinematic circle, which wakes what it touches.
    pub pushing: bool,
    /// Its sleep state, updated in place.
    pub sleep: Sleep,
}

/// What [`settle`] changed: the circles that fell asleep and the ones that woke, by index.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Settled {
    /// Circles that fell asleep (their velocity is to be zeroed).
    pub fell_asleep: Vec<usize>,
    /// Circles that woke.
    pub woke: Vec<usize>,
}

/// Decides which islands of `circles` sleep, after their timers were brought up to date:
/// an island sleeps when every circle in it has been at rest for `time` and no kinematic
/// circle touches it; otherwise its sleeping circles wake (and start their timers again).
/// Islands are found among movable circles within [`TOUCHING`] of each other in `arena`.
pub fn settle(
    circles: &mut [Resting],
    arena: &Arena,
    time: f64,
    cells: &mut CellList,
    pairs: &mut Vec<(u32, u32)>,
) -> Settled {
    let reach: Vec<(DVec2, f64)> = circles
        .iter()
        .map(|c| (c.position, c.radius * (1.0 + TOUCHING)))
        .collect();
    pairs.clear();
    overlapping_pairs(cells, arena, &reach, pairs);
    let mut islands = Islands::new(circles.len());
    let mut pushed = vec![false; circles.len()];
    for &(i, j) in pairs.iter() {
        let (i, j) = (i as usize, j as usize);
        match (circles[i].movable, circles[j].movable) {
            (true, true) => islands.join(i, j),
            (true, false) => pushed[i] |= circles[j].pushing,
            (false, true) => pushed[j] |= circles[i].pushing,
            (false, false) => {}
        }
    }
    let mut ready = vec![true; circles.len()];
    for i in 0..circles.len() {
        if circles[i].movable {
            let root = islands.find(i);
            let c = &circles[i];
            ready[root] &= !pushed[i] && (c.sleep.asleep || c.sleep.slow_for >= time);
        }
    }
    let mut settled = Settled::default();
    for i in 0..circles.len() {
        if !circles[i].movable {
            continue;
        }
        let island_ready = ready[islands.find(i)];
        let sleep = &mut circles[i].sleep;
        if island_ready && !sleep.asleep {
            sleep.asleep = true;
            settled.fell_asleep.push(i);
        } else if !island_ready && sleep.asleep {
            *sleep = Sleep {
                anchor: circles[i].position,
                ..Sleep::default()
            };
            settled.woke.push(i);
        }
    }
    settled
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

/// Buffers reused from step to step: the circles as [`settle`] sees them, the broad phase's
/// cells and the pairs it found.
type SleepScratch = (Vec<Resting>, CellList, Vec<(u32, u32)>);

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
    ),
>;

/// Before each step of a time-stepped solver: wakes sleeping circles that your code moved,
/// advances every awake circle's time at rest, and lets islands fall asleep or wake
/// ([`settle`]). A step in which nothing could change (no circle awake, none moved) looks at
/// each circle once and does nothing else.
fn update_sleep(
    settings: (Res<Effects>, Res<Arena>, Res<Solver>, Res<Time<Fixed>>),
    mut sleeping: ResMut<Sleeping>,
    mut scratch: Local<SleepScratch>,
    mut circles: SleepingCircles,
) {
    let (effects, arena, solver, time) = settings;
    if solver.is_continuous() {
        return; // the event engine rests its circles itself
    }
    let config = effects.sleep;
    let dt = time.timestep().as_secs_f64();
    let (resting, cells, pairs) = &mut *scratch;
    resting.clear();
    let (mut awake, mut asleep, mut ready) = (0usize, 0usize, false);
    for (position, velocity, radius, mass, mut sleep) in &mut circles {
        let movable = !mass.is_immovable();
        let moved = |changed: bool, added: bool| changed && !added;
        if sleep.asleep
            && (moved(position.is_changed(), position.is_added())
                || moved(velocity.is_changed(), velocity.is_added())
                || moved(radius.is_changed(), radius.is_added())
                || moved(mass.is_changed(), mass.is_added()))
        {
            *sleep = Sleep::default();
        }
        if movable && !sleep.asleep {
            rest(&mut sleep, &config, position.0, radius.0, dt);
            awake += 1;
            ready |= sleep.slow_for >= config.time;
        }
        asleep += usize::from(sleep.asleep);
        resting.push(Resting {
            position: position.0,
            radius: radius.0,
            movable,
            pushing: !movable && velocity.0 != DVec2::ZERO,
            sleep: *sleep,
        });
    }
    // Nothing can fall asleep, and nothing awake can touch a sleeping circle.
    if !ready && (asleep == 0 || awake == 0) {
        sleeping.count = asleep;
        return;
    }
    let settled = settle(resting, &arena, config.time, cells, pairs);
    if !(settled.fell_asleep.is_empty() && settled.woke.is_empty()) {
        for (i, (_, mut velocity, _, _, mut sleep)) in circles.iter_mut().enumerate() {
            if sleep.asleep != resting[i].sleep.asleep {
                *sleep = resting[i].sleep;
                if sleep.asleep && velocity.0 != DVec2::ZERO {
                    velocity.0 = DVec2::ZERO;
                }
            }
        }
    }
    sleeping.count = resting.iter().filter(|c| c.sleep.asleep).count();
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(x: f64, movable: bool, slow_for: f64) -> Resting {
        Resting {
            position: DVec2::new(x, 0.0),
            radius: 0.5,
            movable,
            pushing: false,
            sleep: Sleep {
                anchor: DVec2::new(x, 0.0),
                slow_for,
                asleep: false,
            },
        }
    }

    #[test]
    fn an_island_sleeps_only_when_all_of_it_has_rested_long_enough() {
        let arena = Arena::default();
        let (mut cells, mut pairs) = (CellList::default(), Vec::new());
        // Two touching circles, one rested long enough, one not; a third apart, rested.
        let mut circles = [
            circle(0.0, true, 1.0),
            circle(1.0, true, 0.1),
            circle(3.0, true, 1.0),
        ];
        let settled = settle(&mut circles, &arena, 0.5, &mut cells, &mut pairs);
        assert_eq!(settled.fell_asleep, [2]);
        circles[1].sleep.slow_for = 0.6;
        let settled = settle(&mut circles, &arena, 0.5, &mut cells, &mut pairs);
        assert_eq!(settled.fell_asleep, [0, 1]);
        // A circle that is not at rest arrives and touches the sleeping pair: it wakes.
        let mut arrived = circles.to_vec();
        arrived.push(circle(-1.0, true, 0.0));
        let settled = settle(&mut arrived, &arena, 0.5, &mut cells, &mut pairs);
        assert_eq!(settled.woke, [0, 1]);
        assert!(arrived[2].sleep.asleep, "the circle apart sleeps on");
    }

    #[test]
    fn a_static_circle_joins_no_island_and_a_moving_one_wakes_what_it_touches() {
        let arena = Arena::default();
        let (mut cells, mut pairs) = (CellList::default(), Vec::new());
        // Two rested circles on either side of a static peg: two islands, both asleep.
        let mut circles = [
            circle(-1.0, true, 1.0),
            circle(0.0, false, 0.0),
            circle(1.0, true, 1.0),
        ];
        let settled = settle(&mut circles, &arena, 0.5, &mut cells, &mut pairs);
        assert_eq!(settled.fell_asleep, [0, 2]);
        circles[1].pushing = true;
        let settled = settle(&mut circles, &arena, 0.5, &mut cells, &mut pairs);
        assert_eq!(settled.woke, [0, 2]);
    }
}
