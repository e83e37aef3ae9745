//! One of two players of the rollback pile over the network: a GGRS peer-to-peer session on
//! UDP, its sent packets dropped at the rate `--loss` says (5 % by default), inputs without
//! delay (so the other player's are predicted and every wrong guess rolled back). When the
//! frame `--frames` (1000) is confirmed by both players' inputs it prints that frame's
//! `state_hash`, keeps answering for a second (the other player may still need its inputs),
//! and exits; a desync GGRS detects, a lost peer or no result within two minutes exits non-zero.
//!
//! ```text
//! cargo run --features ggrs --example rollback_p2p -- --player 0 --port 7000 --peer 127.0.0.1:7001 &
//! cargo run --features ggrs --example rollback_p2p -- --player 1 --port 7001 --peer 127.0.0.1:7000
//! ```

mod pile;

use std::net::SocketAddr;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use bevy::prelude::*;
use bevy_ggrs::ggrs::{
    DesyncDetection, GgrsEvent, Message, NonBlockingSocket, PlayerType, SessionBuilder,
    UdpNonBlockingSocket,
};
use bevy_ggrs::{LoadWorld, RollbackFrameCount, SaveWorld, SaveWorldSystems, Session};
use moving_circles::game::rollback::ggrs::RollbackFrames;
use moving_circles::prelude::*;
use pile::{PLAYERS, PileConfig, pile_app};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// How long a run may take before it is given up.
const TIMEOUT: Duration = Duration::from_secs(120);

/// How long a player keeps answering after its last frame is confirmed.
const LINGER: Duration = Duration::from_secs(1);

/// The command line.
struct Args {
    player: usize,
    port: u16,
    peer: SocketAddr,
    frames: i32,
    loss: f64,
    solver: Solver,
}

/// GGRS's UDP socket, dropping a share of what it sends.
struct LossySocket {
    udp: UdpNonBlockingSocket,
    loss: f64,
    rng: ChaCha8Rng,
    counts: Arc<Counts>,
}

/// Packets sent and dropped.
#[derive(Default)]
struct Counts {
    sent: AtomicU64,
    dropped: AtomicU64,
}

impl NonBlockingSocket<SocketAddr> for LossySocket {
    fn send_to(&mut self, msg: &Message, addr: &SocketAddr) {
        self.counts.sent.fetch_add(1, Ordering::Relaxed);
        if self.rng.random_bool(self.loss) {
            self.counts.dropped.fetch_add(1, Ordering::Relaxed);
        } else {
            self.udp.send_to(msg, addr);
        }
    }

    fn receive_all_messages(&mut self) -> Vec<(SocketAddr, Message)> {
        self.udp.receive_all_messages()
    }
}

/// What the run saw: the hash of the frame asked for (when saved), rollbacks, and why it
/// failed if it did.
#[derive(Resource, Default)]
struct Watch {
    target: i32,
    hash: Option<u64>,
    rollbacks: u64,
    failure: Option<String>,
}

fn main() -> ExitCode {
    let args = match parse_args(std::env::args().skip(1)) {
        Ok(args) => args,
        Err(message) => {
            eprintln!("rollback_p2p: {message}");
            return ExitCode::from(2);
        }
    };
    match play(&args) {
        Ok(line) => {
            println!("{line}");
            ExitCode::SUCCESS
        }
        Err(message) => {
            eprintln!("rollback_p2p player {}: {message}", args.player);
            ExitCode::FAILURE
        }
    }
}

/// `--player 0|1 --port P --peer ADDR [--frames N] [--loss F] [--solver S]`.
fn parse_args(mut args: impl Iterator<Item = String>) -> Result<Args, String> {
    let (mut player, mut port, mut peer) = (None, None, None);
    let (mut frames, mut loss, mut solver) = (1000, 0.05, Solver::Soft(4));
    while let Some(flag) = args.next() {
        let value = args.next().ok_or(format!("{flag} needs a value"))?;
        let bad = |e: &dyn std::fmt::Display| format!("{flag} {value:?}: {e}");
        match flag.as_str() {
            "--player" => player = Some(value.parse::<usize>().map_err(|e| bad(&e))?),
            "--port" => port = Some(value.parse::<u16>().map_err(|e| bad(&e))?),
            "--peer" => peer = Some(value.parse::<SocketAddr>().map_err(|e| bad(&e))?),
            "--frames" => frames = value.parse().map_err(|e| bad(&e))?,
            "--loss" => loss = value.parse().map_err(|e| bad(&e))?,
            "--solver" => solver = value.parse().map_err(|e| bad(&e))?,
            _ => return Err(format!("unknown argument {flag:?}")),
        }
    }
    let player = player.ok_or("--player is required")?;
    if player >= PLAYERS {
        return Err(format!("--player {player}: 0 or 1"));
    }
    if !(1..=1_000_000).contains(&frames) {
        return Err(format!("--frames {frames}: between 1 and 1000000"));
    }
    if !(0.0..=0.5).contains(&loss) {
        return Err(format!("--loss {loss}: between 0 and 0.5"));
    }
    Ok(Args {
        player,
        port: port.ok_or("--port is required")?,
        peer: peer.ok_or("--peer is required")?,
        frames,
        loss,
        solver,
    })
}

