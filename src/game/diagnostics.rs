//! What the simulation measures about itself after each fixed step, in
//! [`CircleSystems::Diagnostics`]: [`CircleDiagnostics`] (energy, momentum, drift since the
//! last reset) from plain [`Totals`], and [`Pressure`] from the collision counters their owners
//! keep (`PairCollisions` in `collide`, `WallCollisions` in `boundary`) and the schedule's
//! [`StepTotals`]. After a (re)spawn it takes the new baseline and zeroes those counters.

use bevy::math::DVec2;
use bevy::prelude::*;

use crate::base::arena::Arena;
use crate::base::circle::inertia;
use crate::base::components::{AngularVelocity, Inertia, Mass, Position, Radius, Velocity};
use crate::base::config::{DropConfig, Effects, SpawnConfig};
use crate::base::hits::PairCollisions;
use crate::game::spawn::{Dropped, SpawnReport, nth_drop};
use crate::step::boundary::WallCollisions;
use crate::step::schedule::{CircleSystems, StepTotals};

/// Pressure as the compressibility factor `z = P·A / (N·kT)`, with `kT` the mean kinetic energy
/// per circle (2D), measured two ways over the time since the last reset.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Pressure {
    /// From the collisional virial: `z = 1 + Σ σ·j / (2·T·N·kT)`. Works for walls and periodic
    /// boxes; 1 is an ideal gas.
    pub z_virial: Option<f64>,
    /// From the momentum the walls took up: `P = Σ m|Δv| / (T · perimeter)` (walls only).
    pub z_wall: Option<f64>,
}

impl Pressure {
    /// Pressure of `n` circles with total kinetic energy `kinetic_energy` in `arena`, from the
    /// counters over `elapsed`. `None` where it is undefined (no time, no circles, no motion,
    /// or no walls) or too large for an f64 (a gas that all but stopped after huge impulses).
    pub fn measure(
        elapsed: &StepTotals,
        pairs: &PairCollisions,
        walls: &WallCollisions,
        n: usize,
        kinetic_energy: f64,
        arena: &Arena,
    ) -> Self {
        let Some(z_virial) = Self::virial_z(elapsed, pairs, n, kinetic_energy) else {
            return Self::default();
        };
        let (t, n_kt) = (elapsed.sim_seconds, kinetic_energy);
        let size = arena.size();
        let area = size.x * size.y;
        let perimeter = 2.0 * (size.x + size.y);
        Self {
            z_virial: Some(z_virial),
            z_wall: arena
                .has_walls()
                .then(|| walls.impulse / (t * perimeter) * area / n_kt)
                .filter(|z| z.is_finite()),
        }
    }

    /// `z` from the collisional virial alone (see [`Pressure::z_virial`]), for any window of
    /// the counters: what a periodic box or a window of samples needs. `None` where it is
    /// undefined (no time, no circles, no motion) or too large for an f64.
    pub fn virial_z(
        elapsed: &StepTotals,
        pairs: &PairCollisions,
        n: usize,
        kinetic_energy: f64,
    ) -> Option<f64> {
        let t = elapsed.sim_seconds;
        let n_kt = kinetic_energy; // N·kT = total kinetic energy in 2D
        (t > 0.0 && n > 0 && n_kt > 0.0)
            .then(|| 1.0 + pairs.virial / (2.0 * t * n_kt))
            .filter(|z| z.is_finite())
    }
}

/// Conserved quantities of the whole system, measured after every fixed step.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct CircleDiagnostics {
    /// Number of circles.
    pub count: usize,
    /// Total kinetic energy `Σ ½ m |v|²` (f64 sum, so the measurement adds no drift).
    pub kinetic_energy: f64,
    /// Total mechanical energy: kinetic plus, under gravity, potential (see [`Totals`]).
    pub energy: f64,
    /// Mechanical energy right after the last (re)spawn.
    pub initial_energy: f64,
    /// Mechanical energy the circles dropped since then brought in as they entered.
    pub added_energy: f64,
    /// Centres outside the arena.
    pub escaped: usize,
    /// Total momentum `Σ m v`.
    pub momentum: DVec2,
    /// Whether any circle has a non-finite position or velocity.
    pub non_finite: usize,
    /// [`SpawnReport::generation`] the baseline belongs to.
    generation: u64,
}

impl CircleDiagnostics {
    /// Relative change of the mechanical energy since the last reset, counting what drops
    /// brought in: `(E - E0 - Ed) / |E0 + Ed|`, or the absolute change when `E0 + Ed` is zero or
    /// all but zero (so it is always finite).
    pub fn energy_drift(&self) -> f64 {
        relative_change(self.initial_energy + self.added_energy, self.energy)
    }
}

