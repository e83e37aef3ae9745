//! The panel's rolling measurements: how long each fixed step takes ([`StepTimer`], started in
//! `FixedFirst` and stopped in `FixedLast`), and a sample every [`SAMPLE_SECONDS`] of real time
//! ([`LiveHistory`]) of ms per step, collisions and pressure per simulated second over the
//! window, the deepest overlap and the energy drift, each tagged with the solver that ran.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use bevy::prelude::*;

use crate::base::arena::Arena;
use crate::base::collision_layers::{LayeredDisc, layered_disc};
use crate::base::config::Solver;
use crate::base::hits::PairCollisions;
use crate::collision::overlaps::Overlaps;
use crate::game::diagnostics::{CircleDiagnostics, Pressure};
use crate::step::schedule::StepTotals;

/// Seconds of real time between samples.
pub const SAMPLE_SECONDS: f64 = 0.25;
/// Samples kept: a minute at [`SAMPLE_SECONDS`].
pub const HISTORY_LEN: usize = 240;

/// Time spent in the fixed steps since the last sample.
#[derive(Resource, Debug, Default)]
pub struct StepTimer {
    started: Option<Instant>,
    spent: Duration,
    steps: u64,
}

/// One sample of the rolling plots.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LiveSample {
    /// Real seconds since the app started.
    pub t: f64,
    /// The solver that ran through the window.
    pub solver: Solver,
    /// Mean ms per fixed step over the window (`None`: no step ran).
    pub ms_per_step: Option<f64>,
    /// Pair collisions per simulated second over the window.
    pub collisions_per_second: Option<f64>,
    /// Pressure `z` from the collisional virial over the window.
    pub z: Option<f64>,
    /// Deepest overlap now, in smaller radii.
    pub overlap: f64,
    /// Energy drift since the last reset.
    pub energy_drift: f64,
}

/// The last [`HISTORY_LEN`] samples, oldest first, and the counters at the last one.
#[derive(Resource, Debug, Default)]
pub struct LiveHistory {
    /// The samples.
    pub samples: VecDeque<LiveSample>,
    last: Option<(f64, StepTotals, PairCollisions)>,
}

pub(super) fn start_step_timer(mut timer: ResMut<StepTimer>) {
    timer.started = Some(Instant::now());
}

pub(super) fn stop_step_timer(mut timer: ResMut<StepTimer>) {
    if let Some(started) = timer.started.take() {
        timer.spent += started.elapsed();
        timer.steps += 1;
    }
}

/// Takes a sample when [`SAMPLE_SECONDS`] have passed since the last.
#[allow(clippy::too_many_arguments)]
pub(super) fn sample(
    real: Res<Time<Real>>,
    solver: Res<Solver>,
    totals: Res<StepTotals>,
    pairs: Res<PairCollisions>,
    diagnostics: Res<CircleDiagnostics>,
    arena: Res<Arena>,
    circles: Query<LayeredDisc>,
    mut timer: ResMut<StepTimer>,
    mut history: ResMut<LiveHistory>,
) {
    let now = real.elapsed_secs_f64();
    if history
        .last
        .is_some_and(|(then, _, _)| now - then < SAMPLE_SECONDS)
    {
        return;
    }
    let (steps, spent) = (timer.steps, timer.spent);
    *timer = StepTimer::default();
    let previous = history.last.replace((now, *totals, *pairs));
    let Some((_, then_totals, then_pairs)) = previous else {
        return;
    };
    // Counters restart at a reset: a window that spans one measures nothing.
    let window = totals.since(&then_totals);
    let window_pairs = pairs.since(&then_pairs);
    let z = Pressure::virial_z(
        &window,
        &window_pairs,
        diagnostics.count,
        diagnostics.kinetic_energy,
    );
    let sample = LiveSample {
        t: now,
        solver: *solver,
        ms_per_step: (steps > 0).then(|| 1e3 * spent.as_secs_f64() / steps as f64),
        collisions_per_second: (window.sim_seconds > 0.0)
            .then(|| window_pairs.count as f64 / window.sim_seconds),
        z,
        overlap: Overlaps::measure_layered(circles.iter().map(layered_disc), &arena).max,
        energy_drift: diagnostics.energy_drift(),
    };
    if history.samples.len() == HISTORY_LEN {
        history.samples.pop_front();
    }
    history.samples.push_back(sample);
}