/// Plays until the frame asked for is confirmed, and says its hash.
fn play(args: &Args) -> Result<String, String> {
    let udp = UdpNonBlockingSocket::bind_to_port(args.port)
        .map_err(|e| format!("binding UDP port {}: {e}", args.port))?;
    let counts = Arc::new(Counts::default());
    let socket = LossySocket {
        udp,
        loss: args.loss,
        rng: ChaCha8Rng::seed_from_u64(args.player as u64),
        counts: counts.clone(),
    };
    let session = SessionBuilder::<PileConfig>::new()
        .with_num_players(PLAYERS)
        .and_then(|b| b.add_player(PlayerType::Local, args.player))
        .and_then(|b| b.add_player(PlayerType::Remote(args.peer), 1 - args.player))
        .map(|b| b.with_desync_detection_mode(DesyncDetection::On { interval: 10 }))
        .and_then(|b| b.start_p2p_session(socket))
        .map_err(|e| format!("starting the session: {e}"))?;

    let mut app = pile_app(args.solver);
    app.insert_resource(Session::P2P(session))
        .insert_resource(Watch {
            target: args.frames,
            ..default()
        })
        .add_systems(SaveWorld, note_hash.after(SaveWorldSystems::Checksum))
        .add_systems(LoadWorld, |mut watch: ResMut<Watch>| watch.rollbacks += 1)
        .add_systems(Update, watch_events);

    let start = Instant::now();
    let mut confirmed_at = None;
    loop {
        app.update();
        let world = app.world();
        if let Some(failure) = &world.resource::<Watch>().failure {
            return Err(failure.clone());
        }
        let Session::P2P(session) = world.resource::<Session<PileConfig>>() else {
            unreachable!("a peer-to-peer session was inserted");
        };
        if confirmed_at.is_none() && session.confirmed_frame() >= args.frames {
            confirmed_at = Some(Instant::now());
        }
        if confirmed_at.is_some_and(|at| at.elapsed() >= LINGER) {
            break;
        }
        if start.elapsed() > TIMEOUT {
            return Err(format!(
                "frame {} not confirmed after {TIMEOUT:?} (confirmed {})",
                args.frames,
                session.confirmed_frame()
            ));
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    let watch = app.world().resource::<Watch>();
    let hash = watch
        .hash
        .ok_or(format!("frame {} was never saved", args.frames))?;
    Ok(format!(
        "player {}: frame {} state_hash {hash:016x} ({} rollbacks, {} of {} packets \
         dropped, {:.1} s)",
        args.player,
        args.frames,
        watch.rollbacks,
        counts.dropped.load(Ordering::Relaxed),
        counts.sent.load(Ordering::Relaxed),
        start.elapsed().as_secs_f64()
    ))
}

/// Keeps the hash of the frame asked for, as last saved (a rollback saves it again).
fn note_hash(
    frames: Res<RollbackFrames>,
    frame: Res<RollbackFrameCount>,
    mut watch: ResMut<Watch>,
) {
    if frame.0 == watch.target {
        watch.hash = frames.last_saved().map(|(_, hash)| hash);
    }
}

/// Turns a desync or a lost peer into a failure.
fn watch_events(mut session: ResMut<Session<PileConfig>>, mut watch: ResMut<Watch>) {
    let Session::P2P(session) = &mut *session else {
        return;
    };
    for event in session.events() {
        match event {
            GgrsEvent::DesyncDetected {
                frame,
                local_checksum,
                remote_checksum,
                ..
            } => {
                watch.failure = Some(format!(
                    "desync at frame {frame}: checksum {local_checksum:x} here, \
                     {remote_checksum:x} there"
                ));
            }
            GgrsEvent::Disconnected { .. } => {
                watch.failure = Some("the other player was lost".into());
            }
            _ => {}
        }
    }
}
