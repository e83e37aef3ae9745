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
use broad_phase::{
    CellList, Disc, Space, needs_levels, pairs_among, pairs_in_cell_order, radius_range,
};
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

/// The circles of one collision pass, and buffers reused from pass to pass so the hot path
/// does not allocate. Centres and radii sit together (what the broad phase reads); velocities
/// and inverse masses apart (read only for the pairs that touch).
#[derive(Default)]
pub struct ContactScratch {
    discs: Vec<Disc>,
    velocities: Vec<DVec2>,
    inv_masses: Vec<f64>,
    /// `discs` in cell order, while contacts are resolved.
    sorted: Vec<Disc>,
    /// `0, 1, 2, …`: the order of the multi-level path, which resolves in input order.
    identity: Vec<u32>,
    pairs: Vec<(u32, u32)>,
    cells: CellList,
}

impl ContactScratch {
    /// Forgets the circles of the last pass.
    pub fn clear(&mut self) {
        self.discs.clear();
        self.velocities.clear();
        self.inv_masses.clear();
    }

    /// Adds a circle to the next [`resolve_all_contacts`].
    #[inline]
    pub fn push(&mut self, body: Body) {
        self.discs.push((body.position, body.radius));
        self.velocities.push(body.velocity);
        self.inv_masses.push(body.inv_mass);
    }

    /// Circle `i` as it is now.
    pub fn body(&self, i: usize) -> Body {
        Body {
            position: self.discs[i].0,
            velocity: self.velocities[i],
            radius: self.discs[i].1,
            inv_mass: self.inv_masses[i],
        }
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

/// Finds and resolves all overlapping pairs among the circles in `scratch` (Gauss-Seidel: each
/// pair sees the corrections of the pairs before it, in the broad phase's scan order). The
/// kernel of [`collide_circles`], usable without an App.
///
/// Circles of similar size are found in cell order ([`pairs_in_cell_order`]) and their centres
/// are corrected in that order, on nearby memory; radii spanning decades go through the
/// multi-level broad phase in input order.
pub fn resolve_all_contacts(
    scratch: &mut ContactScratch,
    space: Space,
    restitution: f64,
) -> PassStats {
    let ContactScratch {
        discs,
        velocities,
        inv_masses,
        sorted,
        identity,
        pairs,
        cells,
    } = scratch;
    pairs.clear();
    let radii = radius_range(discs);
    let order: &[u32] = if needs_levels(radii) {
        pairs_among(cells, space, discs, pairs);
        sorted.clone_from(discs);
        identity.clear();
        identity.extend(0..discs.len() as u32);
        identity
    } else {
        pairs_in_cell_order(cells, space, discs, radii.1, sorted, pairs);
        cells.order()
    };
    let mut stats = PassStats::default();
    for &(k, l) in pairs.iter() {
        let (k, l) = (k as usize, l as usize);
        let (i, j) = (order[k] as usize, order[l] as usize);
        let mut a = Body {
            position: sorted[k].0,
            velocity: velocities[i],
            radius: sorted[k].1,
            inv_mass: inv_masses[i],
        };
        // Work on the image of `b` nearest to `a`.
        let image = a.position + space.offset(a.position, sorted[l].0);
        let shift = sorted[l].0 - image;
        let mut b = Body {
            position: image,
            velocity: velocities[j],
            radius: sorted[l].1,
            inv_mass: inv_masses[j],
        };
        let outcome = resolve_contact(&mut a, &mut b, restitution);
        (sorted[k].0, velocities[i]) = (a.position, a.velocity);
        (sorted[l].0, velocities[j]) = (b.position + shift, b.velocity);
        stats.contacts += u64::from(outcome.penetration > 0.0);
        stats.max_penetration = stats.max_penetration.max(outcome.penetration);
        stats.penetration_sum += outcome.penetration;
        if outcome.impulse > 0.0 {
            stats.collisions += 1;
            stats.virial += (a.radius + b.radius) * outcome.impulse;
        }
    }
    // Only circles in a pair can have moved.
    for &(k, l) in pairs.iter() {
        for k in [k as usize, l as usize] {
            discs[order[k] as usize].0 = sorted[k].0;
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
    scratch.clear();
    for (p, v, r, m) in &circles {
        scratch.push(Body {
            position: p.0,
            velocity: v.0,
            radius: r.0,
            inv_mass: m.inverse(),
        });
    }
    let space = collision_space(&arena, effects.boundary);
    let stats = resolve_all_contacts(&mut scratch, space, effects.restitution);
    counters.record_pass(&stats);
    if stats.contacts == 0 {
        return;
    }
    let periodic = effects.boundary == Boundary::Periodic;
    for (i, (mut p, mut v, _, _)) in circles.iter_mut().enumerate() {
        let body = scratch.body(i);
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