/// `(now - before) / |before|`, falling back to `now - before` when `before` is zero or so
/// small (a subnormal energy of circles all but at rest) that the ratio overflows.
pub fn relative_change(before: f64, now: f64) -> f64 {
    let ratio = (now - before) / before.abs();
    if before != 0.0 && ratio.is_finite() {
        ratio
    } else {
        now - before
    }
}

/// Totals over a set of circles, summed in f64.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Totals {
    /// Number of circles.
    pub count: usize,
    /// `Σ ½ m |v|²`.
    pub kinetic_energy: f64,
    /// `Σ ½ I ω²`: the energy of turning, each circle a uniform disc (`I = m r² / 2`).
    pub rotational_energy: f64,
    /// `Σ m g·(floor - x)`, measured from the arena's lowest corner along `g` (0 without
    /// gravity).
    pub potential_energy: f64,
    /// `Σ m v`.
    pub momentum: DVec2,
    /// Angular momentum about the origin: `Σ (m x × v + I ω)`.
    pub angular_momentum: f64,
    /// Circles with a non-finite position or velocity.
    pub non_finite: usize,
    /// Centres outside the arena.
    pub escaped: usize,
}

impl Totals {
    /// Measures circles given as `(position, velocity, mass, (angular velocity, moment of
    /// inertia))`. Immovable (infinite-mass) circles carry no energy or momentum.
    pub fn measure(
        circles: impl Iterator<Item = (DVec2, DVec2, f64, (f64, f64))>,
        arena: &Arena,
        gravity: Option<DVec2>,
    ) -> Self {
        let g = gravity.unwrap_or(DVec2::ZERO);
        // Potential energy is measured from the arena's lowest corner along g, so it is never
        // negative and a relative drift stays meaningful.
        let floor = DVec2::select(g.cmpgt(DVec2::ZERO), arena.max, arena.min);
        let mut totals = Self::default();
        for (p, v, m, (w, inertia)) in circles {
            totals.count += 1;
            if !(p.is_finite() && v.is_finite() && w.is_finite()) {
                totals.non_finite += 1;
                continue;
            }
            // An open arena has no edge to escape by.
            totals.escaped += usize::from(!arena.is_open() && !arena.contains(p));
            if !m.is_finite() {
                continue;
            }
            totals.kinetic_energy += 0.5 * m * v.length_squared();
            totals.potential_energy += m * g.dot(floor - p);
            totals.momentum += m * v;
            totals.angular_momentum += m * p.perp_dot(v);
            if w != 0.0 {
                totals.rotational_energy += 0.5 * inertia * w * w;
                totals.angular_momentum += inertia * w;
            }
        }
        totals
    }

    /// Kinetic (moving and turning) plus potential energy.
    pub fn energy(&self) -> f64 {
        self.kinetic_energy + self.rotational_energy + self.potential_energy
    }
}

/// Energy and momentum the drops numbered `drops` brought in as they entered, in `arena` under
/// `gravity` with the spawn rules' mass model: what a run's energy and momentum gained from
/// outside.
pub fn drops_brought(
    rules: &DropConfig,
    drops: std::ops::Range<usize>,
    (spawn, arena, gravity): (&SpawnConfig, &Arena, Option<DVec2>),
) -> Totals {
    let circles = drops.map(|k| {
        let c = nth_drop(rules, spawn, k);
        (c.position, c.velocity, c.mass, (0.0, 0.0))
    });
    Totals::measure(circles, arena, gravity)
}

/// Energy and momentum the circles dropped since the `from`-th brought in as they entered
/// (zero without drop rules).
pub fn dropped_totals(world: &World, from: usize) -> Totals {
    let rules = world.get_resource::<DropConfig>();
    let dropped = world.get_resource::<Dropped>().map_or(0, |d| d.count);
    let setting = (
        world.resource::<SpawnConfig>(),
        world.resource::<Arena>(),
        world.resource::<Effects>().gravity,
    );
    rules.map_or_else(Totals::default, |rules| {
        drops_brought(rules, from..dropped, setting)
    })
}

/// When [`CircleDiagnostics`] is measured. Measuring reads every circle, so a headless run that
/// takes its own totals (`run::advance`) turns it to [`Measuring::AfterSpawn`] while it steps:
/// its timed steps then pay for nothing nobody reads.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Measuring {
    /// After every fixed step: what the HUD, the panel and your own systems read.
    #[default]
    EveryStep,
    /// Only after a (re)spawn, for the new baseline.
    AfterSpawn,
}

/// Measures energy and momentum after every fixed step (unless [`Measuring`] says otherwise),
/// and takes the baseline after every (re)spawn.
#[derive(Clone, Copy, Debug, Default)]
pub struct DiagnosticsPlugin;

