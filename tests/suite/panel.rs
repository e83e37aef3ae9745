//! The app's live panel without a window (feature `render`): each control, written as the
//! panel's sliders write it, changes the running simulation the way a reloaded scene does (an
//! effect switched off loses its systems), bad values are refused, `p` shows and hides the
//! panel, the rolling samples measure the solver that ran, and "compare" finishes in the
//! background with one row per solver.
#![cfg(feature = "render")]

use std::time::{Duration, Instant};

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::prelude::*;
use moving_circles::render::panel::{
    Comparison, Control, LiveHistory, PanelOpen, PanelStatePlugin,
};
use moving_circles::tools::accuracy::SOLVERS;
use moving_circles::tools::run::headless_app_with;

/// The classic scene with the panel's state plugin, shown or not.
fn app(open: bool) -> App {
    headless_app_with(moving_circles::tools::scene::classic(), |app| {
        app.init_resource::<ButtonInput<KeyCode>>()
            .add_plugins(PanelStatePlugin { open });
    })
}

/// Writes `control` as the panel does and lets one frame apply it.
fn send(app: &mut App, control: Control) {
    app.world_mut().write_message(control);
    app.update();
}

/// [`send`], then one more frame: the step after a change runs with the systems it calls for.
fn send_and_step(app: &mut App, control: Control) {
    send(app, control);
    app.update();
}

fn effects(app: &App) -> Effects {
    *app.world().resource::<Effects>()
}

#[test]
fn gravity_and_drag_toggles_add_and_remove_their_systems() {
    let mut app = app(true);
    assert_scheduled(&mut app, "apply_gravity", false);
    send_and_step(&mut app, Control::Gravity(Some(DVec2::new(0.0, -3.0))));
    assert_eq!(effects(&app).gravity, Some(DVec2::new(0.0, -3.0)));
    assert_scheduled(&mut app, "apply_gravity", true);
    // The new system acts: momentum now changes downward step after step.
    let before = energy_momentum(&mut app).1;
    step(&mut app, 10);
    assert!(energy_momentum(&mut app).1.y < before.y, "gravity pulls");
    send_and_step(&mut app, Control::Gravity(None));
    assert_scheduled(&mut app, "apply_gravity", false);

    send_and_step(&mut app, Control::Drag(Some(2.0)));
    assert_scheduled(&mut app, "apply_drag", true);
    send_and_step(&mut app, Control::Drag(None));
    assert_scheduled(&mut app, "apply_drag", false);
    assert_eq!(effects(&app).drag, None);
}

#[test]
fn restitution_dt_speed_and_solver_change_the_running_simulation() {
    let mut app = app(false);
    send(&mut app, Control::Restitution(0.5));
    assert_eq!(effects(&app).restitution, 0.5);
    send(&mut app, Control::Dt(1.0 / 120.0));
    let dt = app.world().resource::<Time<Fixed>>().timestep();
    assert_eq!(dt, Duration::from_secs_f64(1.0 / 120.0));
    send(&mut app, Control::Solver(Solver::Exact));
    assert_eq!(*app.world().resource::<Solver>(), Solver::Exact);
    step(&mut app, 5);
    send(&mut app, Control::Speed(4.0));
    assert_eq!(
        app.world().resource::<Time<Virtual>>().relative_speed_f64(),
        4.0
    );
    let before = app.world().resource::<StepTotals>().steps;
    app.update();
    let after = app.world().resource::<StepTotals>().steps;
    assert!(
        after >= before + 3,
        "four times as many steps per frame: {before} -> {after}"
    );
}

