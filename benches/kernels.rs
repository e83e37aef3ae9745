//! Kernel benchmarks, no App: broad phase, one discrete contact pass, spawn placement, and the
//! event engine's events per second (`exact`), on gases at area fraction 0.3.
//!
//! `cargo bench --bench kernels`; set `MC_BENCH_LARGE=1` to add N = 1M.

use std::hint::black_box;

use bevy::math::DVec2;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use moving_circles::collide::broad_phase::{CellList, Space, overlapping_pairs};
use moving_circles::collide::contact::Body;
use moving_circles::collide::{ContactScratch, resolve_all_contacts};
use moving_circles::config::{Arena, SpawnConfig};
use moving_circles::exact::engine::{Bounds, Circle, EventEngine};
use moving_circles::spawn::{CircleInit, place_circles};

fn sizes() -> Vec<usize> {
    let mut n = vec![1_000, 10_000, 100_000];
    if std::env::var_os("MC_BENCH_LARGE").is_some() {
        n.push(1_000_000);
    }
    n
}

/// A gas of `n` circles (radii 0.5-1, speeds 2-10) at area fraction 0.3 in a 16:9 box, the
/// same shape as the peer harness's scene.
pub fn gas(n: usize) -> (Arena, Vec<CircleInit>) {
    let spawn = SpawnConfig {
        count: n,
        radius: (0.5, 1.0),
        speed: (2.0, 10.0),
        seed: 1,
        ..SpawnConfig::default()
    };
    let mean_area = std::f64::consts::PI * (0.25 + 0.5 + 1.0) / 3.0;
    let area = n as f64 * mean_area / 0.3;
    let arena = Arena::centered(DVec2::new(
        (area * 16.0 / 9.0).sqrt(),
        (area * 9.0 / 16.0).sqrt(),
    ));
    let circles = place_circles(&arena, &spawn, &[]).expect("valid");
    (arena, circles)
}

fn broad_phase(c: &mut Criterion) {
    let mut group = c.benchmark_group("broad_phase");
    group.sample_size(20);
    for n in sizes() {
        let (_, circles) = gas(n);
        let positions: Vec<DVec2> = circles.iter().map(|c| c.position).collect();
        let radii: Vec<f64> = circles.iter().map(|c| c.radius).collect();
        let mut cells = CellList::default();
        let mut pairs = Vec::new();
        group.throughput(Throughput::Elements(n as u64));
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                pairs.clear();
                overlapping_pairs(
                    &mut cells,
                    Space::Open,
                    black_box(&positions),
                    &radii,
                    &mut pairs,
                );
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
        let (_, circles) = gas(n);
        // Move every circle one step of 1/60 s so there are overlaps to resolve.
        let bodies: Vec<Body> = circles
            .iter()
            .map(|c| Body {
                position: c.position + c.velocity / 60.0,
                velocity: c.velocity,
                radius: c.radius,
                inv_mass: 1.0 / c.mass,
            })
            .collect();
        let mut scratch = ContactScratch::default();
        group.throughput(Throughput::Elements(n as u64));
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                scratch.clear();
                for &body in &bodies {
                    scratch.push(body);
                }
                black_box(resolve_all_contacts(&mut scratch, Space::Open, 1.0))
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

fn exact_events(c: &mut Criterion) {
    let mut group = c.benchmark_group("exact_events");
    group.sample_size(10);
    for n in [1_000, 10_000] {
        let (arena, circles) = gas(n);
        let bodies: Vec<Circle> = circles
            .iter()
            .map(|c| Circle {
                position: c.position,
                velocity: c.velocity,
                radius: c.radius,
                inv_mass: 1.0 / c.mass,
            })
            .collect();
        let bounds = Bounds::Walls {
            min: arena.min,
            max: arena.max,
        };
        let mut engine = EventEngine::new(&bodies, bounds, 1.0, 1.0);
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

criterion_group!(benches, broad_phase, contact_pass, spawn, exact_events);
criterion_main!(benches);
