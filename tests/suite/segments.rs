//! Segment walls, the hard cases under every solver: a fast circle against a thin segment, an
//! end hit head-on and at a grazing angle, a circle sliding down a slope, one settling into a
//! wedge, and a gas in a maze of segments that never enters a wall. Also what scenes may
//! declare, and that the effect is scheduled only when a scene has segments.

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::prelude::*;
use moving_circles::solvers::exact::EngineState;

/// Every wall hit a game would hear.
#[derive(Resource, Default)]
struct Heard(Vec<WallHit>);

fn listen(mut heard: ResMut<Heard>, mut hits: MessageReader<WallHit>) {
    heard.0.extend(hits.read().copied());
}

/// A walled arena of `size` with the `segments` polylines (RON), one circle of radius `r` at
/// `p` moving at `v`, under `solver` with `effects` (RON fields), listening to wall hits.
fn one_circle(
    solver: &str,
    size: (f64, f64),
    segments: &str,
    effects: &str,
    c: [f64; 5],
) -> (App, Entity) {
    let [x, y, vx, vy, r] = c;
    let mut app = scene_app(&format!(
        "(solver: \"{solver}\", arena: (size: ({}, {}), boundary: walls),
          effects: (hit_messages: true, {effects}),
          segments: {segments},
          circles: [(position: ({x}, {y}), velocity: ({vx}, {vy}), radius: {r})])",
        size.0, size.1
    ));
    app.init_resource::<Heard>().add_systems(Update, listen);
    assert_eq!(app.world().resource::<StepTotals>().steps, 0);
    let entity = app
        .world_mut()
        .query_filtered::<Entity, With<Radius>>()
        .single(app.world())
        .unwrap();
    (app, entity)
}

/// How far a circle of radius `r` at `p` reaches into the nearest of `segments` (negative: a
/// gap).
fn depth(segments: &Segments, p: DVec2, r: f64) -> f64 {
    segments
        .0
        .iter()
        .map(|s| r - s.distance(p))
        .fold(f64::MIN, f64::max)
}

#[test]
fn a_fast_circle_never_tunnels_through_a_thin_segment_under_soft_swept_and_exact() {
    // Radius 0.05 at 60 units/s with dt = 1/60: 10 diameters per step, against a segment of
    // no thickness 3 units away; it bounces between the segment and the left wall.
    for solver in SOLVERS {
        let solver = &*solver.to_string();
        let (mut app, ball) = one_circle(
            solver,
            (20.0, 4.0),
            "[[(0.0, -1.5), (0.0, 1.5)]]",
            "collisions: false",
            [-3.0, 0.3, 60.0, 0.0, 0.05],
        );
        let mut crossed = false;
        for _ in 0..60 {
            step(&mut app, 1);
            let (p, _) = state(&app, ball);
            crossed |= p.x > 0.0;
        }
        let segment_hits = app
            .world()
            .resource::<Heard>()
            .0
            .iter()
            .filter(|h| h.wall == Wall::Segment(0))
            .count();
        if is_continuous(solver) {
            assert!(!crossed, "{solver}: went through the segment");
            // 2.95 units to the segment, then round trips of 19.8 units to the left wall and
            // back: 3 hits on the segment in the 60 units of one second.
            assert_eq!(segment_hits, 3, "{solver}");
            let (_, v) = state(&app, ball);
            assert_eq!(
                v.length(),
                60.0,
                "{solver}: an elastic wall keeps the speed"
            );
        } else if is_soft(solver) {
            // A speculative contact stops it at the segment within the step it would cross,
            // and the restitution pass sends it back: no tunnelling, the speed kept, each
            // bounce up to a step late.
            assert!(!crossed, "{solver}: went through the segment");
            assert!((2..=3).contains(&segment_hits), "{solver}: {segment_hits}");
            let (_, v) = state(&app, ball);
            assert!((v.length() - 60.0).abs() < 1e-9, "{solver}: {v}");
        } else {
            // The price of a discrete step: it only sees where the circle ends up.
            assert!(
                crossed,
                "{solver}: expected to tunnel at 10 diameters per step"
            );
        }
    }
}

