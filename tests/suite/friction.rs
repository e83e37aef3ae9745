//! Friction and rolling under the contact solver `soft`, against the mechanics of a uniform
//! disc (moment of inertia m r² / 2): rolling down a slope at (2/3) g sin θ, slipping at
//! g (sin θ − μ cos θ) below the friction threshold, a disc launched sliding that starts to roll
//! at t = v₀ / (3 μ g) with 2/3 of its speed, rolling resistance's steady deceleration, and
//! spin passed between two circles within the Coulomb bound, momentum kept; a circle of its own
//! moment of inertia (a ring) rolls as its inertia says.

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::prelude::*;

const G: f64 = 9.81;

/// An open arena under gravity with `segments`, friction `mu` against walls and circles, the
/// contact solver at its defaults, and no sleeping (a test watches every step).
fn rough(mu: f64, rolling_resistance: f64, segments: Vec<Segment>) -> CirclesConfig {
    CirclesConfig {
        arena: Arena::centered(DVec2::new(16.0, 9.0)).with_boundary(Boundary::Open),
        solver: Solver::Soft(4),
        effects: Effects {
            gravity: Some(DVec2::new(0.0, -G)),
            restitution: 0.0,
            wall_restitution: 0.0,
            friction: mu,
            wall_friction: mu,
            rolling_resistance,
            sleep: SleepConfig {
                enabled: false,
                ..default()
            },
            ..default()
        },
        segments: Segments(segments),
        ..default()
    }
}

fn spin(app: &App, e: Entity) -> f64 {
    app.world().get::<AngularVelocity>(e).unwrap().0
}

/// A disc of radius 0.5 released at rest on a slope of `degrees` with friction `mu`: its
/// acceleration along the slope, measured between 0.25 s and 1.25 s, and its rolling ratio
/// `-ω r / v` at the end (1 when it rolls without slipping).
fn down_the_slope(degrees: f64, mu: f64) -> (f64, f64) {
    down_the_slope_with(degrees, mu, None)
}

/// [`down_the_slope`] for a circle of its `own` moment of inertia.
fn down_the_slope_with(degrees: f64, mu: f64, own: Option<Inertia>) -> (f64, f64) {
    let theta = degrees.to_radians();
    let down = DVec2::new(theta.cos(), -theta.sin());
    let (top, r) = (DVec2::new(-60.0, 30.0), 0.5);
    let slope = Segment::new(top, top + down * 200.0);
    let mut app = create_app(rough(mu, 0.0, vec![slope]));
    // On the slope's upper side, touching it, 5 m down from its top.
    let up = DVec2::new(theta.sin(), theta.cos());
    let ball = spawn_circle(&mut app, top + down * 5.0 + up * r, DVec2::ZERO, r, 1.0);
    if let Some(own) = own {
        app.world_mut().entity_mut(ball).insert(own);
    }
    step(&mut app, 15);
    let v1 = state(&app, ball).1.dot(down);
    step(&mut app, 60);
    let (_, v) = state(&app, ball);
    let v2 = v.dot(down);
    assert!(v.dot(up).abs() < 1e-3 * v2, "left the slope: {v}");
    ((v2 - v1) / 1.0, -spin(&app, ball) * r / v2)
}

#[test]
fn a_disc_with_enough_friction_rolls_down_a_slope_at_two_thirds_of_g_sin_theta() {
    for (degrees, mu) in [(20.0, 0.5), (35.0, 0.3), (10.0, 0.1)] {
        let (a, rolling) = down_the_slope(degrees, mu);
        let expected = 2.0 / 3.0 * G * f64::to_radians(degrees).sin();
        println!(
            "rolls at {degrees}°, μ {mu}: a {a:.5}, analytic {expected:.5}, -ωr/v {rolling:.5}"
        );
        assert_relative(
            &format!("acceleration at {degrees}°, μ {mu}"),
            a,
            expected,
            0.01,
        );
        assert_relative("rolling ratio -ω r / v", rolling, 1.0, 0.01);
    }
}

