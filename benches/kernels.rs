//! Kernel benchmarks, no App: broad phase, one discrete contact pass, spawn placement (random
//! and lattice), and the event engine's events per second (`exact`), on gases at area fraction
//! 0.3; and its pair collisions per second from dilute to dense (`exact_density`).
//!
//! `cargo bench --bench kernels`; set `MC_BENCH_LARGE=1` to add N = 1M.

mod common;

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use moving_circles::base::circle::{CircleState, discs};
use moving_circles::game::spawn::place_circles;
use moving_circles::kernels::EventEngine;
use moving_circles::kernels::{CellList, overlapping_pairs};
use moving_circles::kernels::{ContactScratch, resolve_all_contacts};
use moving_circles::prelude::*;

fn sizes() -> Vec<usize> {
    let mut n = vec![1_000, 10_000, 100_000];
    if common::large() {
        n.push(1_000_000);
    }
    n
}

/// The placed circles of [`common::gas`] and its arena.
fn gas(n: usize) -> (Arena, Vec<CircleState>) {
    let config = common::gas(n, Solver::Discrete);
    let circles = place_circles(&config.arena, &config.spawn, &[], &[]).expect("valid");
    (config.arena, circles)
}

fn broad_phase(c: &mut Criterion) {
    let mut group = c.benchmark_group("broad_phase");
    group.sample_size(20);
    for n in sizes() {
        let (arena, circles) = gas(n);
        let discs = discs(&circles);
        let mut cells = CellList::default();
        let mut pairs = Vec::new();
        group.throughput(Throughput::Elements(n as u64));
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                pairs.clear();
                overlapping_pairs(&mut cells, &arena, black_box(&discs), &mut pairs);
                black_box(pairs.len())
            })
        });
    }
    group.finish();
}

fn contact_pass(c: &mut Criterion) {
    let mut group = c.benchmark_group("discrete_contact_pass");
    group.sample_size(20);
    for n in sizes() {
        let (arena, mut circles) = gas(n);
        // Move every circle one step of 1/60 s so there are overlaps to resolve.
        for c in &mut circles {
            c.position += c.velocity / 60.0;
        }
        let mut scratch = ContactScratch::default();
        group.throughput(Throughput::Elements(n as u64));
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                scratch.clear();
                for c in &circles {
                    scratch.push(c.position, c.velocity, c.radius, c.mass);
                }
                black_box(resolve_all_contacts(&mut scratch, &arena, 1.0, None))
            })
        });
    }
    group.finish();
}

fn spawn(c: &mut Criterion) {
    let mut group = c.benchmark_group("spawn");
    group.sample_size(10);
    for n in sizes() {
        group.throughput(Throughput::Elements(n as u64));
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, &n| {
            b.iter(|| black_box(gas(n).1.len()))
        });
    }
    group.finish();
}

fn spawn_lattice(c: &mut Criterion) {
    let mut group = c.benchmark_group("spawn_lattice");
    group.sample_size(10);
    for n in sizes() {
        let config = lattice(n, 0.85);
        group.throughput(Throughput::Elements(n as u64));
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| black_box(place_circles(&config.arena, &config.spawn, &[], &[])))
        });
    }
    group.finish();
}

/// A `pack` placement of 1024 and 4096 equal circles to area fraction 0.85 in a periodic unit
/// box: random spots at 0.25, then the compression under the event engine.
fn spawn_pack(c: &mut Criterion) {
    let mut group = c.benchmark_group("spawn_pack");
    group.sample_size(10);
    for n in [1024, 4096] {
        let mut config = lattice(n, 0.85);
        config.spawn.placement = Placement::Pack;
        group.throughput(Throughput::Elements(n as u64));
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| black_box(place_circles(&config.arena, &config.spawn, &[], &[])))
        });
    }
    group.finish();
}

/// `n` equal circles on a lattice at area fraction `fraction` in a periodic unit box.
fn lattice(n: usize, fraction: f64) -> CirclesConfig {
    let radius = (fraction / (n as f64 * std::f64::consts::PI)).sqrt();
    CirclesConfig {
        arena: Arena::unit_square(Boundary::Periodic),
        spawn: SpawnConfig {
            count: n,
            radius: (radius, radius),
            speed: (1.0, 1.0),
            placement: Placement::Lattice,
            ..SpawnConfig::default()
        },
        ..CirclesConfig::default()
    }
}

