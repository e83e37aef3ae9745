//! The hard-disk equation of state behind `moving_circles eos`: for each area fraction, `n`
//! equal disks in a periodic square box, placed on a triangular lattice with equal speeds in
//! random directions, run under `exact`; the first collisions melt the lattice and are
//! discarded, then the pressure `Z = PA/(NkT)` is measured from the collisional virial in
//! blocks, and the final speeds are compared with the Rayleigh law.
//!
//! - [`theory`]: Henderson's and Liu's equations, the Rayleigh law, block statistics;
//! - [`plot`]: the figure.
//!
//! Lengths are in disk diameters (radius ½), masses are 1 and the initial speed is 1, so
//! `kT = ½`; the step is about one mean free time (from Henderson's contact value), so a step
//! holds about one collision per disk.

#[cfg(feature = "cli")]
pub mod plot;
pub mod theory;

use bevy::math::DVec2;
use serde::Serialize;

use crate::base::arena::{Arena, Boundary};
use crate::base::circle::snapshot;
use crate::base::config::{
    CirclesConfig, DT_RANGE, Effects, MAX_CIRCLES, MassModel, Placement, Solver, SpawnConfig,
};
use crate::base::error::FieldError;
use crate::base::hits::PairCollisions;
use crate::game::diagnostics::{CircleDiagnostics, Pressure};
use crate::step::schedule::StepTotals;
use crate::tools::run::headless_app;
use theory::{block_mean, henderson_z, ks_critical_5_percent, liu_z, rayleigh_ks};

/// What to measure.
#[derive(Clone, Debug, PartialEq)]
pub struct EosOptions {
    /// Disks per box.
    pub n: usize,
    /// The area fractions, each in (0, 0.85].
    pub area_fractions: Vec<f64>,
    /// Collisions per disk run first and discarded (the lattice melting, equilibration).
    pub equilibrate: f64,
    /// Blocks measured after that.
    pub blocks: usize,
    /// Collisions per disk in each block.
    pub block: f64,
    /// Seed of the velocities (and of which lattice sites stay empty).
    pub seed: u64,
}

/// The densest area fraction measured: a lattice of equal disks melted under `exact` (the
/// lattice itself fits to about 0.88 in a square box).
pub const MAX_AREA_FRACTION: f64 = 0.85;

/// The default area fractions: 0.05 to 0.65 in steps of 0.05, then 0.68, 0.70 and 0.72 (the
/// liquid–hexatic region).
pub const DEFAULT_AREA_FRACTIONS: [f64; 16] = [
    0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6, 0.65, 0.68, 0.7, 0.72,
];

/// Most collisions per disk either phase may ask for, so a typo cannot run for days.
pub const MAX_COLLISIONS_PER_DISK: f64 = 1e6;
/// Most blocks.
pub const MAX_BLOCKS: usize = 10_000;

impl Default for EosOptions {
    fn default() -> Self {
        Self {
            n: 4096,
            area_fractions: DEFAULT_AREA_FRACTIONS.to_vec(),
            equilibrate: 100.0,
            blocks: 10,
            block: 100.0,
            seed: 1,
        }
    }
}

impl EosOptions {
    /// Whether these can be measured; the field is named as on the command line.
    pub fn check(&self) -> Result<(), FieldError> {
        if !(2..=MAX_CIRCLES).contains(&self.n) {
            return Err(FieldError::new(
                "--n",
                format!("needs 2 to {MAX_CIRCLES} disks, got {}", self.n),
            ));
        }
        if self.area_fractions.is_empty() {
            return Err(FieldError::new("--area-fractions", "none given"));
        }
        for (k, &phi) in self.area_fractions.iter().enumerate() {
            if self.area_fractions[..k].contains(&phi) {
                return Err(FieldError::new(
                    "--area-fractions",
                    format!("{phi} is given twice"),
                ));
            }
            if !(phi > 0.0 && phi <= MAX_AREA_FRACTION) {
                return Err(FieldError::new(
                    "--area-fractions",
                    format!("each must be in (0, {MAX_AREA_FRACTION}], got {phi}"),
                ));
            }
            // The box and lattice are checked as a scene's are.
            config(self.n, phi, self.seed)
                .check()
                .map_err(|e| FieldError::new("--area-fractions", format!("at {phi}: {e}")))?;
        }
        for (field, value) in [("--equilibrate", self.equilibrate), ("--block", self.block)] {
            if !(value > 0.0 && value <= MAX_COLLISIONS_PER_DISK) {
                return Err(FieldError::new(
                    field,
                    format!(
                        "collisions per disk must be in (0, {MAX_COLLISIONS_PER_DISK}], got {value}"
                    ),
                ));
            }
        }
        if !(2..=MAX_BLOCKS).contains(&self.blocks) {
            return Err(FieldError::new(
                "--blocks",
                format!("must be 2 to {MAX_BLOCKS}, got {}", self.blocks),
            ));
        }
        Ok(())
    }
}

/// One area fraction's result: a row of the CSV.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EosPoint {
    /// Area fraction η.
    pub area_fraction: f64,
    /// Disks.
    pub n: usize,
    /// Mean `Z` over the blocks.
    pub z: f64,
    /// Standard error of that mean, from the spread of the blocks.
    pub z_error: f64,
    /// Henderson's `Z` at η.
    pub henderson: f64,
    /// Liu's `Z` at η.
    pub liu: f64,
    /// `z / liu − 1`.
    pub vs_liu: f64,
    /// Blocks measured.
    pub blocks: usize,
    /// Pair collisions measured (equilibration not counted).
    pub collisions: u64,
    /// Simulated time measured.
    pub sim_seconds: f64,
    /// KS distance of the final speeds from the Rayleigh law.
    pub speed_ks: f64,
    /// The KS distance a sample of `n` independent speeds stays below 95 % of the time.
    pub speed_ks_critical: f64,
    /// Wall-clock seconds of the whole point (equilibration included).
    pub wall_seconds: f64,
}

