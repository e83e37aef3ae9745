//! Spatial query benchmarks through `SpatialQuery`, as a game calls it: on the benchmarks' gas
//! (area fraction 0.3, radii 0.5-1), 1000 queries per run of a registered system from points
//! spread over the arena (criterion's time per element is one query): a point query, a
//! circle overlap of radius 1, a ray cast and a circle cast of radius 0.5 in random
//! directions; and the index build that the first query after each step pays.
//!
//! `cargo bench --bench queries`; set `MC_BENCH_LARGE=1` to add N = 1M.

mod common;

use bevy::math::DVec2;
use bevy::prelude::*;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use moving_circles::prelude::*;
use moving_circles::tools::run::headless_app;

/// Queries per timed run.
const QUERIES: usize = 1000;

fn sizes() -> Vec<usize> {
    let mut n = vec![10_000];
    if common::large() {
        n.push(1_000_000);
    }
    n
}

/// Start points and unit directions spread over `arena` (a fixed low-discrepancy sequence).
fn asks(arena: &Arena) -> Vec<(DVec2, DVec2)> {
    (0..QUERIES)
        .map(|k| {
            let u = DVec2::new((k as f64 * 0.618_034) % 1.0, (k as f64 * 0.754_877_7) % 1.0);
            let angle = k as f64 * 2.399_963;
            (arena.min + u * arena.size(), DVec2::from_angle(angle))
        })
        .collect()
}

type Ask = fn(&SpatialQuery, DVec2, DVec2) -> usize;

fn queries(c: &mut Criterion) {
    let kinds: [(&str, Ask); 4] = [
        ("point", |q, p, _| q.point(p, &QueryFilter::default()).len()),
        ("overlap_circle", |q, p, _| {
            q.overlap_circle(p, 1.0, &QueryFilter::default()).len()
        }),
        ("ray_cast", |q, p, d| {
            q.ray_cast(p, d, f64::INFINITY, &QueryFilter::default())
                .is_some() as usize
        }),
        ("circle_cast", |q, p, d| {
            q.circle_cast(p, 0.5, d, f64::INFINITY, &QueryFilter::default())
                .is_some() as usize
        }),
    ];
    let mut group = c.benchmark_group("queries");
    group
        .sample_size(20)
        .throughput(Throughput::Elements(QUERIES as u64));
    for n in sizes() {
        let mut app = headless_app(common::gas(n, Solver::Discrete));
        app.update();
        let asks = asks(app.world().resource::<Arena>());
        for (name, ask) in kinds {
            let asks = asks.clone();
            let system = app.world_mut().register_system(move |q: SpatialQuery| {
                asks.iter().map(|&(p, d)| ask(&q, p, d)).sum::<usize>()
            });
            group.bench_function(BenchmarkId::new(name, n), |b| {
                b.iter(|| app.world_mut().run_system(system).unwrap())
            });
        }
        // The build the first query after a step pays, with one point query.
        let system = app.world_mut().register_system(|q: SpatialQuery| {
            q.refresh();
            q.point(DVec2::ZERO, &QueryFilter::default()).len()
        });
        group.throughput(Throughput::Elements(n as u64));
        group.bench_function(BenchmarkId::new("index_build", n), |b| {
            b.iter(|| app.world_mut().run_system(system).unwrap())
        });
        group.throughput(Throughput::Elements(QUERIES as u64));
    }
    group.finish();
}

criterion_group!(benches, queries);
criterion_main!(benches);