/// Pair collisions per second of the event engine on 4096 equal circles in a periodic box,
/// melted from a lattice (100 collisions per circle first), at area fractions from dilute to
/// dense. Each iteration advances a fixed simulated time that holds about 20 000 collisions in
/// the melted state; the throughput is the count measured over one such interval beforehand.
fn exact_density(c: &mut Criterion) {
    let mut group = c.benchmark_group("exact_density");
    group.sample_size(10);
    for fraction in [0.05, 0.3, 0.7] {
        let config = lattice(4096, fraction);
        let circles = place_circles(&config.arena, &config.spawn, &[], &[]).expect("fits");
        let mut engine = EventEngine::new(&circles, &config.arena, &[], 1.0, 1.0);
        let collisions = |engine: &EventEngine| engine.stats().pair_collisions;
        // Melt, and find how long 20 000 collisions take.
        let mut t = 0.0;
        while collisions(&engine) < 100 * 4096 {
            t += 0.01;
            engine.advance_to(t, u64::MAX).expect("no budget");
        }
        let (start, before) = (engine.now(), collisions(&engine));
        while collisions(&engine) - before < 20_000 {
            t += 0.001;
            engine.advance_to(t, u64::MAX).expect("no budget");
        }
        let interval = engine.now() - start;
        let before = collisions(&engine);
        engine
            .advance_to(engine.now() + interval, u64::MAX)
            .expect("no budget");
        group.throughput(Throughput::Elements(collisions(&engine) - before));
        group.bench_with_input(BenchmarkId::from_parameter(fraction), &fraction, |b, _| {
            b.iter(|| black_box(engine.advance_to(engine.now() + interval, u64::MAX)))
        });
    }
    group.finish();
}

/// Pair collisions per second of the event engine on `wide_radii.ron` (20 000 circles of radii
/// 1e-4…1e-3 and two of 0.1 and 0.05, walls) against the same count of equal circles (radius
/// 5.5e-4) without the two: the large circles stay out of the cells, so the cost per collision
/// should be about the same. Each iteration runs until 5000 more pair collisions have happened
/// (in steps of 0.002 time units, its time scaled to exactly 5000), after one time unit of
/// warm-up, so that a collision rate that drifts as the gas relaxes does not skew the count.
fn exact_wide_radii(c: &mut Criterion) {
    let mut group = c.benchmark_group("exact_wide_radii");
    group.sample_size(10);
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/wide_radii.ron");
    let wide = Scene::load(std::path::Path::new(path)).expect("the scene loads");
    let mut uniform = wide.clone();
    uniform.circles.clear();
    uniform.spawn.radius = (5.5e-4, 5.5e-4);
    const BATCH: u64 = 5000;
    group.throughput(Throughput::Elements(BATCH));
    for (name, config) in [("uniform", uniform), ("wide", wide)] {
        let mut circles = config.circles.clone();
        let placed = place_circles(&config.arena, &config.spawn, &config.circles, &[]);
        circles.extend(placed.expect("fits"));
        let mut engine = EventEngine::new(&circles, &config.arena, &[], 1.0, 1.0);
        engine.advance_to(1.0, u64::MAX).expect("no budget");
        group.bench_function(name, |b| {
            b.iter_custom(|iterations| {
                let mut elapsed = std::time::Duration::ZERO;
                for _ in 0..iterations {
                    let before = engine.stats().pair_collisions;
                    let start = std::time::Instant::now();
                    while engine.stats().pair_collisions - before < BATCH {
                        let next = engine.now() + 0.002;
                        black_box(engine.advance_to(next, u64::MAX)).expect("no budget");
                    }
                    let done = engine.stats().pair_collisions - before;
                    elapsed += start.elapsed().mul_f64(BATCH as f64 / done as f64);
                }
                elapsed
            })
        });
    }
    group.finish();
}

fn exact_events(c: &mut Criterion) {
    let mut group = c.benchmark_group("exact_events");
    group.sample_size(10);
    for n in [1_000, 10_000] {
        let (arena, circles) = gas(n);
        let mut engine = EventEngine::new(&circles, &arena, &[], 1.0, 1.0);
        // Each iteration processes exactly this many valid events (collisions, wall hits and
        // cell crossings), so throughput is events per second.
        let batch = 10_000u64;
        group.throughput(Throughput::Elements(batch));
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| black_box(engine.advance_to(f64::MAX, batch)))
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    broad_phase,
    contact_pass,
    spawn,
    spawn_lattice,
    spawn_pack,
    exact_events,
    exact_density,
    exact_wide_radii
);
criterion_main!(benches);