#[test]
fn a_ring_rolls_down_a_slope_at_half_of_g_sin_theta_a_heavy_core_faster_a_point_faster_still() {
    // Rolling, a circle of moment of inertia I accelerates at g sin θ / (1 + I / (m r²)): a
    // ring (I = m r²) at half of g sin θ, a ball with a heavy core (I = m r² / 5) at 5/6, and
    // one whose moment is too small for its inverse to be a number (1e-310) at g sin θ, turning
    // as it slides.
    for (inertia, share) in [(0.25, 0.5), (0.05, 5.0 / 6.0), (1e-310, 1.0)] {
        let (a, rolling) = down_the_slope_with(30.0, 0.8, Some(Inertia(inertia)));
        let expected = share * G * f64::to_radians(30.0).sin();
        println!("I = {inertia:e}: a {a:.5}, analytic {expected:.5}, -ωr/v {rolling:.5}");
        assert_relative(&format!("acceleration, I = {inertia:e}"), a, expected, 0.01);
        assert_relative("rolling ratio -ω r / v", rolling, 1.0, 0.01);
    }
}

#[test]
fn below_the_friction_threshold_a_disc_slips_at_g_sin_minus_mu_cos() {
    // Rolling needs μ ≥ tan θ / 3; at 30° that is 0.19.
    for (degrees, mu) in [(30.0, 0.1), (45.0, 0.2), (20.0, 0.0)] {
        let (a, rolling) = down_the_slope(degrees, mu);
        let theta = f64::to_radians(degrees);
        let expected = G * (theta.sin() - mu * theta.cos());
        println!("slips at {degrees}°, μ {mu}: a {a:.5}, analytic {expected:.5}");
        assert_relative(
            &format!("acceleration at {degrees}°, μ {mu}"),
            a,
            expected,
            0.01,
        );
        assert!(rolling < 0.9, "a slipping disc rolls: ratio {rolling}");
    }
}

#[test]
fn a_disc_launched_sliding_starts_to_roll_at_the_analytic_time_with_two_thirds_of_its_speed() {
    let (v0, mu, r) = (3.0, 0.3, 0.5);
    let floor = Segment::new(DVec2::new(-50.0, 0.0), DVec2::new(50.0, 0.0));
    let mut app = create_app(rough(mu, 0.0, vec![floor]));
    let disc = spawn_circle(&mut app, DVec2::new(-40.0, r), DVec2::new(v0, 0.0), r, 1.0);
    // Slip (the contact point's speed over the floor) falls at 3 μ g while the disc slides:
    // the time it reaches zero, found on the line through the last two sliding steps.
    let slip = |app: &App| state(app, disc).1.x + spin(app, disc) * r;
    let dt = 1.0 / 60.0;
    let mut samples = vec![(0.0, v0)];
    for k in 1..=60 {
        step(&mut app, 1);
        samples.push((k as f64 * dt, slip(&app)));
    }
    let stop = samples.iter().position(|&(_, s)| s.abs() < 1e-6).unwrap();
    let ((t1, s1), (t2, s2)) = (samples[stop - 2], samples[stop - 1]);
    let rolls_at = t2 + s2 * (t2 - t1) / (s1 - s2);
    let v = state(&app, disc).1.x;
    println!(
        "rolls from {rolls_at:.5} s (analytic {:.5}) at {v:.5} m/s",
        v0 / (3.0 * mu * G)
    );
    assert_relative(
        "time it starts to roll",
        rolls_at,
        v0 / (3.0 * mu * G),
        0.01,
    );
    let (_, v) = state(&app, disc);
    assert_relative("speed once rolling", v.x, 2.0 / 3.0 * v0, 0.01);
    assert_relative(
        "spin once rolling",
        -spin(&app, disc) * r,
        2.0 / 3.0 * v0,
        0.01,
    );
}

