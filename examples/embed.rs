//! Embedding the simulation in your own Bevy app: configure `CirclesPlugins` with plain structs,
//! swap a part, add your own system to one of the public sets, and read the diagnostics.
//!
//! Headless, so it runs anywhere: `cargo run --example embed`.

use std::time::Duration;

use bevy::app::ScheduleRunnerPlugin;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::prelude::*;

fn main() -> AppExit {
    let config = CirclesConfig {
        arena: Arena::centered(DVec2::new(32.0, 18.0)),
        spawn: SpawnConfig {
            count: 2_000,
            radius: (0.08, 0.2),
            speed: (0.5, 2.0),
            seed: 42,
            mass: MassModel::Equal(1.0),
            ..default()
        },
        solver: Solver::Substeps(2),
        ..default()
    };
    App::new()
        .add_plugins(MinimalPlugins.set(ScheduleRunnerPlugin::run_loop(Duration::ZERO)))
        .add_plugins(CirclesPlugins::new(config))
        // Run as fast as possible: one fixed step per update.
        .insert_resource(bevy::time::TimeUpdateStrategy::FixedTimesteps(1))
        // Your own systems slot in next to ours through the public sets.
        .add_systems(FixedUpdate, report.after(CircleSystems::Diagnostics))
        .run()
}

/// Prints the diagnostics once a simulated second, and stops after five.
fn report(
    diagnostics: Res<CircleDiagnostics>,
    counters: Res<CollisionCounters>,
    mut exit: MessageWriter<AppExit>,
) {
    if !counters.steps.is_multiple_of(60) {
        return;
    }
    println!(
        "t = {:>2} s  circles {}  collisions {:>6}  energy drift {:+.2e}",
        counters.steps / 60,
        diagnostics.count,
        counters.pair_collisions,
        diagnostics.energy_drift()
    );
    if counters.steps >= 300 {
        exit.write(AppExit::Success);
    }
}
