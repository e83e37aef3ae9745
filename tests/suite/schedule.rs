//! The schedule: no ambiguous system order, only the plugins a config calls for, parts can be
//! disabled the Bevy way, and a solver is whatever plugin registers its step.

use crate::common::*;
use bevy::app::PluginGroup;
use bevy::ecs::schedule::{LogLevel, ScheduleBuildSettings};
use bevy::prelude::*;
use moving_circles::prelude::*;
use moving_circles::step::schedule::scheduled_systems;

fn system_names(app: &mut App) -> Vec<String> {
    scheduled_systems(app).into_iter().map(|(_, s)| s).collect()
}

#[test]
fn the_schedule_has_no_ambiguities() {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, CirclesPlugins::default()));
    app.finish();
    app.cleanup();
    let world = app.world_mut();
    let labels: Vec<_> = world
        .resource::<Schedules>()
        .iter()
        .map(|(_, s)| s.label())
        .collect();
    let mut conflicts = Vec::new();
    for label in labels {
        world.schedule_scope(label, |world, schedule| {
            schedule.set_build_settings(ScheduleBuildSettings {
                ambiguity_detection: LogLevel::Warn,
                ..default()
            });
            schedule.initialize(world).expect("schedule builds");
            let n = schedule.graph().conflicting_systems().len();
            if n > 0 {
                conflicts.push(format!("{label:?}: {n}"));
            }
        });
    }
    assert!(
        conflicts.is_empty(),
        "ambiguous system pairs in: {conflicts:?}"
    );
}

#[test]
fn the_default_schedule_runs_the_four_systems_of_the_seed_in_order() {
    let mut app = create_app(moving_circles::tools::scene::classic());
    let step: Vec<_> = scheduled_systems(&mut app)
        .into_iter()
        .filter(|(schedule, _)| schedule == "CircleStep")
        .map(|(_, s)| s)
        .collect();
    assert_eq!(
        step,
        [
            "moving_circles::step::integrate::integrate_positions",
            "moving_circles::step::boundary::bounce_off_walls",
            "moving_circles::solvers::discrete::collide_circles",
        ]
    );
    assert!(
        system_names(&mut app).contains(&"moving_circles::game::spawn::spawn_circles".to_owned())
    );
}

#[test]
fn without_collisions_there_is_no_collision_system() {
    let config = CirclesConfig {
        effects: Effects {
            collisions: false,
            ..default()
        },
        ..default()
    };
    let mut app = create_app(config);
    let names = system_names(&mut app);
    assert!(!names.iter().any(|n| n.contains("collide")), "{names:#?}");
    assert!(
        names.iter().any(|n| n.contains("integrate_positions")),
        "{names:#?}"
    );
    // And under every solver the circles really pass through each other, where with
    // collisions they bounce back.
    let solvers = [
        Solver::Discrete,
        Solver::Substeps(4),
        Solver::Soft(4),
        Solver::Swept,
        Solver::Exact,
    ];
    for solver in solvers {
        for collisions in [false, true] {
            let mut app = create_app(CirclesConfig {
                solver,
                effects: Effects {
                    collisions,
                    ..default()
                },
                ..default()
            });
            spawn_head_on(&mut app, 1.0, 1.0, 0.5);
            step(&mut app, 120);
            let xs: Vec<f64> = circles(&mut app).iter().map(|c| c.0.x).collect();
            let crossed = xs[0] > 0.0 && xs[1] < 0.0;
            assert_eq!(
                crossed, !collisions,
                "{solver:?}, collisions {collisions}: {xs:?}"
            );
        }
    }
}

#[test]
fn a_part_can_be_disabled_like_any_bevy_plugin_group() {
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        CirclesPlugins::default().build().disable::<WallsPlugin>(),
    ));
    app.finish();
    app.cleanup();
    app.update();
    let names = system_names(&mut app);
    assert!(
        !names.iter().any(|n| n.contains("bounce_off_walls")),
        "{names:#?}"
    );
    assert!(
        names.iter().any(|n| n.contains("collide_circles")),
        "{names:#?}"
    );
}

