//! The circles of a step as plain arrays: [`BodyStore`], gathered from the ECS in serial order
//! ([`BodyStore::gather`]) and written back ([`write_motion`]) in one place for every solver.
//! What a solver adds sits beside the store, in the solver's folder: the discrete pass's
//! cell-order buffers, `soft`'s inverse masses and spins, the event engine's rest.

use bevy::ecs::query::QueryItem;
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::base::arena::Arena;
use crate::base::collision_layers::{CircleFilters, CollisionLayers};
use crate::base::components::{Sleep, SolverCircles, SolverData};
use crate::base::order::CircleOrder;

/// The circles of one step, one array per field, in one order (serial order when gathered).
#[derive(Clone, Debug, Default)]
pub struct BodyStore {
    /// Each circle's entity; empty when the circles were pushed without an App.
    pub entity: Vec<Entity>,
    /// Centres.
    pub position: Vec<DVec2>,
    /// Velocities.
    pub velocity: Vec<DVec2>,
    /// Radii.
    pub radius: Vec<f64>,
    /// Masses (infinite for a static or kinematic circle).
    pub mass: Vec<f64>,
    /// Whether each circle sleeps: an immovable circle at rest to the time-stepped solvers
    /// until it is woken.
    pub asleep: Vec<bool>,
    /// Each circle's own restitution, or empty when every circle takes the scene's.
    pub restitution: Vec<f64>,
    /// Each circle's layers, or empty when every pair meets.
    pub layers: Vec<CollisionLayers>,
}

/// What [`BodyStore::gather`] takes besides the motion: own restitutions (with the scene's for
/// a circle without) if any circle has one, and the circles' layers.
pub(crate) struct GatherOwn<'a, 'w, 's> {
    /// `Some(scene's restitution)` when any circle has its own.
    pub restitution: Option<f64>,
    /// Each circle's layers.
    pub filters: &'a CircleFilters<'w, 's>,
}

impl BodyStore {
    /// Forgets every circle (keeping the buffers).
    pub fn clear(&mut self) {
        self.entity.clear();
        self.position.clear();
        self.velocity.clear();
        self.radius.clear();
        self.mass.clear();
        self.asleep.clear();
        self.restitution.clear();
        self.layers.clear();
    }

    /// Number of circles.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// Adds an awake circle (without an entity).
    #[inline]
    pub fn push(&mut self, position: DVec2, velocity: DVec2, radius: f64, mass: f64) {
        self.position.push(position);
        self.velocity.push(velocity);
        self.radius.push(radius);
        self.mass.push(mass);
        self.asleep.push(false);
    }

    /// Circle `i`'s mass as a time-stepped solver moves it: infinite while it sleeps.
    #[inline]
    pub fn moving_mass(&self, i: usize) -> f64 {
        if self.asleep[i] {
            f64::INFINITY
        } else {
            self.mass[i]
        }
    }

    /// Replaces the store with `circles` in `order`'s serial order, with their own restitutions
    /// and layers as `own` says; `beside` sees each circle's index and [`Sleep`], for what a
    /// solver keeps beside the store.
    pub fn gather(
        &mut self,
        order: &CircleOrder,
        circles: &SolverCircles,
        own: &GatherOwn,
        mut beside: impl FnMut(usize, &Sleep),
    ) {
        self.clear();
        order.each(circles, |i, (e, p, v, r, m, restitution, sleep)| {
            self.entity.push(e);
            self.position.push(p.0);
            self.velocity.push(v.0);
            self.radius.push(r.0);
            self.mass.push(m.0);
            self.asleep.push(sleep.asleep);
            if let Some(scene) = own.restitution {
                self.restitution
                    .push(restitution.map_or(scene, |own| own.0));
            }
            beside(i, sleep);
        });
        if own.filters.any() {
            let filters = own.filters;
            self.layers
                .extend(self.entity.iter().map(|&e| filters.of(e)));
        }
    }

    /// Writes the store's positions and velocities back to the circles it was gathered from
    /// (see [`write_motion`]), wrapping a centre that left a periodic `arena` back in.
    pub fn write_back(&self, order: &CircleOrder, circles: &mut SolverCircles, arena: &Arena) {
        let periodic = arena.is_periodic();
        write_motion(order, None, circles, |i| {
            let mut position = self.position[i];
            if periodic && !arena.contains(position) {
                position = arena.wrap(position);
            }
            (position, self.velocity[i])
        });
    }
}

/// Writes `motion(i)`, the new position and velocity of the circle at `i` in serial order, to
/// each circle whose motion changed (an unchanged one is not marked changed). With `entities`,
/// the circles are those entities in index order instead (a solver's own, when circles came or
/// went during the step); any no longer there is skipped.
pub(crate) fn write_motion(
    order: &CircleOrder,
    entities: Option<&[Entity]>,
    circles: &mut SolverCircles,
    motion: impl Fn(usize) -> (DVec2, DVec2),
) {
    let write = |i: usize, (_, mut p, mut v, ..): QueryItem<'_, '_, SolverData>| {
        let (position, velocity) = motion(i);
        if p.0 != position {
            p.0 = position;
        }
        if v.0 != velocity {
            v.0 = velocity;
        }
    };
    match entities {
        None => order.each_mut(circles, write),
        Some(entities) => {
            for (i, &entity) in entities.iter().enumerate() {
                if let Ok(item) = circles.get_mut(entity) {
                    write(i, item);
                }
            }
        }
    }
}
