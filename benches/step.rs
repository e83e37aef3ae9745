//! Whole-App benchmarks: one `app.update()` (exactly one fixed step) of a headless app, after
//! `finish()`, spawning and one warm-up step. Per solver on gases of growing N, and the price of
//! effects: a no-collision scene against the same scene with collisions and against bare
//! integration; collision messages off and on; layers and sensors; a gas without and among
//! 2000 segment walls; a sparse step, where the step's own work is all there is; the pile
//! scenes once they rest; and the 2000-circle pile settled but kept awake.
//!
//! `cargo bench --bench step`; set `MC_BENCH_LARGE=1` to add N = 100k for every solver and
//! N = 1M for `discrete`.

mod common;

use bevy::prelude::{App, Entity, With};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use moving_circles::prelude::*;
use moving_circles::tools::run::headless_app;

use common::gas;

fn bench_config(c: &mut Criterion, group: &str, id: BenchmarkId, n: usize, config: CirclesConfig) {
    bench_app(c, group, id, n, headless_app(config));
}

/// [`bench_config`] on an app already built (and changed by the caller).
fn bench_app(c: &mut Criterion, group: &str, id: BenchmarkId, n: usize, mut app: App) {
    app.update(); // warm-up step
    let mut group = c.benchmark_group(group);
    group
        .sample_size(15)
        .throughput(Throughput::Elements(n as u64));
    group.bench_function(id, |b| b.iter(|| app.update()));
    group.finish();
}

fn solvers(c: &mut Criterion) {
    let large = common::large();
    let mut sizes = vec![1_000, 10_000];
    if large {
        sizes.push(100_000);
    }
    let solvers = [
        Solver::Discrete,
        Solver::Substeps(4),
        Solver::Swept,
        Solver::Exact,
    ];
    for n in sizes {
        for solver in solvers {
            let id = BenchmarkId::new(solver.to_string(), n);
            bench_config(c, "step_gas", id, n, gas(n, solver));
        }
    }
    if large {
        let n = 1_000_000;
        let id = BenchmarkId::new(Solver::Discrete.to_string(), n);
        bench_config(c, "step_gas", id, n, gas(n, Solver::Discrete));
    }
}

/// What an effect costs: the same 10k circles with walls only (the `drift` kind of scene),
/// periodic (wrap only), and with walls and collisions.
fn effects(c: &mut Criterion) {
    let n = 10_000;
    let variants = [
        ("walls_only", Boundary::Walls, false),
        ("periodic_only", Boundary::Periodic, false),
        ("walls_and_collisions", Boundary::Walls, true),
    ];
    for (name, boundary, collisions) in variants {
        let config = gas(n, Solver::Discrete);
        let config = CirclesConfig {
            arena: config.arena.with_boundary(boundary),
            effects: Effects {
                collisions,
                ..config.effects
            },
            ..config
        };
        bench_config(c, "step_effects", BenchmarkId::new(name, n), n, config);
    }
}

/// What collision messages cost: a walled 10k gas with collisions, messages off and on, under
/// `discrete` and `exact` (off, there is no extra system and nothing is recorded).
fn hit_messages(c: &mut Criterion) {
    let n = 10_000;
    for solver in [Solver::Discrete, Solver::Exact] {
        for on in [false, true] {
            let config = gas(n, solver);
            let config = CirclesConfig {
                arena: config.arena.with_boundary(Boundary::Walls),
                effects: Effects {
                    hit_messages: on,
                    ..config.effects
                },
                ..config
            };
            let name = format!("{solver}/{}", if on { "on" } else { "off" });
            bench_config(c, "step_hit_messages", BenchmarkId::new(name, n), n, config);
        }
    }
}

/// What layers and sensors cost: the walled 10k gas as it is (`plain`), split into two teams
/// that meet only themselves (`teams`: every circle has layers, half the pairs are skipped),
/// and with 16 still sensor zones among the circles (`sensors`), under `discrete`, `soft=4`
/// and `exact`. `plain` is the price a scene without layers pays (nothing is gathered).
fn layers(c: &mut Criterion) {
    let n = 10_000;
    for solver in [Solver::Discrete, Solver::Soft(4), Solver::Exact] {
        for variant in ["plain", "teams", "sensors"] {
            let mut app = headless_app(gas(n, solver));
            let world = app.world_mut();
            let circles: Vec<Entity> = world
                .query_filtered::<Entity, With<Radius>>()
                .iter(world)
                .collect();
            match variant {
                "teams" => {
                    for (k, &e) in circles.iter().enumerate() {
                        let team = 1 << (1 + k % 2);
                        world.entity_mut(e).insert(CollisionLayers::new(team, team));
                    }
                }
                "sensors" => {
                    let arena = *world.resource::<Arena>();
                    for k in 0..16 {
                        let at = arena.min
                            + arena.size()
                                * bevy::math::DVec2::new(
                                    (k % 4) as f64 / 4.0 + 0.125,
                                    (k / 4) as f64 / 4.0 + 0.125,
                                );
                        world.spawn((Radius(2.0), Position(at), Mass::IMMOVABLE, Sensor));
                    }
                }
                _ => {}
            }
            let id = BenchmarkId::new(format!("{solver}/{variant}"), n);
            bench_app(c, "step_layers", id, n, app);
        }
    }
}

