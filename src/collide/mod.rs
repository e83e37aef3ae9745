//! Circle-circle collisions for the `discrete` solver: [`CollidePlugin`] gathers the circles into
//! flat arrays, finds overlapping pairs with the [`broad_phase`] cell list, resolves each pair
//! with the [`contact`] kernel in a fixed order, and scatters the result back. On a periodic
//! arena pairs interact across the seam through the minimum image.

pub mod broad_phase;
pub mod contact;

use bevy::math::DVec2;
use bevy::prelude::*;

use crate::boundary::wrap_into;
use crate::components::{Mass, Position, Radius, Velocity};
use crate::config::{Arena, Boundary, Effects};
use crate::diagnostics::CollisionCounters;
use crate::effects::{Effect, schedule_effect};
use broad_phase::{CellList, Space, overlapping_pairs};
use contact::{Body, resolve_contact};

/// Resolves overlaps between circles: separation plus restitution impulse (`effects.restitution`),
/// in [`CircleSystems::Collide`](crate::CircleSystems). Leave it out (or disable it) and there is
/// no broad phase at all.
#[derive(Clone, Copy, Debug, Default)]
pub struct CollidePlugin;

impl Plugin for CollidePlugin {
    fn build(&self, app: &mut App) {
        schedule_effect(app, Effect::Collisions);
    }
}

/// The [`Space`] circles in `arena` collide in.
pub fn collision_space(arena: &Arena, boundary: Boundary) -> Space {
    match boundary {
        Boundary::Walls => Space::Open,
        Boundary::Periodic => Space::Periodic {
            min: arena.min,
            size: arena.size(),
        },
    }
}

/// Buffers reused from step to step so the hot path does not allocate.
#[derive(Default)]
pub struct ContactScratch {
    bodies: Vec<Body>,
    positions: Vec<DVec2>,
    radii: Vec<f64>,
    pairs: Vec<(u32, u32)>,
    cells: CellList,
}

impl ContactScratch {
    /// The circles the next [`resolve_all_contacts`] works on (fill it first).
    pub fn bodies_mut(&mut self) -> &mut Vec<Body> {
        &mut self.bodies
    }
}

/// What one collision pass found and did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PassStats {
    /// Pairs that were approaching and got an impulse.
    pub collisions: u64,
    /// Overlapping pairs found.
    pub contacts: u64,
    /// Deepest overlap, as a fraction of the smaller radius.
    pub max_penetration: f64,
    /// Sum of the overlaps (fractions of the smaller radius), for the mean.
    pub penetration_sum: f64,
    /// `Σ (r_a + r_b) · j` over collisions: the collisional virial.
    pub virial: f64,
}

/// Finds and resolves all overlapping pairs among `bodies` (Gauss-Seidel: each pair sees the
/// corrections of the pairs before it). The kernel of [`collide_circles`], usable without an App.
pub fn resolve_all_contacts(
    scratch: &mut ContactScratch,
    space: Space,
    restitution: f64,
) -> PassStats {
    let ContactScratch {
        bodies,
        positions,
        radii,
        pairs,
        cells,
    } = scratch;
    positions.clear();
    positions.extend(bodies.iter().map(|b| b.position));
    radii.clear();
    radii.extend(bodies.iter().map(|b| b.radius));
    pairs.clear();
    overlapping_pairs(cells, space, positions, radii, pairs);

    let mut stats = PassStats::default();
    for &(i, j) in pairs.iter() {
        let [a, b] = bodies
            .get_disjoint_mut([i as usize, j as usize])
            .expect("broad phase yields distinct indices");
        // Work on the image of `b` nearest to `a`; the shift is undone afterwards.
        let shift = (b.position - a.position) - space.offset(a.position, b.position);
        b.position -= shift;
        let outcome = resolve_contact(a, b, restitution);
        b.position += shift;
        stats.contacts += u64::from(outcome.penetration > 0.0);
        stats.max_penetration = stats.max_penetration.max(outcome.penetration);
        stats.penetration_sum += outcome.penetration;
        if outcome.impulse > 0.0 {
            stats.collisions += 1;
            stats.virial += (a.radius + b.radius) * outcome.impulse;
        }
    }
    stats
}

/// Gathers the circles, resolves their contacts with [`resolve_all_contacts`] and writes back
/// what changed.
pub fn collide_circles(
    arena: Res<Arena>,
    effects: Res<Effects>,
    mut counters: ResMut<CollisionCounters>,
    mut scratch: Local<ContactScratch>,
    mut circles: Query<(&mut Position, &mut Velocity, &Radius, &Mass)>,
) {
    let scratch = &mut *scratch;
    scratch.bodies.clear();
    scratch
        .bodies
        .extend(circles.iter().map(|(p, v, r, m)| Body {
            position: p.0,
            velocity: v.0,
            radius: r.0,
            inv_mass: m.inverse(),
        }));
    let space = collision_space(&arena, effects.boundary);
    let stats = resolve_all_contacts(scratch, space, effects.restitution);
    counters.record_pass(&stats);
    if stats.contacts == 0 {
        return;
    }
    let periodic = effects.boundary == Boundary::Periodic;
    for ((mut p, mut v, _, _), body) in circles.iter_mut().zip(&scratch.bodies) {
        let position = if periodic && !arena.contains(body.position) {
            wrap_into(body.position, &arena)
        } else {
            body.position
        };
        if p.0 != position {
            p.0 = position;
        }
        if v.0 != body.velocity {
            v.0 = body.velocity;
        }
    }
}