impl Plugin for DiagnosticsPlugin {
    fn build(&self, app: &mut App) {
        let measured = || (measure, take_baseline).chain();
        app.init_resource::<CircleDiagnostics>()
            .init_resource::<Measuring>()
            .init_resource::<PairCollisions>()
            .init_resource::<WallCollisions>()
            .add_systems(Startup, measured().after(CircleSystems::Spawn))
            .add_systems(
                PreUpdate,
                measured()
                    .after(CircleSystems::Spawn)
                    .run_if(resource_changed::<SpawnReport>),
            )
            .add_systems(
                FixedUpdate,
                measured()
                    .in_set(CircleSystems::Diagnostics)
                    .run_if(resource_equals(Measuring::EveryStep)),
            );
    }
}

/// What the diagnostics read of each circle.
type MeasuredCircles<'w, 's> = Query<
    'w,
    's,
    (
        &'static Position,
        &'static Velocity,
        &'static Mass,
        &'static Radius,
        Option<&'static AngularVelocity>,
        Option<&'static Inertia>,
    ),
>;

/// The drop rules and how far they got, where a scene has them.
type Drops<'w> = (
    Option<Res<'w, DropConfig>>,
    Option<Res<'w, Dropped>>,
    Option<Res<'w, SpawnConfig>>,
);

/// Updates [`CircleDiagnostics`] from the circles (and the drops so far).
fn measure(
    arena: Res<Arena>,
    effects: Res<Effects>,
    mut diagnostics: ResMut<CircleDiagnostics>,
    circles: MeasuredCircles,
    (rules, dropped, spawn): Drops,
) {
    let spin = |w: Option<&AngularVelocity>| w.map_or(0.0, |w| w.0);
    let totals = Totals::measure(
        circles.iter().map(|(p, v, m, r, w, own)| {
            let turning = (spin(w), inertia(own.map(|i| i.0), m.0, r.0));
            (p.0, v.0, m.0, turning)
        }),
        &arena,
        effects.gravity,
    );
    diagnostics.count = totals.count;
    diagnostics.kinetic_energy = totals.kinetic_energy;
    diagnostics.energy = totals.energy();
    diagnostics.added_energy = match (rules, dropped, spawn) {
        (Some(rules), Some(dropped), Some(spawn))
            if dropped.generation == diagnostics.generation =>
        {
            let setting = (spawn.as_ref(), arena.as_ref(), effects.gravity);
            drops_brought(&rules, 0..dropped.count, setting).energy()
        }
        _ => 0.0,
    };
    diagnostics.momentum = totals.momentum;
    diagnostics.non_finite = totals.non_finite;
    diagnostics.escaped = totals.escaped;
}

/// After a (re)spawn: the energy now is the new baseline, and every counter starts again.
fn take_baseline(
    report: Res<SpawnReport>,
    mut diagnostics: ResMut<CircleDiagnostics>,
    mut elapsed: ResMut<StepTotals>,
    mut pairs: ResMut<PairCollisions>,
    mut walls: ResMut<WallCollisions>,
) {
    if diagnostics.generation != report.generation {
        diagnostics.generation = report.generation;
        diagnostics.initial_energy = diagnostics.energy;
        *elapsed = StepTotals::default();
        *pairs = PairCollisions::default();
        *walls = WallCollisions::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::arena::Boundary;

    #[test]
    fn a_change_from_nothing_or_next_to_nothing_is_finite() {
        assert_eq!(relative_change(2.0, 3.0), 0.5);
        assert_eq!(relative_change(0.0, 3.0), 3.0);
        // From a subnormal energy the ratio would be infinite.
        assert_eq!(relative_change(1.5e-314, 1.0), 1.0 - 1.5e-314);
    }

    /// A gas that all but stopped (inelastic hits under a huge gravity) after large impulses:
    /// `z` overflows an f64 and is reported as undefined, not as infinity.
    #[test]
    fn a_pressure_too_large_for_an_f64_is_undefined() {
        let elapsed = StepTotals {
            steps: 4,
            sim_seconds: 0.0667,
        };
        let pairs = PairCollisions {
            count: 90,
            virial: 1e60,
            ..default()
        };
        let walls = WallCollisions {
            count: u64::MAX,
            impulse: 1e58,
        };
        let arena = Arena::centered(DVec2::splat(1e-3)).with_boundary(Boundary::Walls);
        let stopped = Pressure::measure(&elapsed, &pairs, &walls, 16, 1e-300, &arena);
        assert_eq!(stopped, Pressure::default());
        assert_eq!(Pressure::virial_z(&elapsed, &pairs, 16, 1e-300), None);

        let moving = Pressure::measure(&elapsed, &pairs, &walls, 16, 1e58, &arena);
        assert!(moving.z_virial.is_some_and(f64::is_finite));
        assert!(moving.z_wall.is_some_and(f64::is_finite));
    }
}