#[test]
fn an_end_hit_head_on_sends_the_circle_straight_back() {
    // Along the segment's own line into its right end at (1, 0): touching at x = 1.25 after
    // 0.875 s, back out at speed 2, at x = 1.5 after 1 s.
    for solver in SOLVERS {
        let solver = &*solver.to_string();
        let (mut app, ball) = one_circle(
            solver,
            (10.0, 4.0),
            "[[(-1.0, 0.0), (1.0, 0.0)]]",
            "collisions: false",
            [3.0, 0.0, -2.0, 0.0, 0.25],
        );
        step(&mut app, 60);
        let dt = app
            .world()
            .resource::<Time<Fixed>>()
            .timestep()
            .as_secs_f64();
        let (p, v) = state(&app, ball);
        assert!((v - DVec2::new(2.0, 0.0)).length() < 1e-12, "{solver}: {v}");
        let x = 1.25 + 2.0 * (60.0 * dt - 0.875);
        // `soft` stops the circle at the end and sends it back at the step's end: at most one
        // step's travel behind.
        let lag = if is_soft(solver) { 2.0 * dt } else { 1e-12 };
        assert!((p - DVec2::new(x, 0.0)).length() <= lag, "{solver}: {p}");
        let heard = &app.world().resource::<Heard>().0;
        assert_eq!(heard.len(), 1, "{solver}: {heard:?}");
        let hit = heard[0];
        assert_eq!(
            (hit.wall, hit.point, hit.normal),
            (Wall::Segment(0), DVec2::X, -DVec2::X)
        );
        assert_eq!(
            app.world().resource::<WallCollisions>().count,
            1,
            "{solver}"
        );
        if is_continuous(solver) {
            let expected = 0.875 - 52.0 * dt; // seconds into the 53rd step
            assert!((hit.time - expected).abs() < 1e-9, "{solver}: {}", hit.time);
        }
    }
}

#[test]
fn a_grazing_end_hit_deflects_by_the_contact_angle_and_a_near_miss_does_not() {
    let r = 0.25;
    for solver in SOLVERS {
        let solver = &*solver.to_string();
        // Falling past the right end at (1, 0), its centre 0.8 r to the right of it: it touches
        // the end where the line to the centre makes sin θ = 0.8 with the vertical.
        let (mut app, ball) = one_circle(
            solver,
            (10.0, 6.0),
            "[[(-1.0, 0.0), (1.0, 0.0)]]",
            "collisions: false",
            [1.0 + 0.8 * r, 1.5, 0.0, -2.0, r],
        );
        step(&mut app, 60);
        let (p, v) = state(&app, ball);
        let n = DVec2::new(0.8, 0.6);
        let expected = DVec2::new(0.0, -2.0) - 2.0 * DVec2::new(0.0, -2.0).dot(n) * n;
        assert!((v.length() - 2.0).abs() < 1e-12, "{solver}: speed {v}");
        if is_continuous(solver) {
            assert!(
                (v - expected).length() < 1e-9,
                "{solver}: {v}, expected {expected}"
            );
        } else {
            // The discrete step finds the circle already past the contact, so the normal it
            // reflects about is off; the deflection still goes the right way.
            assert!(v.x > 0.5 && (v - expected).length() < 1.0, "{solver}: {v}");
        }
        assert!(
            depth(app.world().resource::<Segments>(), p, r) <= 1e-12,
            "{solver}"
        );

        // 1.05 r to the right of the end: no hit at all.
        let (mut app, ball) = one_circle(
            solver,
            (10.0, 6.0),
            "[[(-1.0, 0.0), (1.0, 0.0)]]",
            "collisions: false",
            [1.0 + 1.05 * r, 1.5, 0.0, -2.0, r],
        );
        step(&mut app, 60);
        assert_eq!(state(&app, ball).1, DVec2::new(0.0, -2.0), "{solver}");
        assert!(app.world().resource::<Heard>().0.is_empty(), "{solver}");
    }
}