#[test]
fn diagnostics_are_measured_every_step_except_while_a_headless_run_steps() {
    use moving_circles::tools::run::run_steps;
    let mut app = moving_circles::tools::run::headless_app(CirclesConfig {
        solver: Solver::Exact,
        ..default()
    });
    let energy = |app: &App| app.world().resource::<CircleDiagnostics>().kinetic_energy;
    let push = |app: &mut App| {
        let world = app.world_mut();
        for mut v in world.query::<&mut Velocity>().iter_mut(world) {
            v.0 *= 2.0;
        }
    };
    // Every step: doubled speeds show in the next step's kinetic energy.
    let before = energy(&app);
    push(&mut app);
    step(&mut app, 1);
    assert_relative("every step", energy(&app), 4.0 * before, 1e-9);

    // A headless run leaves them as they were, and hands measuring back when it ends.
    push(&mut app);
    let report = run_steps(&mut app, "test", 3, 1, |_| {});
    assert_relative(
        "the run's own totals",
        report.energy_final,
        16.0 * before,
        1e-9,
    );
    assert_eq!(
        energy(&app),
        4.0 * before,
        "not measured while the run stepped"
    );
    assert_eq!(*app.world().resource::<Measuring>(), Measuring::EveryStep);
    step(&mut app, 1);
    assert_relative("after the run", energy(&app), 16.0 * before, 1e-9);
}

/// The schedule of the stand-in solver below.
#[derive(bevy::ecs::schedule::ScheduleLabel, Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct DriftStep;

/// A stand-in for `soft`, registered as any solver registers its step: each of its two runs a
/// fixed step moves every circle right by the run's `dt`, whatever its velocity.
struct DriftPlugin;

impl Plugin for DriftPlugin {
    fn build(&self, app: &mut App) {
        use bevy::ecs::schedule::ScheduleLabel;
        use moving_circles::step::schedule::{SolverStep, StepDt, register_solver};
        #[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
        struct DriftSystems;
        let step = SolverStep {
            advances: Solver::is_soft,
            schedule: DriftStep.intern(),
            runs: |_| 2,
        };
        register_solver(app, step, DriftSystems);
        let drift = |dt: Res<StepDt>, mut circles: Query<&mut Position>| {
            circles.iter_mut().for_each(|mut p| p.0.x += dt.0);
        };
        app.add_systems(DriftStep, drift.in_set(DriftSystems));
    }
}

/// A headless soft gas without `SoftPlugin`, with `setup` added, stepped once.
fn soft_app_without_its_plugin(setup: impl FnOnce(&mut App)) -> App {
    use bevy::time::TimeUpdateStrategy;
    let config = CirclesConfig {
        solver: Solver::Soft(4),
        spawn: SpawnConfig {
            count: 50,
            ..default()
        },
        ..default()
    };
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        CirclesPlugins::new(config).build().disable::<SoftPlugin>(),
    ))
    .insert_resource(TimeUpdateStrategy::FixedTimesteps(1));
    setup(&mut app);
    app.finish();
    app.cleanup();
    app.update();
    app
}

#[test]
fn a_solver_is_replaced_by_a_plugin_that_registers_its_step() {
    let mut app = soft_app_without_its_plugin(|app| {
        app.add_plugins(DriftPlugin);
    });
    let before = circles(&mut app);
    let steps = app.world().resource::<StepTotals>().steps;
    step(&mut app, 3);
    let after = circles(&mut app);
    assert_eq!(app.world().resource::<StepTotals>().steps, steps + 3);
    assert!(!before.is_empty());
    let dt = app
        .world()
        .resource::<Time<Fixed>>()
        .timestep()
        .as_secs_f64();
    for (was, now) in before.iter().zip(&after) {
        assert!(
            (now.0.x - was.0.x - 3.0 * dt).abs() < 1e-12,
            "{was:?} -> {now:?}"
        );
        assert_eq!(now.0.y, was.0.y);
    }
}

#[test]
fn without_the_solvers_plugin_the_circles_stay_where_they_are() {
    let mut app = soft_app_without_its_plugin(|_| {});
    let before = circles(&mut app);
    assert!(before.iter().any(|c| c.1 != bevy::math::DVec2::ZERO));
    step(&mut app, 3);
    assert_eq!(circles(&mut app), before);
}
