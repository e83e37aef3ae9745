//! One contact pass of the discrete solvers, without an App: every overlapping pair found by
//! the broad phase is resolved with [`resolve_contact`] in a fixed order (Gauss-Seidel: each
//! pair sees the corrections of the pairs before it). Also [`separate_overlaps`], the same pass
//! with positions only, which scene loading uses to push explicit circles apart.

use bevy::math::DVec2;

use crate::base::arena::Arena;
use crate::base::circle::CircleState;
use crate::base::collision_layers::{CollisionLayers, pair_meets};
use crate::base::hits::{CircleHit, HitLog};
use crate::collision::broad_phase::{
    CellList, needs_levels, overlapping_pairs, pairs_in_cell_order, radius_range,
};
use crate::collision::contact::{combine_restitution, resolve_contact, work_by_immovable};
use crate::step::bodies::BodyStore;
use crate::step::boundary::put_back_inside;

/// The circles of one collision pass (the step's body store), and buffers reused from pass to
/// pass so the hot path does not allocate: centres and radii together (what the broad phase
/// reads) and in cell order, and the pairs.
#[derive(Default)]
pub struct ContactScratch {
    pub(crate) bodies: BodyStore,
    /// Centres and radii, what the broad phase reads.
    discs: Vec<(DVec2, f64)>,
    /// `discs` in cell order, while contacts are resolved.
    sorted: Vec<(DVec2, f64)>,
    /// `0, 1, 2, …`: the order of the multi-level path, which resolves in input order.
    identity: Vec<u32>,
    pairs: Vec<(u32, u32)>,
    cells: CellList,
}

impl ContactScratch {
    /// Forgets the circles of the last pass.
    pub fn clear(&mut self) {
        self.bodies.clear();
    }

    /// Adds a circle to the next [`resolve_all_contacts`].
    #[inline]
    pub fn push(&mut self, position: DVec2, velocity: DVec2, radius: f64, mass: f64) {
        self.bodies.push(position, velocity, radius, mass);
    }

    /// Gives the circle pushed last its own restitution. Either every circle gets one (pushed
    /// right after it) or none does; a pair then bounces with `combine_restitution` of theirs.
    #[inline]
    pub fn push_restitution(&mut self, restitution: f64) {
        self.bodies.restitution.push(restitution);
    }

    /// Gives the circle pushed last its layers. Either every circle gets them (pushed right
    /// after it) or none does (every pair meets); a pair that does not meet is left alone.
    #[inline]
    pub fn push_layers(&mut self, layers: CollisionLayers) {
        self.bodies.layers.push(layers);
    }

    /// Centre of circle `i` now.
    pub fn position(&self, i: usize) -> DVec2 {
        self.bodies.position[i]
    }

    /// Velocity of circle `i` now.
    pub fn velocity(&self, i: usize) -> DVec2 {
        self.bodies.velocity[i]
    }
}

/// What one collision pass found and did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PassStats {
    /// Pairs that were approaching and got an impulse.
    pub collisions: u64,
    /// Overlapping pairs found.
    pub contacts: u64,
    /// `Σ (r_a + r_b) · j` over collisions: the collisional virial.
    pub virial: f64,
    /// Kinetic energy immovable circles gave movable ones ([`work_by_immovable`]).
    pub immovable_work: f64,
    /// Momentum immovable circles gave movable ones.
    pub immovable_impulse: DVec2,
}