/// What segment walls cost: a walled 10k gas with collisions, without segments and among 2000
/// short bars (a 50 × 40 grid of them), under `discrete` and `exact`.
fn segments(c: &mut Criterion) {
    let n = 10_000;
    for solver in [Solver::Discrete, Solver::Exact] {
        for bars in [0, 2000] {
            let config = gas(n, solver);
            let arena = config.arena.with_boundary(Boundary::Walls);
            let cell = arena.size() / bevy::math::DVec2::new(50.0, 40.0);
            let segments = (0..bars)
                .map(|k| {
                    let centre = arena.min
                        + cell
                            * bevy::math::DVec2::new((k % 50) as f64 + 0.5, (k / 50) as f64 + 0.5);
                    let half = cell * 0.15;
                    Segment::new(centre - half, centre + half)
                })
                .collect();
            let config = CirclesConfig {
                arena,
                segments: Segments(segments),
                ..config
            };
            let name = format!("{solver}/{bars}");
            bench_config(c, "step_segments", BenchmarkId::new(name, n), n, config);
        }
    }
}

/// What a point of `moving_circles eos` costs through the app (lattice, melting, blocks, the
/// speed test): 4096 disks at area fractions 0.3 and 0.7, 20 collisions per disk discarded and
/// 4 blocks of 20 measured; throughput in pair collisions (engine alone: `exact_density` in
/// the kernels bench).
fn eos_point(c: &mut Criterion) {
    use moving_circles::tools::eos::{EosOptions, measure};
    let mut group = c.benchmark_group("eos_point");
    group.sample_size(10);
    for phi in [0.3, 0.7] {
        let options = EosOptions {
            n: 4096,
            area_fractions: vec![phi],
            equilibrate: 20.0,
            blocks: 4,
            block: 20.0,
            seed: 1,
        };
        // All the collisions a point processes, melting included (deterministic).
        let point = measure(&options, phi).expect("collides");
        let melting = (options.equilibrate * 4096.0 / 2.0) as u64;
        group.throughput(Throughput::Elements(point.collisions + melting));
        group.bench_with_input(BenchmarkId::from_parameter(phi), &phi, |b, &phi| {
            b.iter(|| measure(&options, phi).expect("collides"))
        });
    }
    group.finish();
}

/// What a sparse step costs under `exact`: 2000 circles of radius 0.001 in a unit box with walls
/// (area fraction 0.006) at speeds 0.005-0.015, the shape of `p2000.txt`, whose steps of 1/60 s
/// hold about two collisions each: what is left is the step's own work, per circle.
fn sparse_step(c: &mut Criterion) {
    let n = 2000;
    let config = CirclesConfig {
        arena: Arena::unit_square(Boundary::Walls),
        spawn: SpawnConfig {
            count: n,
            radius: (0.001, 0.001),
            speed: (0.005, 0.015),
            seed: 1,
            ..SpawnConfig::default()
        },
        solver: Solver::Exact,
        ..CirclesConfig::default()
    };
    bench_config(c, "step_sparse", BenchmarkId::new("exact", n), n, config);
}

/// What a pile costs once it rests: each pile scene under each solver, run until it has come to
/// rest (asleep, under `soft`, `swept` and `exact`; a heap that never rests, under the course's
/// solvers), then one step timed. `soft` is the scene's own setting (the Galton board's
/// `soft=8`). The run to rest happens the first time a benchmark is selected, so a filter that
/// leaves these out does not pay for it. What a pile costs while it forms is a run report's
/// `ms_per_step` (docs/piles.md).
fn piles(c: &mut Criterion) {
    let scenes = [
        ("column", 5.0),
        ("pyramid", 5.0),
        ("galton", 45.0),
        ("pile", 20.0),
    ];
    let solvers = [
        Solver::Soft(4),
        Solver::Substeps(4),
        Solver::Discrete,
        Solver::Swept,
        Solver::Exact,
    ];
    let mut group = c.benchmark_group("step_pile");
    group.sample_size(20);
    for (name, seconds) in scenes {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("assets/scenes")
            .join(format!("{name}.ron"));
        let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let n = scene.circles.len() + scene.spawn.count + scene.drop.map_or(0, |d| d.count);
        group.throughput(Throughput::Elements(n as u64));
        for solver in solvers {
            let mut config = scene.clone();
            if !matches!((solver, config.solver), (Solver::Soft(_), Solver::Soft(_))) {
                config.solver = solver;
            }
            let id = BenchmarkId::new(config.solver.to_string(), name);
            let mut app = None;
            group.bench_function(id, |b| {
                let app = app.get_or_insert_with(|| {
                    let mut app = headless_app(config.clone());
                    for _ in 0..(seconds * 60.0) as u32 {
                        app.update();
                    }
                    app
                });
                b.iter(|| app.update())
            });
        }
    }
    group.finish();
}

/// What a settled pile costs while it is awake, where the solve is all the work: the
/// 2000-circle pile under `soft` with sleeping off, run 12 s, then one step timed. A settled
/// pile still awake is what the peers' harness times in its settled window (no peer's pile of
/// 2000 sleeps there).
fn pile_awake(c: &mut Criterion) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes/pile.ron");
    let mut scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    scene.effects.sleep.enabled = false;
    let mut group = c.benchmark_group("step_pile_awake");
    group.sample_size(20);
    group.throughput(Throughput::Elements(scene.spawn.count as u64));
    let mut app = None;
    group.bench_function(BenchmarkId::new(scene.solver.to_string(), "pile"), |b| {
        let app = app.get_or_insert_with(|| {
            let mut app = headless_app(scene.clone());
            for _ in 0..12 * 60 {
                app.update();
            }
            app
        });
        b.iter(|| app.update())
    });
    group.finish();
}

criterion_group!(
    benches,
    solvers,
    effects,
    hit_messages,
    layers,
    segments,
    eos_point,
    sparse_step,
    piles,
    pile_awake
);
criterion_main!(benches);
