//! Circle-circle collisions for the `discrete` solver: [`CollidePlugin`] gathers the circles into
//! flat arrays, finds overlapping pairs with the [`broad_phase`] cell list, resolves each pair
//! with the [`contact`] kernel in a fixed order, and scatters the result back.

pub mod broad_phase;
pub mod contact;

use bevy::prelude::*;

use crate::components::{Mass, Position, Radius, Velocity};
use crate::diagnostics::CollisionCounters;
use crate::schedule::{CircleStep, CircleSystems};
use broad_phase::{CellList, overlapping_pairs};
use contact::{Body, resolve_contact};

/// Settings of circle-circle contact.
#[derive(Resource, Reflect, Clone, Copy, Debug, PartialEq)]
#[reflect(Resource, Debug)]
pub struct CollisionSettings {
    /// Coefficient of restitution: 1 is perfectly elastic, 0 perfectly inelastic.
    pub restitution: f32,
}

/// Resolves overlaps between circles: separation plus elastic impulse, in
/// [`CircleSystems::Collide`]. Leave it out (or disable it) and there is no broad phase at all.
#[derive(Clone, Copy, Debug)]
pub struct CollidePlugin {
    /// Coefficient of restitution between circles.
    pub restitution: f32,
}

impl Default for CollidePlugin {
    fn default() -> Self {
        Self { restitution: 1.0 }
    }
}

impl Plugin for CollidePlugin {
    fn build(&self, app: &mut App) {
        app.register_type::<CollisionSettings>()
            .insert_resource(CollisionSettings {
                restitution: self.restitution,
            })
            .add_systems(CircleStep, collide_circles.in_set(CircleSystems::Collide));
    }
}

/// Buffers reused from step to step so the hot path does not allocate.
#[derive(Default)]
pub struct ContactScratch {
    bodies: Vec<Body>,
    positions: Vec<Vec2>,
    radii: Vec<f32>,
    pairs: Vec<(u32, u32)>,
    cells: CellList,
}

/// Finds and resolves all overlapping pairs (Gauss-Seidel: each pair sees the corrections of the
/// pairs before it).
pub fn collide_circles(
    settings: Res<CollisionSettings>,
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
    scratch.positions.clear();
    scratch
        .positions
        .extend(scratch.bodies.iter().map(|b| b.position));
    scratch.radii.clear();
    scratch
        .radii
        .extend(scratch.bodies.iter().map(|b| b.radius));
    scratch.pairs.clear();
    overlapping_pairs(
        &mut scratch.cells,
        &scratch.positions,
        &scratch.radii,
        &mut scratch.pairs,
    );

    let mut max_penetration = 0.0f32;
    let mut impulses = 0u64;
    for &(i, j) in &scratch.pairs {
        let [a, b] = scratch
            .bodies
            .get_disjoint_mut([i as usize, j as usize])
            .expect("broad phase yields distinct indices");
        let outcome = resolve_contact(a, b, settings.restitution);
        max_penetration = max_penetration.max(outcome.penetration);
        impulses += u64::from(outcome.impulse);
    }
    counters.pair_collisions += impulses;
    counters.max_penetration = counters.max_penetration.max(max_penetration);

    if scratch.pairs.is_empty() {
        return;
    }
    for ((mut p, mut v, _, _), body) in circles.iter_mut().zip(&scratch.bodies) {
        if p.0 != body.position {
            p.0 = body.position;
        }
        if v.0 != body.velocity {
            v.0 = body.velocity;
        }
    }
}
