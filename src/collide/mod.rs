//! Circle-circle collisions. [`CollidePlugin`] schedules the `discrete` solvers' collision
//! system when the scene calls for collisions: it gathers the circles into the [`pass`]'s flat
//! arrays, which finds overlapping pairs with the [`broad_phase`] and resolves each with the
//! [`contact`] kernel, and scatters the result back. On a periodic arena pairs interact across
//! the seam through the minimum image. Pair collisions are counted here ([`PairCollisions`]),
//! by whichever solver makes them; [`overlaps`] measures overlap in any state.

pub mod broad_phase;
pub mod contact;
pub mod overlaps;
pub mod pass;

use bevy::ecs::schedule::ScheduleLabel;
use bevy::prelude::*;

use crate::arena::Arena;
use crate::components::{Mass, Position, Radius, Velocity};
use crate::config::Effects;
use crate::effects::{Effect, register_effect};
use crate::schedule::{CircleStep, CircleSystems};
use pass::{ContactScratch, resolve_all_contacts};

/// Resolves overlaps between circles: separation plus restitution impulse (`effects.restitution`),
/// in [`CircleSystems::Collide`]. Without collisions in the scene (or with this plugin disabled)
/// there is no broad phase at all.
#[derive(Clone, Copy, Debug, Default)]
pub struct CollidePlugin;

impl Plugin for CollidePlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<PairCollisions>();
        register_effect(app, Effect::Collisions, &[CircleStep.intern()], || {
            collide_circles
                .in_set(CircleSystems::Collide)
                .into_configs()
        });
    }
}

/// Circle-circle collisions since the last (re)spawn, under any solver.
#[derive(
    Resource, Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize,
)]
pub struct PairCollisions {
    /// Impulses applied.
    pub count: u64,
    /// Collisional virial `Σ (r_a + r_b) · j` over those impulses (for the pressure).
    pub virial: f64,
}

/// Gathers the circles, resolves their contacts with [`resolve_all_contacts`] and writes back
/// what changed.
fn collide_circles(
    arena: Res<Arena>,
    effects: Res<Effects>,
    mut counted: ResMut<PairCollisions>,
    mut scratch: Local<ContactScratch>,
    mut circles: Query<(&mut Position, &mut Velocity, &Radius, &Mass)>,
) {
    scratch.clear();
    for (p, v, r, m) in &circles {
        scratch.push(p.0, v.0, r.0, m.0);
    }
    let stats = resolve_all_contacts(&mut scratch, &arena, effects.restitution);
    counted.count += stats.collisions;
    counted.virial += stats.virial;
    if stats.contacts == 0 {
        return;
    }
    for (i, (mut p, mut v, _, _)) in circles.iter_mut().enumerate() {
        let mut position = scratch.position(i);
        if arena.is_periodic() && !arena.contains(position) {
            position = arena.wrap(position);
        }
        if p.0 != position {
            p.0 = position;
        }
        let velocity = scratch.velocity(i);
        if v.0 != velocity {
            v.0 = velocity;
        }
    }
}