/// Finds and resolves all overlapping pairs among the circles in `scratch`, in the broad
/// phase's scan order, with `restitution` (or the circles' own, if they have theirs), leaving
/// out pairs whose layers do not meet. Each
/// collision is recorded in `hits` if given (circle indices in push order, time 0).
///
/// Circles of similar size are found in cell order (`pairs_in_cell_order`) and their centres
/// are corrected in that order, on nearby memory; radii spanning decades go through the
/// multi-level broad phase in input order.
pub fn resolve_all_contacts(
    scratch: &mut ContactScratch,
    arena: &Arena,
    restitution: f64,
    mut hits: Option<&mut HitLog>,
) -> PassStats {
    let ContactScratch {
        bodies,
        discs,
        sorted,
        identity,
        pairs,
        cells,
    } = scratch;
    pairs.clear();
    discs.clear();
    discs.extend(
        bodies
            .position
            .iter()
            .zip(&bodies.radius)
            .map(|(&p, &r)| (p, r)),
    );
    let layers = &bodies.layers;
    let radii = radius_range(discs);
    let order: &[u32] = if needs_levels(radii) {
        overlapping_pairs(cells, arena, discs, pairs);
        sorted.clone_from(discs);
        identity.clear();
        identity.extend(0..discs.len() as u32);
        identity
    } else {
        pairs_in_cell_order(cells, arena, discs, radii.1, sorted, pairs);
        cells.order()
    };
    if !layers.is_empty() {
        pairs.retain(|&(k, l)| {
            pair_meets(
                layers,
                order[k as usize] as usize,
                order[l as usize] as usize,
            )
        });
    }
    let mut stats = PassStats::default();
    let circle = |(position, radius): (DVec2, f64), velocity, mass| {
        CircleState::new(position, velocity, radius).with_mass(mass)
    };
    for &(k, l) in pairs.iter() {
        let (k, l) = (k as usize, l as usize);
        let (i, j) = (order[k] as usize, order[l] as usize);
        let mut a = circle(sorted[k], bodies.velocity[i], bodies.moving_mass(i));
        // Work on the image of `b` nearest to `a`.
        let image = a.position + arena.offset(a.position, sorted[l].0);
        let shift = sorted[l].0 - image;
        let mut b = circle(
            (image, sorted[l].1),
            bodies.velocity[j],
            bodies.moving_mass(j),
        );
        let e = match &bodies.restitution[..] {
            [] => restitution,
            own => combine_restitution(own[i], own[j]),
        };
        let (va, vb) = (a.velocity, b.velocity);
        let outcome = resolve_contact(&mut a, &mut b, e);
        (sorted[k].0, bodies.velocity[i]) = (a.position, a.velocity);
        (sorted[l].0, bodies.velocity[j]) = (b.position + shift, b.velocity);
        stats.contacts += u64::from(outcome.penetration > 0.0);
        if outcome.impulse > 0.0 {
            stats.collisions += 1;
            stats.virial += (a.radius + b.radius) * outcome.impulse;
            let inverse = (a.inv_mass(), b.inv_mass());
            if inverse.0 == 0.0 || inverse.1 == 0.0 {
                let (work, impulse) =
                    work_by_immovable(inverse, (va, a.velocity), (vb, b.velocity));
                stats.immovable_work += work;
                stats.immovable_impulse += impulse;
            }
            if let Some(log) = hits.as_deref_mut() {
                log.circles.push(CircleHit {
                    a: i as u32,
                    b: j as u32,
                    point: a.position + outcome.normal * a.radius,
                    normal: outcome.normal,
                    impulse: outcome.impulse,
                    normal_speed: outcome.normal_speed,
                    time: 0.0,
                });
            }
        }
    }
    // Only circles in a pair can have moved. Separation may push a circle deep into a wall;
    // one pushed so far that its centre left the arena is put back (the boundary's rule for a
    // circle past a wall, position only), so a step never ends with a centre outside.
    for &(k, l) in pairs.iter() {
        for k in [k as usize, l as usize] {
            let (position, radius) = &mut sorted[k];
            if arena.has_walls() && !arena.contains(*position) {
                put_back_inside(position, *radius, arena);
            }
            bodies.position[order[k] as usize] = *position;
        }
    }
    stats
}

/// Pushes overlapping circles apart (positions only, split by inverse mass, kept inside the
/// arena), for at most a bounded number of sweeps; whatever still overlaps is for the caller's
/// overlap check to report. (Scene files ask for it: feature `tools`.)
#[cfg(feature = "tools")]
pub fn separate_overlaps(circles: &mut [CircleState], arena: &Arena) {
    let mut scratch = ContactScratch::default();
    for _ in 0..1000 {
        scratch.clear();
        for c in circles.iter() {
            // No velocities: no impulses, only positions move.
            scratch.push(c.position, DVec2::ZERO, c.radius, c.mass);
        }
        let stats = resolve_all_contacts(&mut scratch, arena, 1.0, None);
        for (i, c) in circles.iter_mut().enumerate() {
            let mut p = scratch.position(i);
            if arena.is_periodic() {
                p = arena.wrap(p);
            } else if arena.has_walls() {
                put_back_inside(&mut p, c.radius, arena);
            }
            c.position = p;
        }
        if stats.contacts == 0 {
            break;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::arena::Boundary;

    #[test]
    fn separation_never_pushes_a_centre_out_of_the_arena() {
        // A light circle on the floor under a heavy one sunk deep into it: split by inverse
        // mass, nearly all of the 1.9 r of overlap moves the light one, 0.9 r past the floor.
        let arena = Arena::unit_square(Boundary::Walls);
        let r = 0.1;
        let mut scratch = ContactScratch::default();
        scratch.push(DVec2::new(0.5, r), DVec2::ZERO, r, 1.0);
        scratch.push(DVec2::new(0.5, 1.1 * r), DVec2::new(0.0, -1.0), r, 1e6);
        resolve_all_contacts(&mut scratch, &arena, 1.0, None);
        for i in 0..2 {
            assert!(
                arena.contains(scratch.position(i)),
                "circle {i} at {}",
                scratch.position(i)
            );
        }
    }
}
