//! GGRS's sync test on a pile of circles: every frame is rolled back `--check-distance`
//! frames (7 by default) and simulated again, and the checksums of the two runs compared; any
//! difference is a mismatch, and the example exits non-zero. Runs each solver given with
//! `--solver` (all five by default) for `--frames` frames (600: 10 s of the game).
//!
//! `cargo run --features ggrs --example rollback_synctest -- --solver soft --frames 600`

mod pile;

use std::process::ExitCode;

use bevy::prelude::*;
use bevy_ggrs::RollbackFrameCount;
use bevy_ggrs::prelude::*;
use moving_circles::game::rollback::ggrs::RollbackFrames;
use moving_circles::prelude::*;
use pile::{PLAYERS, PileConfig, pile_app};

/// What one solver's sync test saw.
struct Outcome {
    frames: i32,
    mismatches: Vec<i32>,
    most_asleep: usize,
    circles: usize,
    hash: u64,
}

/// The frames GGRS reported as mismatched.
#[derive(Resource, Default)]
struct Mismatches(Vec<i32>);

fn main() -> ExitCode {
    let (solvers, frames, distance) = match parse_args(std::env::args().skip(1)) {
        Ok(args) => args,
        Err(message) => {
            eprintln!("rollback_synctest: {message}");
            return ExitCode::from(2);
        }
    };
    let mut failed = false;
    for solver in solvers {
        let outcome = sync_test(solver, frames, distance);
        let verdict = if outcome.mismatches.is_empty() && outcome.frames >= frames {
            "ok"
        } else {
            failed = true;
            "MISMATCH"
        };
        println!(
            "{solver:<11} {verdict}: {} frames at check distance {distance}, {} circles, \
             up to {} asleep, state_hash {:016x}{}",
            outcome.frames,
            outcome.circles,
            outcome.most_asleep,
            outcome.hash,
            if outcome.mismatches.is_empty() {
                String::new()
            } else {
                format!(", mismatched frames {:?}", outcome.mismatches)
            }
        );
    }
    if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

/// `--solver S` (repeatable), `--frames N`, `--check-distance D`.
fn parse_args(mut args: impl Iterator<Item = String>) -> Result<(Vec<Solver>, i32, usize), String> {
    let (mut solvers, mut frames, mut distance) = (Vec::new(), 600, 7);
    while let Some(flag) = args.next() {
        let mut value = || args.next().ok_or(format!("{flag} needs a value"));
        match flag.as_str() {
            "--solver" => solvers.push(
                value()?
                    .parse::<Solver>()
                    .map_err(|e| format!("--solver: {e}"))?,
            ),
            "--frames" => {
                frames = value()?.parse().map_err(|e| format!("--frames: {e}"))?;
            }
            "--check-distance" => {
                distance = value()?
                    .parse()
                    .map_err(|e| format!("--check-distance: {e}"))?;
            }
            _ => return Err(format!("unknown argument {flag:?}")),
        }
    }
    if !(1..=1_000_000).contains(&frames) {
        return Err(format!("--frames {frames}: between 1 and 1000000"));
    }
    if solvers.is_empty() {
        solvers = vec![
            Solver::Discrete,
            Solver::Substeps(4),
            Solver::Swept,
            Solver::Exact,
            Solver::Soft(4),
        ];
    }
    Ok((solvers, frames, distance))
}

/// Runs `frames` frames of the pile under `solver` in a sync test session.
fn sync_test(solver: Solver, frames: i32, distance: usize) -> Outcome {
    let mut app = pile_app(solver);
    let session = SessionBuilder::<PileConfig>::new()
        .with_num_players(PLAYERS)
        .expect("two players are allowed")
        .with_check_distance(distance)
        .start_synctest_session()
        .expect("a sync test session of two local players");
    app.insert_resource(Session::SyncTest(session))
        .init_resource::<Mismatches>()
        .add_observer(
            |mismatch: On<SyncTestMismatch>, mut seen: ResMut<Mismatches>| {
                seen.0.push(mismatch.current_frame);
            },
        );
    let mut most_asleep = 0;
    let mut frame = 0;
    // One GGRS frame per update; a few spare updates for the first, which has no time yet.
    for _ in 0..frames + 10 {
        app.update();
        let world = app.world();
        most_asleep = most_asleep.max(world.resource::<Sleeping>().count);
        frame = world.resource::<RollbackFrameCount>().0;
        if frame >= frames || !world.resource::<Mismatches>().0.is_empty() {
            break;
        }
    }
    let world = app.world_mut();
    let circles = world.query::<&Radius>().iter(world).count();
    Outcome {
        frames: frame,
        mismatches: world.resource::<Mismatches>().0.clone(),
        most_asleep,
        circles,
        hash: world
            .resource::<RollbackFrames>()
            .last_saved()
            .map_or(0, |(_, hash)| hash),
    }
}
