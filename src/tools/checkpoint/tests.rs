//! What the checkpoint reader refuses of a checkpoint we wrote, edited: any byte changed, cut
//! or added (the checksum), an arena that no longer holds its circles, an impossible radius, a sleeper that moves or turns, a rotation out of
//! range, a clock that is not its steps, parts of their own out of range or order, first
//! energies below zero or past the range.

use super::bytes::CHECKSUM_BYTES;
use super::*;
use bevy::math::DVec2;

/// The checkpoint of `app` as it is, which our reader takes back.
fn taken(app: &mut App) -> Checkpoint {
    let progress = Progress::start(app.world_mut());
    let good = Checkpoint::take(app.world_mut(), "t", &progress);
    assert!(Checkpoint::from_bytes(&good.to_bytes(), "c").is_ok());
    good
}

#[test]
fn every_byte_changed_cut_or_added_is_refused_as_damaged() {
    let mut config = CirclesConfig::default();
    config.spawn.count = 8;
    config.solver = "exact".parse().unwrap();
    let mut app = headless_app(config);
    app.update();
    let good = taken(&mut app).to_bytes();
    let damaged = |bytes: &[u8], what: &str| {
        let error = Checkpoint::from_bytes(bytes, "c")
            .expect_err(what)
            .to_string();
        assert!(error.contains("damaged checkpoint"), "{what}: {error}");
    };
    // Past the format's name (a change there says what the file is instead): one bit of each
    // byte, and a byte's every other value at a few places.
    let header = 1 + FORMAT.len();
    for at in header..good.len() {
        let mut changed = good.clone();
        changed[at] ^= 1 << (at % 8);
        damaged(&changed, &format!("bit {} of byte {at} flipped", at % 8));
    }
    for at in [header, good.len() / 2, good.len() - 1] {
        for value in 0..=255u8 {
            if value != good[at] {
                let mut changed = good.clone();
                changed[at] = value;
                damaged(&changed, &format!("byte {at} set to {value}"));
            }
        }
    }
    for cut in [
        header,
        good.len() / 2,
        good.len() - CHECKSUM_BYTES,
        good.len() - 1,
    ] {
        damaged(&good[..cut], &format!("cut to {cut} bytes"));
    }
    let mut longer = good.clone();
    longer.push(0);
    damaged(&longer, "a byte added");
    // Resealed, a byte added before the checksum is still refused: it is past the last field.
    let mut padded = good[..good.len() - CHECKSUM_BYTES].to_vec();
    padded.extend_from_slice(&[0; 1 + CHECKSUM_BYTES]);
    Checkpoint::reseal(&mut padded);
    let error = Checkpoint::from_bytes(&padded, "c")
        .unwrap_err()
        .to_string();
    assert!(error.contains("1 byte past its last field"), "{error}");
    // Resealing what we wrote changes nothing.
    let mut resealed = good.clone();
    Checkpoint::reseal(&mut resealed);
    assert_eq!(resealed, good);
}

#[test]
fn a_checkpoint_whose_arena_no_longer_holds_its_circles_is_refused() {
    let mut config = CirclesConfig::default();
    config.spawn.count = 16;
    config.solver = "exact".parse().unwrap();
    let mut app = headless_app(config);
    app.update();
    let good = taken(&mut app);
    // A bound moved within the range of values, past the circles on that side.
    let mut moved = good.clone();
    let leftmost = good
        .circles
        .iter()
        .map(|c| c.position.x)
        .fold(f64::MAX, f64::min);
    moved.arena.min.x = leftmost + 1e-3;
    let error = Checkpoint::from_bytes(&moved.to_bytes(), "c")
        .unwrap_err()
        .to_string();
    assert!(error.contains("outside the arena"), "{error}");
    moved.arena.min = DVec2::splat(-1e20);
    moved.arena.max = DVec2::splat(-1e19);
    assert!(Checkpoint::from_bytes(&moved.to_bytes(), "c").is_err());
    // A radius a scene could not give: overlaps of it are not measurable.
    let mut tiny = good.clone();
    tiny.circles[3].radius = 1e-310;
    let error = Checkpoint::from_bytes(&tiny.to_bytes(), "c")
        .unwrap_err()
        .to_string();
    assert!(error.contains("impossible radius"), "{error}");
    // A sleeper that turns would drive its neighbours like a wheel, and one that moves too
    // (found by the checkpoint fuzz target: without gravity `exact` flew it on, asleep).
    for (w, v, says) in [
        (3.0, 0.0, "asleep but turns"),
        (0.0, -1.6, "asleep but moves"),
    ] {
        let mut woken = good.clone();
        woken.sleep[2].asleep = true;
        (woken.circles[2].angular_velocity, woken.circles[2].velocity) = (w, DVec2::X * v);
        let error = Checkpoint::from_bytes(&woken.to_bytes(), "c").unwrap_err();
        assert!(error.to_string().contains(says), "{error}");
    }
    let mut spun = good.clone();
    spun.circles[2].rotation = 4.0;
    let error = Checkpoint::from_bytes(&spun.to_bytes(), "c")
        .unwrap_err()
        .to_string();
    assert!(error.contains("rotation"), "{error}");
}

