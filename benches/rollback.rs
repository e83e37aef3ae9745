//! Rollback in memory: what saving and restoring a `CirclesSnapshot` of the 2000-circle
//! `pile.ron` costs under `soft`, settled (20 s, asleep) and settled but kept awake (sleeping
//! off, 12 s), and a rollback of 8 frames (restore, then 8 steps) of the settled pile. Prints
//! each snapshot's bytes a circle and its contacts' bytes once.
//!
//! `cargo bench --bench rollback`

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use moving_circles::game::rollback::CirclesSnapshot;
use moving_circles::prelude::*;
use moving_circles::tools::run::headless_app;

/// `pile.ron` run `seconds` (with sleeping, if `sleep`), as an app and a snapshot of it.
fn settled_pile(seconds: u32, sleep: bool) -> (bevy::prelude::App, CirclesSnapshot) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes/pile.ron");
    let mut scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    scene.effects.sleep.enabled = sleep;
    let mut app = headless_app(scene);
    for _ in 0..seconds * 60 {
        app.update();
    }
    let snapshot = CirclesSnapshot::taken(app.world_mut());
    let (circles, contacts) = snapshot.bytes();
    let n = snapshot.len();
    eprintln!(
        "pile after {seconds} s, sleeping {sleep}: {n} circles, {:.1} bytes a circle, \
         {contacts} bytes of contacts ({:.1} a circle)",
        circles as f64 / n as f64,
        contacts as f64 / n as f64
    );
    (app, snapshot)
}

fn rollback(c: &mut Criterion) {
    let mut group = c.benchmark_group("rollback");
    for (name, seconds, sleep) in [("pile", 20, true), ("pile_awake", 12, false)] {
        let mut pile = None;
        group.bench_function(BenchmarkId::new("save_restore/soft", name), |b| {
            let (app, snapshot) = pile.get_or_insert_with(|| settled_pile(seconds, sleep));
            b.iter(|| {
                snapshot.save(app.world_mut());
                snapshot.restore(app.world_mut()).expect("the same circles");
            })
        });
    }
    let mut pile = None;
    group.sample_size(20);
    group.bench_function(BenchmarkId::new("rollback_8_frames/soft", "pile"), |b| {
        let (app, snapshot) = pile.get_or_insert_with(|| settled_pile(20, true));
        b.iter(|| {
            snapshot.restore(app.world_mut()).expect("the same circles");
            for _ in 0..8 {
                app.update();
            }
        })
    });
    group.finish();
}

criterion_group!(benches, rollback);
criterion_main!(benches);
