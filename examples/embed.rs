//! Embedding the simulation in your own Bevy app: configure `CirclesPlugins` with plain structs,
//! swap a part (here the spawner, replaced by one that also places a heavy circle in the
//! middle), add your own system after one of the public sets, and read what the simulation
//! measures.
//!
//! Headless, so it runs anywhere: `cargo run --example embed`.

use std::time::Duration;

use bevy::app::ScheduleRunnerPlugin;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::prelude::*;

fn main() -> AppExit {
    let spawn = SpawnConfig {
        count: 2_000,
        radius: (0.08, 0.2),
        speed: (0.5, 2.0),
        seed: 42,
        mass: MassModel::Equal(1.0),
        ..default()
    };
    let config = CirclesConfig {
        arena: Arena::centered(DVec2::new(32.0, 18.0)),
        spawn: spawn.clone(),
        solver: Solver::Substeps(2),
        ..default()
    };
    // The spawner of the group, swapped for one that first places a heavy circle at rest.
    let heavy = CircleState::new(DVec2::ZERO, DVec2::ZERO, 1.5).with_mass(500.0);
    let spawner = SpawnPlugin {
        config: spawn,
        circles: vec![heavy],
        drop: None,
    };
    App::new()
        .add_plugins(MinimalPlugins.set(ScheduleRunnerPlugin::run_loop(Duration::ZERO)))
        .add_plugins(CirclesPlugins::new(config).build().set(spawner))
        // Run as fast as possible: one fixed step per update.
        .insert_resource(bevy::time::TimeUpdateStrategy::FixedTimesteps(1))
        // Your own systems slot in next to ours through the public sets.
        .add_systems(FixedUpdate, report.after(CircleSystems::Diagnostics))
        .run()
}

/// Prints what the simulation measured once a simulated second, and stops after five.
fn report(
    elapsed: Res<StepTotals>,
    pairs: Res<PairCollisions>,
    diagnostics: Res<CircleDiagnostics>,
    circles: Query<(&Position, &Mass)>,
    mut exit: MessageWriter<AppExit>,
) {
    if !elapsed.steps.is_multiple_of(60) {
        return;
    }
    let heavy = circles.iter().find(|(_, m)| m.0 == 500.0).map(|(p, _)| p.0);
    println!(
        "t = {:>2} s  circles {}  collisions {:>6}  energy drift {:+.2e}  heavy circle at {:.3?}",
        elapsed.steps / 60,
        diagnostics.count,
        pairs.count,
        diagnostics.energy_drift(),
        heavy,
    );
    if elapsed.steps >= 300 {
        exit.write(AppExit::Success);
    }
}
