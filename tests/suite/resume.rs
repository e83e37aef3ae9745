//! Checkpoint and resume through the real binary: a run paused at a checkpoint and resumed
//! ends bit for bit where the run without the pause ends, under every solver, and a damaged
//! checkpoint is refused by name within the memory bound (signals are in `signals.rs`). And,
//! in the library, a resumed `exact` app goes on with the engine it restored instead of
//! rebuilding one (with circles of their own restitution too); a kinematic circle, the hit
//! messages and circles of their own restitution resume bit for bit under every solver; and
//! what code gave circles of their own is kept.
#![cfg(unix)]

use crate::common::binary::scratch_dir;
use std::path::Path;

use crate::common::binary::{successful, under_one_gib};

fn text(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap()
}

/// The report without the fields that time the run.
fn untimed(report: &Path) -> serde_json::Value {
    let mut value: serde_json::Value = serde_json::from_str(&text(report)).unwrap();
    let fields = value.as_object_mut().unwrap();
    fields.remove("wall_seconds");
    fields.remove("ms_per_step");
    value
}

#[test]
fn a_resumed_run_ends_bit_for_bit_where_the_whole_run_ends_under_every_solver() {
    let dir = scratch_dir("resume", "identical");
    let p = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let (whole_txt, whole_json, c1) = (p("whole.txt"), p("whole.json"), p("c1"));
    // A walled rack of billiards and a periodic gas: the engine's events cross the pause; and a
    // heap under gravity, whose resting contacts `soft` warm starts across it and whose circles
    // come to rest and sleep across it under every solver that holds a heap; and the Galton
    // board: static pegs, segment walls, and balls of a given mass dropped on either side of
    // each pause; balls that roll with friction (the reports' angular momentum holds their
    // spin).
    // Every solver of the suite: `soft=8` among them, the Galton board's own.
    let names = crate::common::SOLVERS.map(|s| s.to_string());
    let every = names.each_ref().map(String::as_str);
    let runs = [
        ("assets/scenes/billiards.ron", &every[..]),
        ("assets/scenes/gas1k.ron", &every[..]),
        ("assets/scenes/gravity.ron", &["soft", "swept", "exact"][..]),
        ("assets/scenes/galton.ron", &every[..]),
        // Friction: spin, and friction impulses warm started across each pause.
        ("assets/scenes/slope.ron", &["soft", "exact"][..]),
        ("assets/scenes/repose.ron", &["soft"][..]),
        // Rough hits: spin and rotation kept in the engine across each pause.
        ("assets/scenes/rough_gas.ron", &["swept", "exact"][..]),
        // No collisions: the engine predicts no pair, and keeps that across each pause.
        ("assets/scenes/drift.ron", &["discrete", "exact"][..]),
    ];
    for (scene, solvers) in runs {
        for &solver in solvers {
            let base = ["run", "--scene", scene, "--solver", solver];
            let whole = [&base[..], &["--steps", "240", "--dump", &whole_txt]].concat();
            successful(&[&whole[..], &["--report", &whole_json]].concat());
            // Paused twice: checkpoints every 50 steps, the last at step 100 (the end).
            let first = [&base[..], &["--steps", "100", "--checkpoint", &c1]].concat();
            successful(&[&first[..], &["--every", "50"]].concat());
            successful(&[
                "run",
                "--resume",
                &p("c1"),
                "--steps",
                "73",
                "--checkpoint",
                &p("c2"),
            ]);
            successful(&[
                "run",
                "--resume",
                &p("c2"),
                "--steps",
                "67",
                "--dump",
                &p("resumed.txt"),
                "--report",
                &p("resumed.json"),
            ]);
            let what = format!("{scene} under {solver}");
            assert!(
                text(&dir.join("whole.txt")) == text(&dir.join("resumed.txt")),
                "final states differ: {what}"
            );
            assert_eq!(
                untimed(&dir.join("whole.json")),
                untimed(&dir.join("resumed.json")),
                "{what}"
            );
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_checkpoint_that_is_damaged_or_not_one_is_refused_by_name() {
    let dir = scratch_dir("resume", "damaged");
    let checkpoint = dir.join("c");
    let c = checkpoint.to_str().unwrap();
    successful(&[
        "run",
        "--scene",
        "assets/scenes/billiards.ron",
        "--solver",
        "exact",
        "--steps",
        "30",
        "--checkpoint",
        c,
    ]);
    let good = std::fs::read(&checkpoint).unwrap();
    let mut truncated = good.clone();
    truncated.truncate(good.len() / 2);
    let mut flipped = good.clone();
    let last = flipped.len() - 9;
    flipped[last] ^= 0x40;
    let mut longer = good.clone();
    longer.push(b'\n');
    // Everything after the format's name at its largest: every length and count it reads
    // claims more than memory holds (its checksum made to match, so that the fields are read).
    // (The name is a string: its length in one byte, then its bytes.)
    let header = 1 + usize::from(good[0]);
    let mut largest = good.clone();
    largest[header..].fill(0xff);
    moving_circles::tools::checkpoint::Checkpoint::reseal(&mut largest);
    // A bit flipped deep in a number, or a byte added, could still read as a usable state:
    // the checksum refuses both.
    let cases: [(&[u8], &str); 6] = [
        (b"", "not a moving_circles checkpoint"),
        (b"hello, world", "not a moving_circles checkpoint"),
        (&truncated, "damaged checkpoint"),
        (&largest, "damaged checkpoint"),
        (&flipped, "damaged checkpoint"),
        (&longer, "damaged checkpoint"),
    ];
    let refused = |path: &str, expected: &str| {
        // Refused before allocating what it claims: within the memory bound.
        let out = under_one_gib(&["run", "--resume", path, "--steps", "5"]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert!(
            stderr.contains(path) && stderr.contains(expected),
            "{stderr}"
        );
    };
    for (bytes, expected) in cases {
        std::fs::write(&checkpoint, bytes).unwrap();
        refused(c, expected);
    }
    // An endless device is refused at its first bytes, not read to the size limit first.
    refused("/dev/zero", "not a moving_circles checkpoint");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_resumed_exact_run_goes_on_with_the_engine_it_kept() {
    use moving_circles::prelude::*;
    use moving_circles::solvers::exact::EngineState;
    use moving_circles::tools::checkpoint::Checkpoint;
    use moving_circles::tools::run::Progress;

    // Plain circles, and circles of which some have their own restitution: the restored engine
    // has them too, so the first step finds every circle as the engine has it.
    let scene = "(arena: (size: (8.0, 6.0), boundary: walls), effects: (restitution: 0.9),
        spawn: (count: 60, radius: (0.1, 0.2), speed: (1.0, 3.0), seed: 3))";
    let config = Scene::parse(scene, "gas.ron")
        .and_then(|s| s.to_config("gas.ron"))
        .unwrap();
    for own in [false, true] {
        let made = |i: usize, circle: &mut bevy::ecs::world::EntityWorldMut| {
            if own && i.is_multiple_of(3) {
                circle.insert(Restitution(0.5));
            }
        };
        let mut app = made_app(&config, Solver::Exact, &made);
        for _ in 0..10 {
            app.update();
        }
        let progress = Progress::start(app.world_mut());
        let kept = own_parts(app.world_mut());
        let restitutions = kept.iter().filter(|p| p.contains("Restitution")).count();
        assert_eq!((kept.len(), restitutions), (60, if own { 20 } else { 0 }));
        let checkpoint = Checkpoint::take(app.world_mut(), "test", &progress);
        let (mut resumed, _) = Checkpoint::from_bytes(&checkpoint.to_bytes(), "test")
            .unwrap()
            .resume("test")
            .unwrap();
        crate::common::step(&mut resumed, 1);
        let engine = resumed.world().resource::<EngineState>();
        assert_eq!(
            (engine.rebuilds, engine.updates),
            (0, 0),
            "own restitution {own}: the restored engine was kept: every circle is seen as \
             changed once, and found equal"
        );
        if !own {
            crate::common::step(&mut resumed, 2);
            let engine = resumed.world().resource::<EngineState>();
            assert_eq!((engine.rebuilds, engine.updates), (0, 0));
        }
    }
}

/// What a game-side reader heard: each hit with the step it came in, its circles as their
/// places in spawn order, and its numbers' bits.
#[derive(bevy::prelude::Resource, Default)]
struct Heard(Vec<(u64, String)>);

fn listen(
    totals: bevy::prelude::Res<moving_circles::step::schedule::StepTotals>,
    mut heard: bevy::prelude::ResMut<Heard>,
    mut circle_hits: bevy::prelude::MessageReader<moving_circles::base::hits::CircleHit>,
    mut wall_hits: bevy::prelude::MessageReader<moving_circles::base::hits::WallHit>,
    circles: bevy::prelude::Query<
        bevy::prelude::Entity,
        bevy::prelude::With<moving_circles::prelude::Radius>,
    >,
) {
    let place = |e| circles.iter().position(|c| c == e).unwrap();
    let step = totals.steps;
    for h in circle_hits.read() {
        let bits = [
            h.point.x,
            h.point.y,
            h.normal.x,
            h.impulse,
            h.normal_speed,
            h.time,
        ]
        .map(f64::to_bits);
        heard
            .0
            .push((step, format!("pair {} {} {bits:?}", place(h.a), place(h.b))));
    }
    for h in wall_hits.read() {
        let bits = [h.point.x, h.point.y, h.impulse, h.normal_speed, h.time].map(f64::to_bits);
        heard.0.push((
            step,
            format!("wall {} {:?} {} {bits:?}", place(h.circle), h.wall, h.count),
        ));
    }
}

/// What code gave each circle of its own, with where the circle is, in a fixed order (the
/// order of a query depends on the components circles were given, and when).
fn own_parts(world: &mut bevy::prelude::World) -> Vec<String> {
    use moving_circles::base::collision_layers::{Sensor, SensorOverlaps};
    use moving_circles::prelude::*;
    let mut circles = world.query::<(
        &Position,
        Option<&Restitution>,
        Option<&Friction>,
        Option<&Inertia>,
        Option<&CollisionLayers>,
        Option<(&Sensor, &SensorOverlaps)>,
    )>();
    let mut parts: Vec<String> = circles
        .iter(world)
        .map(|(p, e, f, i, l, s)| {
            let sensing = s.map(|s| s.1.circles().len());
            format!(
                "{:?} {e:?} {f:?} {i:?} {l:?} {sensing:?}",
                p.0.to_array().map(f64::to_bits)
            )
        })
        .collect();
    parts.sort();
    parts
}

/// Every circle's position and, as [`own_parts`] writes them, the parts code gave it.
fn placed_parts(world: &mut bevy::prelude::World) -> Vec<(bevy::math::DVec2, String)> {
    use moving_circles::prelude::*;
    let mut circles = world.query::<&Position>();
    let places: Vec<_> = circles.iter(world).map(|p| p.0).collect();
    let mut parts = own_parts(world);
    // `own_parts` is sorted by the position's bits, first: sort the places the same way.
    let mut sorted = places;
    sorted.sort_by_key(|p| format!("{:?}", p.to_array().map(f64::to_bits)));
    parts
        .iter_mut()
        .for_each(|p| *p = p.split_once("] ").unwrap().1.to_owned());
    sorted.into_iter().zip(parts).collect()
}

/// A headless app of `config` under `solver` whose circles code changed before the first step:
/// `made` is given each (its place in spawn order, the circle).
fn made_app(
    config: &moving_circles::base::config::CirclesConfig,
    solver: moving_circles::base::config::Solver,
    made: &impl Fn(usize, &mut bevy::ecs::world::EntityWorldMut),
) -> bevy::prelude::App {
    use bevy::prelude::*;
    use moving_circles::prelude::*;
    let mut app = moving_circles::tools::run::headless_app(CirclesConfig {
        solver,
        ..config.clone()
    });
    let world = app.world_mut();
    let circles: Vec<Entity> = world
        .query_filtered::<Entity, With<Radius>>()
        .iter(world)
        .collect();
    for (i, &e) in circles.iter().enumerate() {
        made(i, &mut world.entity_mut(e));
    }
    app
}

/// Runs `scene` under every solver with `made` applied to its circles (in spawn order) by code
/// before the first step, whole and paused at step 25 then resumed from the checkpoint, and
/// asserts both end in the same state and that a reader hears the same hits after the pause.
fn resumes_bit_for_bit(scene: &str, made: impl Fn(usize, &mut bevy::ecs::world::EntityWorldMut)) {
    use bevy::prelude::*;
    use moving_circles::base::circle::snapshot;
    use moving_circles::prelude::*;
    use moving_circles::tools::checkpoint::Checkpoint;
    use moving_circles::tools::run::Progress;
    let config = Scene::parse(scene, "k.ron")
        .and_then(|s| s.to_config("k.ron"))
        .unwrap();
    let listening = |mut app: App| {
        app.init_resource::<Heard>().add_systems(Update, listen);
        app
    };
    for solver in crate::common::SOLVERS {
        let mut whole = listening(made_app(&config, solver, &made));
        for _ in 0..25 {
            whole.update();
        }
        let progress = Progress::start(whole.world_mut());
        let bytes = Checkpoint::take(whole.world_mut(), "k", &progress).to_bytes();
        let (resumed, _) = Checkpoint::from_bytes(&bytes, "k")
            .unwrap()
            .resume("k")
            .unwrap();
        let mut resumed = listening(resumed);
        for _ in 0..35 {
            whole.update();
            resumed.update();
        }
        let what = format!("{solver}");
        assert_eq!(
            snapshot(whole.world_mut()),
            snapshot(resumed.world_mut()),
            "{what}"
        );
        let heard = |app: &App| app.world().resource::<Heard>().0.clone();
        let after: Vec<_> = heard(&whole)
            .into_iter()
            .filter(|(step, _)| *step > 25)
            .collect();
        assert!(after.len() > 20, "{what}: {} hits heard", after.len());
        assert_eq!(after, heard(&resumed), "{what}");
    }
}

#[test]
fn a_kinematic_circle_and_the_hit_messages_resume_bit_for_bit_under_every_solver() {
    use moving_circles::prelude::*;
    // A walled gas whose first circle is made kinematic by code (immovable, flying on at the
    // velocity it has), with hit messages on.
    let scene = "(arena: (size: (8.0, 6.0), boundary: walls),
        effects: (collisions: true, hit_messages: true, restitution: 0.9),
        spawn: (count: 40, radius: (0.15, 0.3), speed: (2.0, 6.0), seed: 7))";
    resumes_bit_for_bit(scene, |i, circle| {
        if i == 0 {
            circle.insert(Mass::IMMOVABLE);
        }
    });
}

#[test]
fn circles_of_their_own_restitution_resume_bit_for_bit_under_every_solver() {
    use moving_circles::prelude::*;
    // A box under gravity, hit messages on: every fourth circle given a restitution of its
    // own by code as it is made.
    let scene = "(arena: (size: (8.0, 6.0), boundary: walls),
        effects: (collisions: true, hit_messages: true, restitution: 0.9,
                  gravity: (0.0, -3.0)),
        spawn: (count: 40, radius: (0.15, 0.3), speed: (2.0, 6.0), seed: 8))";
    resumes_bit_for_bit(scene, |i, circle| {
        if i % 4 == 0 {
            circle.insert(Restitution(0.3));
        }
    });
}

#[test]
fn what_code_gave_circles_of_their_own_is_kept_by_a_checkpoint_under_every_solver() {
    use moving_circles::base::circle::snapshot;
    use moving_circles::base::collision_layers::Sensor;
    use moving_circles::prelude::*;
    use moving_circles::tools::checkpoint::Checkpoint;
    use moving_circles::tools::run::Progress;
    // Rough hits with friction in a box under gravity: circles of their own restitution,
    // friction and moment of inertia, a team in layers of its own, and a sensor. The resumed
    // circles are where they were with the same parts (a sensor with as many overlaps), and
    // keep them as the run goes on.
    let scene = "(arena: (size: (8.0, 6.0), boundary: walls),
        effects: (collisions: true, restitution: 0.9, gravity: (0.0, -3.0), friction: 0.3,
                  tangential_restitution: 0.4),
        spawn: (count: 40, radius: (0.15, 0.3), speed: (2.0, 6.0), seed: 8))";
    let config = Scene::parse(scene, "own.ron")
        .and_then(|s| s.to_config("own.ron"))
        .unwrap();
    let made = |i: usize, circle: &mut bevy::ecs::world::EntityWorldMut| {
        match i % 8 {
            0 => circle.insert(Restitution(0.3)),
            1 => circle.insert(Friction(0.9)),
            2 => circle.insert(Inertia(0.002)),
            3 => circle.insert(CollisionLayers::new(0b10, 0b10)),
            4 if i < 10 => circle.insert(Sensor),
            _ => circle,
        };
    };
    for solver in crate::common::SOLVERS {
        let mut app = made_app(&config, solver, &made);
        for _ in 0..25 {
            app.update();
        }
        let progress = Progress::start(app.world_mut());
        let kept = own_parts(app.world_mut());
        assert!(
            kept.iter()
                .any(|p| p.ends_with("Some(1)") || p.ends_with("Some(0)"))
        );
        let bytes = Checkpoint::take(app.world_mut(), "own", &progress).to_bytes();
        let (mut resumed, _) = Checkpoint::from_bytes(&bytes, "own")
            .unwrap()
            .resume("own")
            .unwrap();
        assert_eq!(own_parts(resumed.world_mut()), kept, "{solver}");
        // Then both go on: the resumed run is the run without the pause, every circle where it
        // would have been with the same parts, a sensor with as many overlaps. To the bit,
        // though the resumed world keeps its circles in tables of another order; under `exact`
        // to rounding, as a checkpoint keeps no engine whose circles have layers or that
        // sensors share (see `EngineState::snapshot`): the resumed run builds a fresh one.
        for _ in 0..35 {
            app.update();
            resumed.update();
        }
        let (went_on, paused) = (snapshot(resumed.world_mut()), snapshot(app.world_mut()));
        assert!(
            went_on == paused || solver == Solver::Exact,
            "{solver}: not the same bits"
        );
        let (went_on, paused) = (
            placed_parts(resumed.world_mut()),
            placed_parts(app.world_mut()),
        );
        assert_eq!(went_on.len(), paused.len(), "{solver}");
        for (p, parts) in &went_on {
            let twin = paused.iter().find(|(q, _)| q.distance(*p) < 1e-9);
            assert_eq!(
                twin.map(|(_, parts)| parts),
                Some(parts),
                "{solver}: the resumed run's circle at {p} is not the paused run's"
            );
        }
    }
}
