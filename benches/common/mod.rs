//! What the benchmarks share: the gas they time, the same shape as the peer harness's scene.

use bevy::math::DVec2;
use moving_circles::prelude::*;

/// `n` circles (radii 0.5-1, speeds 2-10, seed 1) at area fraction 0.3 in a 16:9 box with walls,
/// under `solver`.
pub fn gas(n: usize, solver: Solver) -> CirclesConfig {
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

/// Whether `MC_BENCH_LARGE` asks for the large sizes too.
pub fn large() -> bool {
    std::env::var_os("MC_BENCH_LARGE").is_some()
}
