//! Whole-App benchmarks: one `app.update()` (exactly one fixed step) of a headless app, after
//! `finish()`, spawning and one warm-up step. Per solver on gases of growing N, and the price of
//! effects: a no-collision scene against the same scene with collisions and against bare
//! integration.
//!
//! `cargo bench --bench step`; set `MC_BENCH_LARGE=1` to add N = 100k for every solver and
//! N = 1M for `discrete`.

use bevy::math::DVec2;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use moving_circles::config::{Arena, CirclesConfig, Effects, SpawnConfig};
use moving_circles::prelude::{Boundary, Solver};
use moving_circles::run::headless_app;

fn gas_config(n: usize, solver: Solver) -> CirclesConfig {
    let mean_area = std::f64::consts::PI * (0.25 + 0.5 + 1.0) / 3.0;
    let area = n as f64 * mean_area / 0.3;
    CirclesConfig {
        arena: Arena::centered(DVec2::new(
            (area * 16.0 / 9.0).sqrt(),
            (area * 9.0 / 16.0).sqrt(),
        )),
        spawn: SpawnConfig {
            count: n,
            radius: (0.5, 1.0),
            speed: (2.0, 10.0),
            seed: 1,
            ..SpawnConfig::default()
        },
        solver,
        ..CirclesConfig::default()
    }
}

fn bench_config(c: &mut Criterion, group: &str, id: BenchmarkId, n: usize, config: CirclesConfig) {
    let mut app = headless_app(config);
    app.update(); // warm-up step
    let mut group = c.benchmark_group(group);
    group
        .sample_size(15)
        .throughput(Throughput::Elements(n as u64));
    group.bench_function(id, |b| b.iter(|| app.update()));
    group.finish();
}

fn solvers(c: &mut Criterion) {
    let large = std::env::var_os("MC_BENCH_LARGE").is_some();
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
            bench_config(c, "step_gas", id, n, gas_config(n, solver));
        }
    }
    if large {
        let n = 1_000_000;
        let id = BenchmarkId::new(Solver::Discrete.to_string(), n);
        bench_config(c, "step_gas", id, n, gas_config(n, Solver::Discrete));
    }
}

/// What an effect costs: the same 10k circles with walls only (the `drift` kind of scene),
/// with collisions added, and periodic (wrap only).
fn effects(c: &mut Criterion) {
    let n = 10_000;
    let variants = [
        (
            "walls_only",
            Effects {
                collisions: false,
                ..Effects::default()
            },
        ),
        (
            "periodic_only",
            Effects {
                collisions: false,
                boundary: Boundary::Periodic,
                ..Effects::default()
            },
        ),
        ("walls_and_collisions", Effects::default()),
    ];
    for (name, effects) in variants {
        let config = CirclesConfig {
            effects,
            ..gas_config(n, Solver::Discrete)
        };
        bench_config(c, "step_effects", BenchmarkId::new(name, n), n, config);
    }
}

criterion_group!(benches, solvers, effects);
criterion_main!(benches);