#[test]
fn rolling_resistance_slows_a_rolling_disc_at_two_thirds_of_its_coefficient_times_g() {
    // A torque c N r on a rolling uniform disc decelerates it at c g / (1 + 1/2).
    let (c, r, v0) = (0.02, 0.5, 2.0);
    let floor = Segment::new(DVec2::new(-50.0, 0.0), DVec2::new(50.0, 0.0));
    let mut app = create_app(rough(0.5, c, vec![floor]));
    let disc = spawn_circle(&mut app, DVec2::new(-40.0, r), DVec2::new(v0, 0.0), r, 1.0);
    app.world_mut().get_mut::<AngularVelocity>(disc).unwrap().0 = -v0 / r;
    step(&mut app, 15);
    let v1 = state(&app, disc).1.x;
    step(&mut app, 60);
    let v2 = state(&app, disc).1.x;
    println!(
        "slows at {:.5} m/s² (analytic {:.5})",
        v1 - v2,
        2.0 / 3.0 * c * G
    );
    assert_relative("deceleration", v1 - v2, 2.0 / 3.0 * c * G, 0.01);
    // Without rolling resistance it rolls on at its speed.
    let mut app = create_app(rough(0.5, 0.0, vec![floor]));
    let disc = spawn_circle(&mut app, DVec2::new(-40.0, r), DVec2::new(v0, 0.0), r, 1.0);
    app.world_mut().get_mut::<AngularVelocity>(disc).unwrap().0 = -v0 / r;
    step(&mut app, 75);
    assert_relative("speed without resistance", state(&app, disc).1.x, v0, 1e-6);
}

#[test]
fn a_spinning_disc_pressed_against_another_turns_it_the_other_way_and_keeps_momentum() {
    let mut config = rough(0.4, 0.0, Vec::new());
    config.effects.gravity = None;
    let mut app = create_app(config);
    let a = spawn_circle(
        &mut app,
        DVec2::new(-1.0, 0.0),
        DVec2::new(1.0, 0.0),
        0.5,
        1.0,
    );
    let b = spawn_circle(&mut app, DVec2::new(0.2, 0.0), DVec2::ZERO, 0.5, 2.0);
    app.world_mut().get_mut::<AngularVelocity>(a).unwrap().0 = 20.0;
    let (energy, momentum) = energy_momentum(&mut app);
    let rotational = 0.5 * (0.5 * 1.0 * 0.25) * 400.0;
    step(&mut app, 60);
    let (moved, after) = energy_momentum(&mut app);
    assert!((after - momentum).length() < 1e-12, "{momentum} -> {after}");
    // Like gears: b turns clockwise, a slows; a's surface, moving up where they touch,
    // drags b up with at most μ times the hit's impulse (2/3, the two stopping along the
    // line at restitution 0).
    let (wa, wb) = (spin(&app, a), spin(&app, b));
    assert!(wb < -0.1 && wa < 20.0, "spins {wa} {wb}");
    let most = 0.4 * (2.0 / 3.0) / 2.0;
    let up = state(&app, b).1.y;
    assert!(
        up > 0.5 * most && up <= most * (1.0 + 1e-9),
        "{up} against {most}"
    );
    let spinning = 0.5 * (0.5 * 0.25) * wa * wa + 0.5 * (0.5 * 2.0 * 0.25) * wb * wb;
    assert!(moved + spinning <= energy + rotational, "energy grew");
}

/// A repository scene, as the command line loads it.
fn scene(name: &str) -> App {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets/scenes")
        .join(name);
    create_app(Scene::load(&path).unwrap_or_else(|e| panic!("{e}")))
}

