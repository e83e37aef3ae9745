//! What the simulation measures about itself: collision counters the step systems fill in, and
//! [`CircleDiagnostics`] (energy, momentum, drift since the last reset), computed after each
//! fixed step in [`CircleSystems::Diagnostics`] and read by the HUD and the reports.

use bevy::math::DVec2;
use bevy::prelude::*;

use crate::components::{Mass, Radius, Velocity};
use crate::schedule::CircleSystems;
use crate::spawn::SpawnReport;

/// Running totals since the last (re)spawn, written by the step systems.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct CollisionCounters {
    /// Fixed steps advanced.
    pub steps: u64,
    /// Circle-circle impulses applied.
    pub pair_collisions: u64,
    /// Wall reflections.
    pub wall_collisions: u64,
    /// Deepest overlap the collision pass found, as a fraction of the smaller radius.
    pub max_penetration: f32,
}

/// Conserved quantities of the whole system, measured after every fixed step.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct CircleDiagnostics {
    /// Number of circles.
    pub count: usize,
    /// Total kinetic energy `Σ ½ m |v|²` (f64 sum, so the measurement adds no drift).
    pub kinetic_energy: f64,
    /// Kinetic energy right after the last (re)spawn.
    pub initial_kinetic_energy: f64,
    /// Total momentum `Σ m v`.
    pub momentum: DVec2,
    /// Whether any circle has a non-finite position or velocity.
    pub non_finite: usize,
    /// [`SpawnReport::generation`] the baseline belongs to.
    generation: u64,
}

impl CircleDiagnostics {
    /// Relative kinetic-energy change since the last reset: `(E - E0) / E0`, or the absolute
    /// change when `E0` is zero (so it is always finite).
    pub fn energy_drift(&self) -> f64 {
        relative_change(self.initial_kinetic_energy, self.kinetic_energy)
    }
}

/// `(now - before) / before`, falling back to `now - before` when `before` is zero.
pub fn relative_change(before: f64, now: f64) -> f64 {
    if before != 0.0 {
        (now - before) / before
    } else {
        now - before
    }
}

/// Kinetic energy and momentum of a set of circles, summed in f64.
pub fn energy_and_momentum<'a>(
    circles: impl Iterator<Item = (&'a Velocity, &'a Mass)>,
) -> (f64, DVec2, usize) {
    let mut energy = 0.0;
    let mut momentum = DVec2::ZERO;
    let mut non_finite = 0;
    for (v, m) in circles {
        if !v.0.is_finite() {
            non_finite += 1;
            continue;
        }
        if !m.0.is_finite() {
            continue; // immovable circles carry no kinetic energy
        }
        let v = v.0.as_dvec2();
        let m = f64::from(m.0);
        energy += 0.5 * m * v.length_squared();
        momentum += m * v;
    }
    (energy, momentum, non_finite)
}

/// Measures energy and momentum after every fixed step.
#[derive(Clone, Copy, Debug, Default)]
pub struct DiagnosticsPlugin;

impl Plugin for DiagnosticsPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<CircleDiagnostics>()
            .add_systems(Startup, measure.after(CircleSystems::Spawn))
            .add_systems(
                PreUpdate,
                measure
                    .after(CircleSystems::Spawn)
                    .run_if(resource_changed::<SpawnReport>),
            )
            .add_systems(FixedUpdate, measure.in_set(CircleSystems::Diagnostics));
    }
}

/// Updates [`CircleDiagnostics`]; after a (re)spawn, takes the new baseline and zeroes counters.
pub fn measure(
    report: Res<SpawnReport>,
    mut diagnostics: ResMut<CircleDiagnostics>,
    mut counters: ResMut<CollisionCounters>,
    circles: Query<(&Velocity, &Mass), With<Radius>>,
) {
    let (energy, momentum, non_finite) = energy_and_momentum(circles.iter());
    diagnostics.count = circles.iter().len();
    diagnostics.kinetic_energy = energy;
    diagnostics.momentum = momentum;
    diagnostics.non_finite = non_finite;
    if diagnostics.generation != report.generation {
        diagnostics.generation = report.generation;
        diagnostics.initial_kinetic_energy = energy;
        *counters = CollisionCounters::default();
    }
}