/// The configuration of one point: `n` disks of radius ½ at area fraction `phi` in a periodic
/// square box, on a lattice, unit masses, unit speeds, under `exact` with a step of about one
/// mean free time.
pub fn config(n: usize, phi: f64, seed: u64) -> CirclesConfig {
    let side = (n as f64 * std::f64::consts::PI * 0.25 / phi).sqrt();
    CirclesConfig {
        arena: Arena::centered(DVec2::splat(side)).with_boundary(Boundary::Periodic),
        spawn: SpawnConfig {
            count: n,
            area_fraction: Some(phi),
            radius: (0.5, 0.5),
            speed: (1.0, 1.0),
            seed,
            mass: MassModel::Equal(1.0),
            placement: Placement::Lattice,
            ..SpawnConfig::default()
        },
        // `exact`: hard disks event by event, the pressure from their collisions.
        solver: Solver::REFERENCE,
        effects: Effects::default(),
        dt: step(phi),
        ..CirclesConfig::default()
    }
}

/// The step: about one mean free time, but no longer than the longest step a scene may have
/// (which dilute boxes reach).
fn step(phi: f64) -> f64 {
    mean_free_time(phi).min(DT_RANGE.1)
}

/// About the mean free time of unit-diameter disks with `kT/m = ½` at area fraction `phi`:
/// `1 / (√2 ρ σ g(σ) v̄)` with Henderson's contact value `g(σ) = (Z − 1) / (2η)`.
fn mean_free_time(phi: f64) -> f64 {
    let density = phi / (std::f64::consts::PI * 0.25);
    let contact = (henderson_z(phi) - 1.0) / (2.0 * phi);
    let mean_speed = (std::f64::consts::PI / 4.0).sqrt();
    1.0 / (std::f64::consts::SQRT_2 * density * contact * mean_speed)
}

/// Measures one area fraction. Fails when the collisions asked for do not come within a
/// hundred times the steps they should take (a box too sparse to collide).
pub fn measure(options: &EosOptions, phi: f64) -> Result<EosPoint, String> {
    let started = std::time::Instant::now();
    let mut app = headless_app(config(options.n, phi, options.seed));
    let n = app.world().resource::<CircleDiagnostics>().count;
    let pair_target = |per_disk: f64| (per_disk * n as f64 / 2.0).ceil() as u64;
    let counters = |app: &bevy::app::App| {
        let world = app.world();
        (
            *world.resource::<StepTotals>(),
            *world.resource::<PairCollisions>(),
        )
    };
    // A step is about one collision per disk, so `per_disk` collisions take about `per_disk`
    // steps.
    let run_until = |app: &mut bevy::app::App, per_disk: f64| {
        let (start, pairs) = (
            app.world().resource::<PairCollisions>().count,
            pair_target(per_disk),
        );
        let steps_per_free_time = (mean_free_time(phi) / step(phi)).ceil();
        let most_steps = (100.0 * per_disk * steps_per_free_time).ceil() as u64 + 1000;
        for _ in 0..most_steps {
            if app.world().resource::<PairCollisions>().count - start >= pairs {
                return Ok(());
            }
            app.update();
        }
        let got = app.world().resource::<PairCollisions>().count - start;
        Err(format!(
            "area fraction {phi}: {got} of the {pairs} collisions asked for came in {most_steps} steps"
        ))
    };
    run_until(&mut app, options.equilibrate)?;
    let (first_totals, first_pairs) = counters(&app);
    let mut blocks = Vec::with_capacity(options.blocks);
    let mut before = (first_totals, first_pairs);
    for _ in 0..options.blocks {
        run_until(&mut app, options.block)?;
        let after = counters(&app);
        let (window, pairs) = (after.0.since(&before.0), after.1.since(&before.1));
        let diagnostics = app.world().resource::<CircleDiagnostics>();
        let z = Pressure::virial_z(
            &window,
            &pairs,
            diagnostics.count,
            diagnostics.kinetic_energy,
        );
        blocks.push(z.unwrap_or(f64::NAN));
        before = after;
    }
    let (z, z_error) = block_mean(&blocks).unwrap_or((f64::NAN, f64::NAN));
    let kinetic = app.world().resource::<CircleDiagnostics>().kinetic_energy;
    let speeds: Vec<f64> = snapshot(app.world_mut())
        .iter()
        .map(|c| c.velocity.length())
        .collect();
    // Unit masses: kT/m = kT = E / N in 2D.
    let speed_ks = rayleigh_ks(&speeds, kinetic / n as f64).unwrap_or(f64::NAN);
    let (last_totals, last_pairs) = counters(&app);
    let liu = liu_z(phi);
    Ok(EosPoint {
        area_fraction: phi,
        n,
        z,
        z_error,
        henderson: henderson_z(phi),
        liu,
        vs_liu: z / liu - 1.0,
        blocks: options.blocks,
        collisions: last_pairs.count - first_pairs.count,
        sim_seconds: last_totals.sim_seconds - first_totals.sim_seconds,
        speed_ks,
        speed_ks_critical: ks_critical_5_percent(n),
        wall_seconds: started.elapsed().as_secs_f64(),
    })
}
