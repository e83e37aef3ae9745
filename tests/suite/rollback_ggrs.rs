//! Rollback through `bevy_ggrs` (feature `ggrs`): GGRS's sync test passes on the rollback
//! examples' pile when a game despawns circles (the rollback library spawns them again with
//! new entities), and fails when a game keeps state outside rollback; two processes playing
//! over UDP on the loopback address with lost packets end on the same `state_hash`.

#[path = "../../examples/rollback/pile.rs"]
#[allow(dead_code)]
mod pile;

use std::net::UdpSocket;
use std::path::PathBuf;
use std::process::{Command, Stdio};

use bevy::prelude::*;
use bevy_ggrs::prelude::*;
use bevy_ggrs::{RollbackFrameCount, SyncTestMismatch};
use moving_circles::base::components::CircleSerial;
use moving_circles::game::rollback::ggrs::GgrsCirclesSystems;
use moving_circles::game::spawn::Dropped;
use moving_circles::prelude::*;
use pile::{PLAYERS, PileConfig, pile_app};

/// The frames GGRS reported as mismatched.
#[derive(Resource, Default)]
struct Mismatches(Vec<i32>);

/// Runs `app` in a sync test session at check distance 7 for `frames` frames (or to the
/// first mismatch); the mismatched frames, and the circles at the end less those dropped in.
fn sync_test(mut app: App, frames: i32) -> (Vec<i32>, usize) {
    let session = SessionBuilder::<PileConfig>::new()
        .with_num_players(PLAYERS)
        .unwrap()
        .with_check_distance(7)
        .start_synctest_session()
        .unwrap();
    app.insert_resource(Session::SyncTest(session))
        .init_resource::<Mismatches>()
        .add_observer(|m: On<SyncTestMismatch>, mut seen: ResMut<Mismatches>| {
            seen.0.push(m.current_frame);
        });
    for _ in 0..frames + 10 {
        app.update();
        let world = app.world();
        if world.resource::<RollbackFrameCount>().0 >= frames
            || !world.resource::<Mismatches>().0.is_empty()
        {
            break;
        }
    }
    let world = app.world_mut();
    let mismatches = world.resource::<Mismatches>().0.clone();
    assert!(world.resource::<RollbackFrameCount>().0 >= frames || !mismatches.is_empty());
    let circles = world.query::<&Radius>().iter(world).count();
    (mismatches, circles - world.resource::<Dropped>().count)
}

/// At frame 100 despawns the circle of the smallest serial (a new entity comes back on each
/// rollback past it), and at frame 150 takes out the next with `bevy_ggrs`'s deferred despawn.
fn despawn_two(
    mut commands: Commands,
    frame: Res<RollbackFrameCount>,
    circles: Query<(Entity, &CircleSerial)>,
) {
    let mut sorted: Vec<_> = circles.iter().map(|(e, s)| (*s, e)).collect();
    sorted.sort_unstable();
    match frame.0 {
        100 => commands.entity(sorted[0].1).despawn(),
        150 => commands.entity(sorted[0].1).despawn_rollback(),
        _ => {}
    }
}

#[test]
fn the_sync_test_passes_when_a_game_despawns_circles_under_every_solver() {
    let mut failures = Vec::new();
    for solver in [Solver::Discrete, Solver::Exact, Solver::Soft(4)] {
        let mut app = pile_app(solver);
        app.add_systems(GgrsSchedule, despawn_two.before(GgrsCirclesSystems::Step));
        let (mismatches, circles) = sync_test(app, 200);
        if !mismatches.is_empty() {
            failures.push(format!("{solver}: mismatched frames {mismatches:?}"));
        }
        // 50 spawned, two despawned.
        assert_eq!(circles, 50 - 2, "{solver}");
    }
    assert!(failures.is_empty(), "{failures:?}");
}

/// Nudges a circle every fifth time it runs: state (its count) outside rollback, so a frame
/// simulated again is not the frame simulated first.
fn nudge_by_hidden_count(mut runs: Local<u32>, mut circles: Query<&mut Velocity>) {
    *runs += 1;
    if runs.is_multiple_of(5)
        && let Some(mut v) = circles.iter_mut().next()
    {
        v.0.x += 0.1;
    }
}

#[test]
fn the_sync_test_fails_when_a_game_keeps_state_outside_rollback() {
    let mut app = pile_app(Solver::Soft(4));
    app.add_systems(
        GgrsSchedule,
        nudge_by_hidden_count
            .after(pile::kick)
            .before(GgrsCirclesSystems::Step),
    );
    let (mismatches, _) = sync_test(app, 100);
    assert!(!mismatches.is_empty(), "the sync test saw no mismatch");
}

/// A free UDP port on the loopback address.
fn free_port() -> u16 {
    let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
    socket.local_addr().unwrap().port()
}

#[test]
fn two_players_over_udp_with_lost_packets_end_on_the_same_state_hash() {
    // `cargo test` builds the examples next to the test binaries.
    let example: PathBuf = std::env::current_exe()
        .unwrap()
        .parent()
        .and_then(|deps| deps.parent())
        .unwrap()
        .join("examples")
        .join(format!("rollback_p2p{}", std::env::consts::EXE_SUFFIX));
    assert!(
        example.exists(),
        "{} is missing: cargo build --features ggrs --example rollback_p2p",
        example.display()
    );
    let ports = [free_port(), free_port()];
    let children: Vec<_> = (0..2)
        .map(|p| {
            Command::new(&example)
                .args(["--player", &p.to_string()])
                .args(["--port", &ports[p].to_string()])
                .args(["--peer", &format!("127.0.0.1:{}", ports[1 - p])])
                .args(["--frames", "1000", "--loss", "0.05"])
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    let mut hashes = Vec::new();
    let mut rollbacks = 0;
    for child in children {
        let out = child.wait_with_output().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "a player failed: {stdout}{stderr}");
        // "player 0: frame 1000 state_hash 292d836b0e66a8be (14 rollbacks, ..."
        let word_after = |word: &str| {
            let words: Vec<&str> = stdout.split_whitespace().collect();
            let k = words.iter().position(|w| *w == word).unwrap();
            words[k + 1].trim_start_matches('(').to_string()
        };
        hashes.push(word_after("state_hash"));
        let before = |word: &str| {
            let words: Vec<&str> = stdout.split_whitespace().collect();
            let k = words.iter().position(|w| w.starts_with(word)).unwrap();
            words[k - 1].trim_start_matches('(').parse::<u64>().unwrap()
        };
        rollbacks += before("rollbacks");
    }
    assert_eq!(hashes[0], hashes[1], "the players ended apart");
    // The other player's inputs were guessed wrong and the frames played again.
    assert!(
        rollbacks > 0,
        "no rollback happened: the test tests nothing"
    );
}
