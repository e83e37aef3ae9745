//! What a `soft` step tells the world: [`SoftStats`] (collisions, wall hits, the virial, the
//! work of immovable circles) and the hits it records, counted from its contacts once they
//! are solved.

use bevy::math::DVec2;

use super::bodies::Bodies;
use super::contacts::{Constraint, Partner};
use crate::base::hits::{CircleHit, HitLog, WallHit};

/// The work immovable circles did on movable ones through their contacts' impulses, and the
/// momentum they gave them, added up over a step's passes.
#[derive(Default)]
pub struct Work {
    /// Work (N·m).
    pub energy: f64,
    /// Momentum.
    pub momentum: DVec2,
}

impl Work {
    /// Adds one contact's work and momentum.
    pub fn add(&mut self, (energy, momentum): (f64, DVec2)) {
        self.energy += energy;
        self.momentum += momentum;
    }
}

/// What one `soft` step did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SoftStats {
    /// Circle contacts that began to push this step: collisions.
    pub collisions: u64,
    /// `Σ (r_a + r_b) · j` over every impulse between circles (the virial, for the pressure).
    pub virial: f64,
    /// Work immovable circles did on movable ones: each push times the pusher's velocity along
    /// it (a static peg does none, a kinematic paddle what it injects).
    pub immovable_work: f64,
    /// Momentum immovable circles gave movable ones.
    pub immovable_impulse: DVec2,
    /// Wall contacts that began to push this step: wall hits.
    pub wall_hits: u64,
    /// Momentum the walls took up.
    pub wall_impulse: f64,
    /// Contacts solved (pairs and walls).
    pub contacts: usize,
}

impl SoftStats {
    pub(super) fn add(&mut self, other: &SoftStats) {
        self.collisions += other.collisions;
        self.virial += other.virial;
        self.immovable_work += other.immovable_work;
        self.immovable_impulse += other.immovable_impulse;
        self.wall_hits += other.wall_hits;
        self.wall_impulse += other.wall_impulse;
        self.contacts = self.contacts.max(other.contacts);
    }
}

/// Counts the step's collisions and wall hits (contacts that began to push), the virial and
/// the walls' momentum, and records the hits.
pub(super) fn count(
    bodies: &Bodies,
    (walls, pairs): (&[Constraint], &[Constraint]),
    dt: f64,
    stats: &mut SoftStats,
    mut hits: Option<&mut HitLog>,
) {
    for c in pairs {
        stats.virial += c.reach * c.total_impulse;
        if c.total_impulse > 0.0 && !c.was_touching {
            stats.collisions += 1;
            if let Some(log) = hits.as_deref_mut() {
                let a = c.a as usize;
                log.circles.push(CircleHit {
                    a: c.a,
                    b: c.b,
                    point: bodies.position[a] + c.normal * bodies.radius[a],
                    normal: c.normal,
                    impulse: c.total_impulse,
                    normal_speed: c.approach.max(-c.relative_velocity),
                    time: dt,
                });
            }
        }
    }
    for c in walls {
        stats.wall_impulse += c.total_impulse;
        if c.total_impulse > 0.0 && !c.was_touching {
            stats.wall_hits += 1;
            if let (Some(log), Partner::Wall(wall)) = (hits.as_deref_mut(), c.partner) {
                log.walls.push(WallHit {
                    circle: c.a,
                    wall,
                    point: c.anchor,
                    normal: c.normal,
                    impulse: c.total_impulse,
                    normal_speed: c.approach.max(-c.relative_velocity),
                    time: dt,
                    count: 1,
                });
            }
        }
    }
}
