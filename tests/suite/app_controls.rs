//! The app's keys and HUD, tested headless (feature `render`): keys are pressed through
//! `ButtonInput<KeyCode>` in a `MinimalPlugins` app with the app's input and HUD plugins, as
//! Bevy's own `how_to_test_systems` does, and the HUD text is read back from the world.
#![cfg(feature = "render")]

use crate::common::*;
use bevy::prelude::*;
use moving_circles::game::diagnostics::Pressure;
use moving_circles::prelude::*;
use moving_circles::render::hud::{HelpVisible, HudPlugin, HudRates, HudText};
use moving_circles::render::input::InputPlugin;
use moving_circles::tools::run::headless_app_with;

/// The classic scene with the app's input and HUD plugins, past its first update.
fn app() -> App {
    headless_app_with(moving_circles::tools::scene::classic(), |app| {
        app.init_resource::<ButtonInput<KeyCode>>()
            .init_resource::<ButtonInput<MouseButton>>()
            .add_plugins((InputPlugin, HudPlugin));
    })
}

/// Presses `key` for one update (and lets go), as a player tapping it.
fn tap(app: &mut App, key: KeyCode) {
    app.world_mut()
        .resource_mut::<ButtonInput<KeyCode>>()
        .press(key);
    app.update();
    let mut keys = app.world_mut().resource_mut::<ButtonInput<KeyCode>>();
    keys.release(key);
    keys.clear();
}

fn generation(app: &App) -> u64 {
    app.world().resource::<SpawnReport>().generation
}

fn steps(app: &App) -> u64 {
    app.world().resource::<StepTotals>().steps
}

#[test]
fn r_respawns_from_the_same_seed() {
    let mut app = app();
    let before = circles(&mut app);
    step(&mut app, 30);
    assert_ne!(circles(&mut app), before, "the circles moved");
    let spawned = generation(&app);
    tap(&mut app, KeyCode::KeyR);
    app.update(); // the respawn runs in the next frame's PreUpdate
    assert_eq!(generation(&app), spawned + 1, "one respawn");
    assert_eq!(steps(&app), 1, "counters restart at the respawn");
    let mut fresh = headless_app_with(moving_circles::tools::scene::classic(), |_| {});
    fresh.update();
    assert_eq!(
        circles(&mut app),
        circles(&mut fresh),
        "same seed, same circles"
    );
}

#[test]
fn plus_and_minus_double_and_halve_the_count() {
    let mut app = app();
    assert_eq!(circles(&mut app).len(), 32);
    tap(&mut app, KeyCode::Equal);
    app.update();
    assert_eq!(circles(&mut app).len(), 64);
    tap(&mut app, KeyCode::Minus);
    tap(&mut app, KeyCode::Minus);
    app.update();
    assert_eq!(circles(&mut app).len(), 16);
}

#[test]
fn digits_switch_the_solver() {
    let mut app = app();
    for (key, solver) in [
        (KeyCode::Digit5, Solver::Soft(4)),
        (KeyCode::Digit4, Solver::Exact),
        (KeyCode::Digit3, Solver::Swept),
        (KeyCode::Digit2, Solver::Substeps(8)),
        (KeyCode::Digit1, Solver::Discrete),
    ] {
        let before = steps(&app);
        tap(&mut app, key);
        assert_eq!(*app.world().resource::<Solver>(), solver, "{key:?}");
        step(&mut app, 5);
        assert_eq!(steps(&app), before + 6, "{solver} steps on");
    }
}

#[test]
fn space_pauses_and_period_steps_once_while_paused() {
    let mut app = app();
    tap(&mut app, KeyCode::Space);
    assert!(app.world().resource::<Time<Virtual>>().is_paused());
    let paused_at = steps(&app);
    for _ in 0..5 {
        app.update();
    }
    assert_eq!(steps(&app), paused_at, "no steps while paused");
    let before = circles(&mut app);
    tap(&mut app, KeyCode::Period);
    assert_eq!(steps(&app), paused_at + 1, "`.` advances exactly one step");
    assert_ne!(circles(&mut app), before, "and the circles moved");
    tap(&mut app, KeyCode::Space);
    assert!(!app.world().resource::<Time<Virtual>>().is_paused());
    app.update();
    assert!(steps(&app) > paused_at + 1, "running again");
}

#[test]
fn brackets_change_the_speed_of_simulated_time() {
    let mut app = app();
    tap(&mut app, KeyCode::BracketRight);
    assert_eq!(
        app.world().resource::<Time<Virtual>>().relative_speed(),
        2.0
    );
    tap(&mut app, KeyCode::BracketLeft);
    tap(&mut app, KeyCode::BracketLeft);
    assert_eq!(
        app.world().resource::<Time<Virtual>>().relative_speed(),
        0.5
    );
}

#[test]
fn q_asks_the_app_to_exit() {
    let mut app = app();
    assert!(app.should_exit().is_none());
    tap(&mut app, KeyCode::KeyQ);
    assert_eq!(app.should_exit(), Some(AppExit::Success));
}

#[test]
fn h_toggles_the_help() {
    let mut app = app();
    assert!(!app.world().resource::<HelpVisible>().0);
    tap(&mut app, KeyCode::KeyH);
    assert!(app.world().resource::<HelpVisible>().0);
    tap(&mut app, KeyCode::KeyH);
    assert!(!app.world().resource::<HelpVisible>().0);
}

fn hud_text(app: &mut App) -> String {
    app.world_mut()
        .query_filtered::<&Text, With<HudText>>()
        .single(app.world())
        .unwrap()
        .0
        .clone()
}

#[test]
fn the_hud_shows_what_the_diagnostics_hold() {
    let mut app = app();
    step(&mut app, 120);
    // Start a new refresh window so the next frame redraws the text.
    *app.world_mut().resource_mut::<HudRates>() = HudRates::default();
    app.update();
    let text = hud_text(&mut app);
    let world = app.world();
    let d = *world.resource::<CircleDiagnostics>();
    let pressure = Pressure::measure(
        world.resource::<StepTotals>(),
        world.resource::<PairCollisions>(),
        world.resource::<WallCollisions>(),
        d.count,
        d.kinetic_energy,
        world.resource::<Arena>(),
    );
    for expected in [
        format!("circles {} (0 asleep)", d.count),
        "solver discrete".to_owned(),
        format!("energy drift {:+.2e}", d.energy_drift()),
        format!("pressure z {:.3}", pressure.z_virial.unwrap()),
        format!("(walls {:.3})", pressure.z_wall.unwrap()),
        format!("momentum ({:+.3e}, {:+.3e})", d.momentum.x, d.momentum.y),
        "escaped 0".to_owned(),
        "non-finite 0".to_owned(),
    ] {
        assert!(text.contains(&expected), "HUD lacks `{expected}`:\n{text}");
    }
    assert_eq!(d.count, 32);
    assert!(
        pressure.z_virial.unwrap() > 1.0,
        "collisions raise z above 1"
    );

    // A solver switch shows on the next redraw.
    tap(&mut app, KeyCode::Digit4);
    *app.world_mut().resource_mut::<HudRates>() = HudRates::default();
    app.update();
    assert!(hud_text(&mut app).contains("solver exact"));
}