#[test]
fn out_of_range_values_are_refused_not_clamped() {
    let mut app = app(false);
    let before = effects(&app);
    for control in [
        Control::Restitution(1.5),
        Control::Restitution(f64::NAN),
        Control::Drag(Some(-1.0)),
        Control::Gravity(Some(DVec2::new(f64::INFINITY, 0.0))),
    ] {
        send(&mut app, control);
        assert_eq!(effects(&app), before, "{control:?} changed the effects");
    }
    assert_scheduled(&mut app, "apply_drag", false);
    let dt = app.world().resource::<Time<Fixed>>().timestep();
    send(&mut app, Control::Dt(0.0));
    send(&mut app, Control::Dt(f64::NAN));
    assert_eq!(app.world().resource::<Time<Fixed>>().timestep(), dt);
    send(&mut app, Control::Speed(1000.0));
    assert_eq!(
        app.world().resource::<Time<Virtual>>().relative_speed_f64(),
        1.0
    );
    send(&mut app, Control::Solver(Solver::Substeps(0)));
    assert_eq!(*app.world().resource::<Solver>(), Solver::default());
    send(&mut app, Control::Count(usize::MAX));
    assert_eq!(
        circles(&mut app).len(),
        32,
        "no respawn for a refused count"
    );
}

#[test]
fn the_count_slider_respawns_that_many_circles() {
    let mut app = app(false);
    send(&mut app, Control::Count(100));
    app.update(); // the respawn runs in the next frame's PreUpdate
    assert_eq!(circles(&mut app).len(), 100);
}

#[test]
fn p_shows_and_hides_the_panel_and_sampling_follows() {
    let mut app = app(false);
    let tap = |app: &mut App| {
        app.world_mut()
            .resource_mut::<ButtonInput<KeyCode>>()
            .press(KeyCode::KeyP);
        app.update();
        let mut keys = app.world_mut().resource_mut::<ButtonInput<KeyCode>>();
        keys.release(KeyCode::KeyP);
        keys.clear();
    };
    // A headless app's real clock advances one step per update: 20 updates are a third of a
    // second, more than a sampling window.
    step(&mut app, 20);
    assert!(
        app.world().resource::<LiveHistory>().samples.is_empty(),
        "nothing sampled while hidden"
    );
    tap(&mut app);
    assert_eq!(*app.world().resource::<PanelOpen>(), PanelOpen(true));
    // A sample needs a window between two looks.
    step(&mut app, 40);
    send(&mut app, Control::Solver(Solver::Exact));
    step(&mut app, 20);
    let history = app.world().resource::<LiveHistory>();
    let solvers: Vec<Solver> = history.samples.iter().map(|s| s.solver).collect();
    assert!(solvers.contains(&Solver::Discrete), "{solvers:?}");
    assert_eq!(solvers.last(), Some(&Solver::Exact));
    for sample in &history.samples {
        assert!(sample.ms_per_step.is_some_and(|ms| ms > 0.0), "{sample:?}");
        assert!(sample.collisions_per_second.is_some(), "{sample:?}");
        assert!(sample.energy_drift.abs() < 1e-9, "{sample:?}");
    }
    tap(&mut app);
    assert_eq!(*app.world().resource::<PanelOpen>(), PanelOpen(false));
}

#[test]
fn compare_runs_every_solver_in_the_background() {
    let mut app = app(true);
    // Under `exact` nothing overlaps, so the comparison starts from the state reached.
    send(&mut app, Control::Solver(Solver::Exact));
    step(&mut app, 10);
    send(&mut app, Control::Compare);
    assert!(app.world().resource::<Comparison>().is_running());
    let started = Instant::now();
    // The frame goes on while the comparison runs.
    while app.world().resource::<Comparison>().is_running() {
        assert!(
            started.elapsed() < Duration::from_secs(300),
            "no result in 5 min"
        );
        std::thread::sleep(Duration::from_millis(20));
        app.update();
    }
    let Comparison::Done { rows, from } = app.world().resource::<Comparison>() else {
        panic!("the comparison failed");
    };
    assert!(from.starts_with("the current state"), "{from}");
    assert_eq!(rows.len(), SOLVERS.len());
    let exact = rows.iter().find(|r| r.solver == "exact").unwrap();
    assert_eq!(exact.collision_error, 0.0);
    assert_eq!(exact.max_penetration, 0.0);
    let discrete = rows.iter().find(|r| r.solver == "discrete").unwrap();
    assert!(discrete.max_penetration > 0.0, "discrete overlaps");
}