/// The angles of a heap's two flanks (degrees), from its circles `(centre, radius)` below
/// `below`: the top of the heap in columns three of the largest radii wide, and on each side
/// of the highest column a line fitted by least squares through the columns between a fifth
/// and four fifths of the heap's height.
fn repose_angles(circles: &[(DVec2, f64)], below: f64) -> (f64, f64) {
    let heap: Vec<_> = circles.iter().filter(|(p, _)| p.y < below).collect();
    let width = 3.0 * heap.iter().map(|(_, r)| *r).fold(0.0, f64::max);
    let floor = heap.iter().map(|(p, r)| p.y - r).fold(f64::MAX, f64::min);
    let mut tops = std::collections::BTreeMap::<i64, f64>::new();
    for &&(p, r) in &heap {
        let top = tops.entry((p.x / width).floor() as i64).or_insert(0.0);
        *top = top.max(p.y + r - floor);
    }
    let peak = tops.values().copied().fold(0.0, f64::max);
    let crest = tops
        .iter()
        .find(|&(_, &h)| h == peak)
        .map(|(&k, _)| k)
        .unwrap();
    let flank = |left: bool| {
        let points: Vec<(f64, f64)> = tops
            .iter()
            .filter(|&(&k, _)| k != crest && (k < crest) == left)
            .filter(|&(_, &h)| h > 0.2 * peak && h < 0.8 * peak)
            .map(|(&k, &h)| ((k - crest).abs() as f64 * width, h))
            .collect();
        if points.len() < 3 {
            return 0.0; // no flank: flat
        }
        let n = points.len() as f64;
        let (mx, my) = points
            .iter()
            .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
        let (sxy, sxx) = points.iter().fold((0.0, 0.0), |(a, b), (x, y)| {
            (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
        });
        (-sxy / sxx).atan().to_degrees()
    };
    (flank(true), flank(false))
}

/// The circles as `(centre, radius)`.
fn discs(app: &mut App) -> Vec<(DVec2, f64)> {
    circles(app).iter().map(|&(p, _, r, _)| (p, r)).collect()
}

#[test]
fn a_pile_poured_with_friction_stands_at_its_angle_of_repose_and_sleeps() {
    // The hopper's outlet is at y = -3: the heap is what lies below it.
    let mut app = scene("repose.ron");
    step(&mut app, 60 * 15);
    let settled = discs(&mut app);
    let (left, right) = repose_angles(&settled, -3.0);
    println!("angle of repose at μ 0.5: left {left:.1}°, right {right:.1}°");
    for angle in [left, right] {
        assert!(
            (10.0..35.0).contains(&angle),
            "flanks at {left:.1}° and {right:.1}°"
        );
    }
    let asleep = app.world().resource::<Sleeping>().count;
    assert_eq!(
        asleep,
        settled.len(),
        "{asleep} of {} asleep",
        settled.len()
    );
    // Nothing flows after settling.
    step(&mut app, 60 * 5);
    let moved = settled
        .iter()
        .zip(&discs(&mut app))
        .map(|((a, r), (b, _))| a.distance(*b) / r)
        .fold(0.0, f64::max);
    assert!(moved < 0.01, "a circle moved {moved} radii after settling");
    // The same pour without friction flows out flat.
    let mut app = scene("repose.ron");
    let smooth = Effects {
        friction: 0.0,
        wall_friction: 0.0,
        rolling_resistance: 0.0,
        ..*app.world().resource::<Effects>()
    };
    app.world_mut().insert_resource(smooth);
    step(&mut app, 60 * 15);
    let (left, right) = repose_angles(&discs(&mut app), -3.0);
    println!("the same without friction: left {left:.1}°, right {right:.1}°");
    assert!(
        left.max(right) < 6.0,
        "smooth flanks at {left:.1}° and {right:.1}°"
    );
}

#[test]
fn the_slope_scene_rolls_its_balls_down_turning_and_puts_them_to_sleep() {
    let mut app = scene("slope.ron");
    step(&mut app, 30);
    let turning: Vec<f64> = app
        .world_mut()
        .query::<&AngularVelocity>()
        .iter(app.world())
        .map(|w| w.0)
        .collect();
    // Rolling down to the right turns clockwise.
    assert!(turning.iter().all(|&w| w < -1.0), "{turning:?}");
    step(&mut app, 60 * 20);
    assert_eq!(app.world().resource::<Sleeping>().count, 4);
}

#[test]
fn a_spinning_ball_dropped_on_the_floor_bounces_off_the_way_its_spin_throws_it() {
    let mut app = scene("spin.ron");
    let balls: Vec<Entity> = app
        .world_mut()
        .query_filtered::<Entity, With<Radius>>()
        .iter(app.world())
        .collect();
    // 4.1 m to fall: the floor is hit after about 0.9 s.
    step(&mut app, 70);
    let vx: Vec<f64> = balls.iter().map(|&b| state(&app, b).1.x).collect();
    let w: Vec<f64> = balls.iter().map(|&b| spin(&app, b)).collect();
    assert!(vx[0] < -0.5 && vx[2] > 0.5, "{vx:?}");
    assert_eq!(vx[1], 0.0, "the ball without spin bounced sideways");
    // Friction took spin away: the spinning balls turn slower than at first.
    assert!(
        w[0] > 0.0 && w[0] < 30.0 && w[2] < 0.0 && w[2] > -30.0,
        "{w:?}"
    );
    assert_eq!(w[1], 0.0);
    // Mirror images: the same speeds, opposite directions.
    assert!((vx[0] + vx[2]).abs() < 1e-9 && (w[0] + w[2]).abs() < 1e-9);
}

#[test]
fn rolling_resistance_switched_off_leaves_no_push_behind() {
    // A rolling disc slowed by rolling resistance, which a game then switches off: from then
    // on it rolls at a constant speed (a warm-started torque no row takes back would drive it).
    let (r, v0) = (0.5, 2.0);
    let floor = Segment::new(DVec2::new(-50.0, 0.0), DVec2::new(50.0, 0.0));
    let mut app = create_app(rough(0.5, 0.05, vec![floor]));
    let disc = spawn_circle(&mut app, DVec2::new(-40.0, r), DVec2::new(v0, 0.0), r, 1.0);
    app.world_mut().get_mut::<AngularVelocity>(disc).unwrap().0 = -v0 / r;
    step(&mut app, 30);
    assert!(
        state(&app, disc).1.x < v0 - 0.01,
        "rolling resistance did not slow it"
    );
    app.world_mut().resource_mut::<Effects>().rolling_resistance = 0.0;
    step(&mut app, 2);
    let v1 = state(&app, disc).1.x;
    step(&mut app, 60);
    assert_relative("speed once it is off", state(&app, disc).1.x, v1, 1e-9);
}

#[test]
fn a_circle_spinning_in_place_is_not_at_rest_and_does_not_fall_asleep() {
    // On a frictionless floor nothing slows its spin, so it never rests.
    let mut config = rough(0.0, 0.0, Vec::new());
    config.arena = Arena::centered(DVec2::new(16.0, 9.0));
    config.effects.sleep = SleepConfig::default();
    let mut app = create_app(config);
    let top = spawn_circle(&mut app, DVec2::new(0.0, -4.0), DVec2::ZERO, 0.5, 1.0);
    let still = spawn_circle(&mut app, DVec2::new(3.0, -4.0), DVec2::ZERO, 0.5, 1.0);
    app.world_mut().get_mut::<AngularVelocity>(top).unwrap().0 = 5.0;
    step(&mut app, 120);
    let asleep = |app: &App, e: Entity| app.world().get::<Sleep>(e).unwrap().asleep;
    assert!(asleep(&app, still), "the circle at rest did not sleep");
    assert!(!asleep(&app, top), "the spinning circle fell asleep");
    assert_eq!(spin(&app, top), 5.0);
}

#[test]
fn a_spinning_kinematic_wheel_drives_a_ball_resting_on_it_and_its_work_is_counted() {
    // A wheel (immovable, turning counter-clockwise) whose top moves to the left carries a
    // ball resting on it to the left; the work it does is what the ball gains, less friction.
    let mut app = create_app(rough(0.5, 0.0, Vec::new()));
    let wheel = app
        .world_mut()
        .spawn((
            Radius(1.0),
            Position(DVec2::ZERO),
            Mass::IMMOVABLE,
            AngularVelocity(2.0),
        ))
        .id();
    let ball = spawn_circle(&mut app, DVec2::new(0.0, 1.3), DVec2::ZERO, 0.3, 1.0);
    step(&mut app, 20);
    let (p, v) = state(&app, ball);
    assert!(
        v.x < -0.1 && p.x < -0.01,
        "the ball was not carried left: {p} {v}"
    );
    assert_eq!(spin(&app, wheel), 2.0, "nothing turns a kinematic wheel");
    let work = app.world().resource::<PairCollisions>().immovable_work;
    assert!(work > 0.0, "the wheel did no work: {work}");
}