#[test]
fn a_circle_slides_down_a_slope_without_sinking_into_it() {
    // A slope of 1 in 2 (sin θ = 1/√5), gravity, no bounce off the wall: the circle starts
    // touching it near the top and slides; along the slope it covers g sin θ t² / 2.
    let r = 0.2;
    let (a, b) = (DVec2::new(-4.0, 2.0), DVec2::new(4.0, -2.0));
    let down = (b - a).normalize();
    let normal = down.perp(); // up and to the right: the side the circle is on
    let start = a + down * 1.0 + normal * r;
    for solver in SOLVERS {
        let solver = &*solver.to_string();
        let (mut app, ball) = one_circle(
            solver,
            (10.0, 6.0),
            "[[(-4.0, 2.0), (4.0, -2.0)]]",
            "collisions: false, gravity: (0.0, -9.81), wall_restitution: 0.0",
            [start.x, start.y, 0.0, 0.0, r],
        );
        let segments = app.world().resource::<Segments>().clone();
        let mut deepest = f64::MIN;
        for _ in 0..60 {
            step(&mut app, 1);
            deepest = deepest.max(depth(&segments, state(&app, ball).0, r));
        }
        let (p, _) = state(&app, ball);
        let slid = (p - start).dot(down);
        let expected = 9.81 / 5f64.sqrt() / 2.0;
        assert_relative(solver, slid, expected, 0.05);
        let tolerance = if is_continuous(solver) { 1e-9 } else { 0.02 } * r;
        assert!(
            deepest <= tolerance,
            "{solver}: sank {deepest} into the slope"
        );
        assert!(
            (p - a).dot(normal) > 0.0,
            "{solver}: fell through the slope"
        );
    }
}

#[test]
fn a_circle_dropped_into_a_wedge_settles_in_it_touching_both_sides() {
    // A right-angled V with its point at the origin; a bouncy circle dropped off-centre.
    let r = 0.3;
    for solver in SOLVERS {
        let solver = &*solver.to_string();
        let (mut app, ball) = one_circle(
            solver,
            (10.0, 8.0),
            "[[(-3.0, 3.0), (0.0, 0.0), (3.0, 3.0)]]",
            "collisions: false, gravity: (0.0, -9.81), wall_restitution: 0.7",
            [0.4, 2.5, 0.0, 0.0, r],
        );
        let segments = app.world().resource::<Segments>().clone();
        let mut deepest = f64::MIN;
        for _ in 0..600 {
            step(&mut app, 1);
            deepest = deepest.max(depth(&segments, state(&app, ball).0, r));
        }
        let (p, v) = state(&app, ball);
        let rest = DVec2::new(0.0, r * 2f64.sqrt()); // touching both sides
        assert!(
            (p - rest).length() < 0.02,
            "{solver}: ended at {p}, moving {v}"
        );
        let tolerance = if is_continuous(solver) { 1e-9 } else { 0.02 } * r;
        assert!(
            deepest <= tolerance,
            "{solver}: {deepest} into a side of the wedge"
        );
        assert_eq!(
            app.world().resource::<EngineState>().budget_exhausted,
            0,
            "{solver}"
        );
    }
}

#[test]
fn a_circle_in_a_narrow_v_never_leaves_it() {
    // A V of 12 degrees, its point at (0, -1): the circle sinks in until it touches both sides,
    // where each side's push presses it into the other. The discrete solvers once pushed it out
    // through one side.
    let (a, b) = (DVec2::new(-0.3, 1.9), DVec2::new(0.0, -1.0));
    let c = DVec2::new(0.3, 1.9);
    let inside = |p: DVec2| (b - a).perp_dot(p - a) > 0.0 && (c - b).perp_dot(p - b) > 0.0;
    for solver in SOLVERS {
        let solver = &*solver.to_string();
        let (mut app, ball) = one_circle(
            solver,
            (4.0, 4.0),
            "[[(-0.3, 1.9), (0.0, -1.0), (0.3, 1.9)]]",
            "gravity: (0.0, -9.81), wall_restitution: 0.3",
            [0.0, 1.5, 0.0, 0.0, 0.15],
        );
        for k in 0..600 {
            step(&mut app, 1);
            let p = state(&app, ball).0;
            assert!(inside(p), "{solver}: out of the V at {p} after {k} steps");
        }
        let p = state(&app, ball).0;
        assert!(p.y > 0.3 && p.x.abs() < 0.01, "{solver}: ended at {p}");
    }
}

