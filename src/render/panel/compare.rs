//! The panel's "compare" button: every solver of the accuracy study run for
//! [`COMPARE_SECONDS`] from the app's current state on a thread of its own (a headless copy of
//! the simulation; the frame never waits), each measured against `exact` as in
//! `moving_circles accuracy`. The app polls [`Comparison`] each frame.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, TryRecvError, channel};
use std::sync::{Arc, Mutex};

use bevy::prelude::*;

use crate::base::arena::Arena;
use crate::base::circle::snapshot;
use crate::base::config::{CirclesConfig, DropConfig, Effects, SoftConfig, Solver, SpawnConfig};
use crate::base::segment::Segments;
use crate::game::spawn::FixedCircles;
use crate::tools::accuracy::{Case, HORIZON_SECONDS, Row, SOLVERS, compare, trace};
use crate::tools::scene::check::first_overlap;

/// Simulated seconds each solver runs in a comparison.
pub const COMPARE_SECONDS: f64 = 2.0;

/// Where the last comparison stands.
#[derive(Resource, Default)]
pub enum Comparison {
    /// None asked for yet.
    #[default]
    Idle,
    /// Running: runs done so far (of [`SOLVERS`] and the reference) and where the rows arrive.
    Running {
        /// Runs finished.
        done: Arc<AtomicUsize>,
        /// What the runs started from.
        from: String,
        /// The rows, once all are done.
        rows: Mutex<Receiver<Vec<Row>>>,
    },
    /// Finished: what it started from and one row per solver.
    Done {
        /// What the runs started from.
        from: String,
        /// One row per solver, against `exact`.
        rows: Vec<Row>,
    },
    /// The thread stopped without rows.
    Failed(String),
}

impl Comparison {
    /// Runs to do in a comparison: the reference and every solver.
    pub const RUNS: usize = SOLVERS.len() + 1;

    /// Whether a comparison is under way.
    pub fn is_running(&self) -> bool {
        matches!(self, Comparison::Running { .. })
    }
}

/// The running simulation's configuration, with its circles as explicit ones, and what that
/// start is: the current state, or the scene's start when the current state overlaps (which
/// `discrete` leaves, and a scene may not start from).
pub fn current_case(world: &mut World) -> (Case, String) {
    let arena = *world.resource::<Arena>();
    let mut config = CirclesConfig {
        arena,
        spawn: world.resource::<SpawnConfig>().clone(),
        solver: *world.resource::<Solver>(),
        effects: *world.resource::<Effects>(),
        dt: world.resource::<Time<Fixed>>().timestep().as_secs_f64(),
        circles: Vec::new(),
        segments: world.resource::<Segments>().clone(),
        drop: world.get_resource::<DropConfig>().copied(),
        soft: *world.resource::<SoftConfig>(),
    };
    let circles = snapshot(world);
    let from = match first_overlap(&circles, &arena) {
        None => {
            config.spawn.count = 0;
            config.spawn.area_fraction = None;
            config.circles = circles;
            format!("the current state ({} circles)", config.circles.len())
        }
        Some(_) => {
            config.circles = world.resource::<FixedCircles>().0.clone();
            "the scene's start (the current state has overlapping circles)".to_owned()
        }
    };
    let case = Case {
        name: "now".into(),
        config,
        seconds: COMPARE_SECONDS,
        horizon: HORIZON_SECONDS,
    };
    (case, from)
}

/// Starts a comparison from the current state, unless one is running.
pub fn start_comparison(world: &mut World) {
    if world.resource::<Comparison>().is_running() {
        return;
    }
    let (case, from) = current_case(world);
    let (send, receive) = channel();
    let done = Arc::new(AtomicUsize::new(0));
    let counter = Arc::clone(&done);
    let spawned = std::thread::Builder::new()
        .name("compare solvers".into())
        .spawn(move || {
            let dt = case.config.dt;
            let reference = trace(&case, Solver::REFERENCE, dt);
            counter.fetch_add(1, Ordering::Relaxed);
            let rows = SOLVERS
                .iter()
                .map(|&solver| {
                    let row = compare(&case, &trace(&case, solver, dt), &reference);
                    counter.fetch_add(1, Ordering::Relaxed);
                    row
                })
                .collect();
            // The app may have closed meanwhile; then nobody wants the rows.
            let _ = send.send(rows);
        });
    *world.resource_mut::<Comparison>() = match spawned {
        Ok(_) => Comparison::Running {
            done,
            from,
            rows: Mutex::new(receive),
        },
        Err(e) => Comparison::Failed(format!("could not start a thread: {e}")),
    };
}

/// Picks up the rows of a finished comparison.
pub(super) fn poll_comparison(mut comparison: ResMut<Comparison>) {
    let Comparison::Running { from, rows, .. } = &*comparison else {
        return;
    };
    let received = rows
        .lock()
        .map_err(|_| TryRecvError::Disconnected)
        .and_then(|r| r.try_recv());
    *comparison = match received {
        Ok(rows) => Comparison::Done {
            from: from.clone(),
            rows,
        },
        Err(TryRecvError::Empty) => return,
        Err(TryRecvError::Disconnected) => {
            Comparison::Failed("the comparison stopped before it finished".into())
        }
    };
}