#[test]
fn a_clock_that_is_not_its_steps_is_refused() {
    let mut app = headless_app(CirclesConfig {
        solver: "swept".parse().unwrap(),
        ..default()
    });
    for _ in 0..40 {
        app.update();
    }
    let good = taken(&mut app);
    // Run backwards (the fuzzer's find: a negative clock hid how coarsely a fast circle's
    // events resolve) or far ahead.
    for clock in [
        -good.steps.sim_seconds,
        1e12,
        good.steps.sim_seconds * (1.0 + 1e-9),
    ] {
        let mut bad = good.clone();
        bad.steps.sim_seconds = clock;
        let error = Checkpoint::from_bytes(&bad.to_bytes(), "c")
            .unwrap_err()
            .to_string();
        assert!(error.contains("its clock"), "{error}");
    }
}

#[test]
fn parts_of_their_own_out_of_range_or_order_are_refused() {
    use crate::base::collision_layers::Sensor;
    use crate::base::components::{Friction, Inertia, Restitution};
    let mut config = CirclesConfig::default();
    config.spawn.count = 8;
    let mut app = headless_app(config);
    let world = app.world_mut();
    let circles: Vec<Entity> = world
        .query_filtered::<Entity, With<crate::base::components::Radius>>()
        .iter(world)
        .collect();
    world
        .entity_mut(circles[1])
        .insert((Restitution(0.5), Friction(0.2)));
    world.entity_mut(circles[4]).insert((Inertia(0.01), Sensor));
    world.entity_mut(circles[6]).insert(Sensor);
    app.update();
    let progress = Progress::start(app.world_mut());
    let good = Checkpoint::take(app.world_mut(), "t", &progress);
    assert_eq!(good.own.len(), 3, "{:?}", good.own);
    assert!(Checkpoint::from_bytes(&good.to_bytes(), "c").is_ok());
    // Which entry is which, in the checkpoint's order of circles.
    let find = |has: fn(&own::OwnParts) -> bool| good.own.iter().position(has).unwrap();
    let rubbing = find(|p| p.restitution.is_some());
    let wheel = find(|p| p.inertia.is_some());
    let other = find(|p| p.sensor.is_some() && p.inertia.is_none());
    let refused = |edit: &dyn Fn(&mut Checkpoint), says: &str| {
        let mut bad = good.clone();
        edit(&mut bad);
        let error = Checkpoint::from_bytes(&bad.to_bytes(), "c")
            .unwrap_err()
            .to_string();
        assert!(error.contains(says), "{says}: {error}");
    };
    refused(
        &|c| c.own[rubbing].restitution = Some(1.5),
        "own restitution is 1.5",
    );
    refused(&|c| c.own[rubbing].friction = Some(-0.1), "own friction");
    refused(
        &|c| c.own[wheel].inertia = Some(f64::NAN),
        "own moment of inertia",
    );
    refused(&|c| c.own[2].circle = 8, "out of order or range");
    refused(&|c| c.own.swap(0, 1), "out of order or range");
    // A sensor overlapping itself, circles out of order, or another sensor.
    let sensor = good.own[wheel].circle;
    let says = format!("sensor circle {sensor} overlaps");
    refused(&|c| c.own[wheel].sensor = Some(vec![sensor]), &says);
    let plain: Vec<u32> = (0..8)
        .filter(|k| good.own.iter().all(|p| p.circle != *k))
        .collect();
    refused(
        &|c| c.own[wheel].sensor = Some(vec![plain[1], plain[0]]),
        &says,
    );
    let second = good.own[other].circle;
    refused(&|c| c.own[wheel].sensor = Some(vec![second]), &says);
    let mut fine = good.clone();
    fine.own[wheel].sensor = Some(vec![plain[0], plain[1]]);
    assert!(Checkpoint::from_bytes(&fine.to_bytes(), "c").is_ok());
}

#[test]
fn first_energies_below_zero_or_past_the_range_are_refused() {
    let mut config = CirclesConfig::default();
    config.spawn.count = 8;
    let mut app = headless_app(config);
    app.update();
    let good = taken(&mut app);
    // Each finite, as the fuzz target found them: their sum is -∞, and so was every report's
    // first energy.
    let mut bad = good.clone();
    bad.progress.before.kinetic_energy = -1.29e308;
    bad.progress.before.rotational_energy = -1.18e308;
    let mut huge = good.clone();
    huge.progress.before.kinetic_energy = 1.5e308;
    huge.progress.before.rotational_energy = 1.5e308;
    for bad in [bad, huge] {
        let error = Checkpoint::from_bytes(&bad.to_bytes(), "c")
            .unwrap_err()
            .to_string();
        assert!(error.contains("first energies"), "{error}");
    }
}