#[test]
fn a_gas_in_a_maze_of_segments_never_enters_a_wall_and_keeps_its_energy() {
    // 60 circles among 40 segments in a grid of short bars (listed in many cells each).
    let mut bars = Vec::new();
    for i in 0..8 {
        for j in 0..5 {
            let (x, y) = (-3.5 + i as f64, -2.0 + j as f64);
            let d = if (i + j) % 2 == 0 {
                (0.3, 0.3)
            } else {
                (0.3, -0.3)
            };
            bars.push(format!(
                "[({}, {}), ({}, {})]",
                x - d.0,
                y - d.1,
                x + d.0,
                y + d.1
            ));
        }
    }
    for solver in ["swept", "exact"] {
        let mut app = scene_app(&format!(
            "(solver: \"{solver}\", arena: (size: (8.0, 5.0), boundary: walls),
              segments: [{}],
              spawn: (count: 60, radius: (0.05, 0.12), speed: (1.0, 4.0), seed: 3))",
            bars.join(", ")
        ));
        step(&mut app, 1);
        let segments = app.world().resource::<Segments>().clone();
        let (e0, _) = energy_momentum(&mut app);
        let mut deepest = f64::MIN;
        for _ in 0..240 {
            step(&mut app, 1);
            for (p, _, r, _) in circles(&mut app) {
                deepest = deepest.max(depth(&segments, p, r) / r);
            }
        }
        let (e1, _) = energy_momentum(&mut app);
        assert!(
            deepest <= 1e-9,
            "{solver}: a circle went {deepest} radii into a wall"
        );
        assert_relative(solver, e1, e0, 1e-9);
        assert!(
            app.world().resource::<WallCollisions>().count > 200,
            "{solver}"
        );
    }
}

#[test]
fn scenes_declare_segments_as_polylines_and_bad_ones_are_refused_by_field() {
    let load = |extra: &str| {
        Scene::parse(&format!("(arena: (size: (4.0, 4.0)), {extra})"), "s.ron")
            .and_then(|s| s.to_config("s.ron"))
    };
    let ok = load("segments: [[(-1.0, 0.0), (0.0, 1.0), (1.0, 0.0)], [(1.5, -1.5), (1.5, 1.5)]]")
        .unwrap();
    assert_eq!(ok.segments.0.len(), 3);
    assert_eq!(
        ok.segments.0[2],
        Segment::new(DVec2::new(1.5, -1.5), DVec2::new(1.5, 1.5))
    );
    let refusals = [
        (
            "segments: [[(0.0, 0.0)]]",
            "`segments[0]`: a polyline needs at least two points",
        ),
        (
            "segments: [[(0.0, 0.0), (3.0, 0.0)]]",
            "`segments[0][1]`: [3, 0] is outside the arena",
        ),
        (
            "segments: [[(0.0, 0.0), (inf, 0.0)]]",
            "`segments[0][1]`: must be finite",
        ),
        (
            "segments: [[(-1.0, 0.0), (1.0, 0.0)]], circles: [(position: (0.5, 0.1), radius: 0.2)]",
            "`circles[0]`: overlaps segments[0]",
        ),
        (
            "arena: (size: (4.0, 4.0), boundary: periodic), segments: [[(0.0, 0.0), (1.0, 0.0)]]",
            "`segments`: segment walls need an arena with walls",
        ),
    ];
    for (extra, expected) in refusals {
        let text = if extra.starts_with("arena") {
            Scene::parse(&format!("({extra})"), "s.ron").and_then(|s| s.to_config("s.ron"))
        } else {
            load(extra)
        };
        let err = text.unwrap_err().to_string();
        assert!(err.contains(expected), "{extra}: {err}");
    }
}

#[test]
fn random_circles_are_placed_clear_of_segments_and_the_effect_runs_only_with_segments() {
    let mut with = scene_app(
        "(arena: (size: (6.0, 6.0)), segments: [[(-3.0, -3.0), (3.0, 3.0)], [(-3.0, 3.0), (3.0, -3.0)]],
          spawn: (count: 300, radius: (0.05, 0.1), seed: 9))",
    );
    let segments = with.world().resource::<Segments>().clone();
    let placed = circles(&mut with);
    assert_eq!(placed.len(), 300);
    for (p, _, r, _) in placed {
        assert!(
            depth(&segments, p, r) < 0.0,
            "a circle placed on a wall at {p}"
        );
    }
    assert!(system_names(&mut with).contains(&"bounce_off_segments".to_owned()));
    let mut without = scene_app("(arena: (size: (6.0, 6.0)), spawn: (count: 30))");
    assert!(!system_names(&mut without).contains(&"bounce_off_segments".to_owned()));
}
