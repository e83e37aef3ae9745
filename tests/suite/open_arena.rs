//! An arena with no edges (`Boundary::Open`), under every solver: circles fly out of the
//! rectangle and on, meet each other out there, are held by segment walls and nothing else,
//! and a run's checkpoint with circles far outside is read back and resumed.

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::prelude::*;
use moving_circles::step::effects::EffectRegistry;
use moving_circles::tools::checkpoint::Checkpoint;
use moving_circles::tools::run::Progress;

fn open(solver: Solver, gravity: Option<DVec2>, segments: Vec<Segment>) -> CirclesConfig {
    CirclesConfig {
        arena: Arena::centered(DVec2::new(16.0, 9.0)).with_boundary(Boundary::Open),
        solver,
        effects: Effects {
            gravity,
            ..default()
        },
        segments: Segments(segments),
        ..default()
    }
}

#[test]
fn circles_leave_an_open_arena_and_meet_outside_it() {
    for solver in SOLVERS {
        let mut app = create_app(open(solver, None, Vec::new()));
        let registry = app.world().resource::<EffectRegistry>();
        assert!(!registry.is_scheduled(Effect::Walls) && !registry.is_scheduled(Effect::Periodic));
        // One leaves by the right edge; a head-on pair meets 12 units past the left one.
        let leaver = spawn_circle(
            &mut app,
            DVec2::new(7.0, 0.0),
            DVec2::new(4.0, 0.0),
            0.5,
            1.0,
        );
        let left = spawn_circle(
            &mut app,
            DVec2::new(-22.0, 2.0),
            DVec2::new(2.0, 0.0),
            0.5,
            1.0,
        );
        let right = spawn_circle(
            &mut app,
            DVec2::new(-18.0, 2.0),
            DVec2::new(-2.0, 0.0),
            0.5,
            1.0,
        );
        step(&mut app, 120);
        let at = |app: &App, e: Entity| {
            let world = app.world();
            (
                world.get::<Position>(e).unwrap().0,
                world.get::<Velocity>(e).unwrap().0,
            )
        };
        let (p, v) = at(&app, leaver);
        assert!(
            (p.x - 15.0).abs() < 1e-6 && v == DVec2::new(4.0, 0.0),
            "{solver}: flew on undisturbed to {p}, {v}"
        );
        let ((pl, vl), (pr, vr)) = (at(&app, left), at(&app, right));
        assert_eq!(
            app.world().resource::<PairCollisions>().count,
            1,
            "{solver}"
        );
        assert!(
            vl.x < -1.9 && vr.x > 1.9 && pl.x < -21.0 && pr.x > -19.0,
            "{solver}: the pair should have bounced apart: {pl} {vl}, {pr} {vr}"
        );
        assert_eq!(
            app.world().resource::<WallCollisions>().count,
            0,
            "{solver}"
        );
        assert_eq!(
            app.world().resource::<CircleDiagnostics>().escaped,
            0,
            "{solver}"
        );
    }
}

#[test]
fn in_an_open_arena_segment_walls_hold_what_lands_on_them_and_the_rest_falls_away() {
    let g = Some(DVec2::new(0.0, -9.81));
    // A V-shaped cup of two segment walls; nothing else below.
    let cup = vec![
        Segment::new(DVec2::new(-3.0, 0.0), DVec2::new(0.0, -2.0)),
        Segment::new(DVec2::new(0.0, -2.0), DVec2::new(3.0, 0.0)),
    ];
    for solver in SOLVERS {
        let mut config = open(solver, g, cup.clone());
        config.effects.wall_restitution = 0.2;
        let mut app = create_app(config);
        let held = spawn_circle(&mut app, DVec2::new(0.5, 2.0), DVec2::ZERO, 0.3, 1.0);
        let lost = spawn_circle(&mut app, DVec2::new(6.0, 2.0), DVec2::ZERO, 0.3, 1.0);
        step(&mut app, 240);
        let y = |e: Entity| app.world().get::<Position>(e).unwrap().0.y;
        assert!(
            y(held) > -2.0 && y(held) < -1.0,
            "{solver}: the cup should hold its ball near its bottom, at {}",
            y(held)
        );
        // Four seconds of free fall from y = 2: 78 m down.
        assert!(
            y(lost) < -70.0,
            "{solver}: the other ball fell to {}",
            y(lost)
        );
        assert_eq!(app.world().resource::<CircleDiagnostics>().escaped, 0);
    }
}

#[test]
fn a_checkpoint_with_circles_far_outside_an_open_arena_resumes_the_same() {
    for solver in SOLVERS {
        let config = open(solver, Some(DVec2::new(0.0, -9.81)), Vec::new());
        let mut app = create_app(config);
        for k in 0..6 {
            let at = DVec2::new(-5.0 + 2.0 * f64::from(k), 3.0);
            spawn_circle(&mut app, at, DVec2::new(1.0, 2.0), 0.4, 1.0);
        }
        let progress = Progress::start(app.world_mut());
        step(&mut app, 150); // 2.5 s of fall: 30 m below the arena
        let bytes = Checkpoint::take(app.world_mut(), "open", &progress).to_bytes();
        let checkpoint = Checkpoint::from_bytes(&bytes, "open.checkpoint")
            .unwrap_or_else(|e| panic!("{solver}: our own checkpoint is refused: {e}"));
        assert!(checkpoint.circles().iter().all(|c| c.position.y < -20.0));
        let (mut resumed, _) = checkpoint.resume("open.checkpoint").unwrap();
        step(&mut app, 30);
        step(&mut resumed, 30);
        assert_eq!(
            state_hash(&mut app),
            state_hash(&mut resumed),
            "{solver}: the resumed run differs"
        );
    }
}
