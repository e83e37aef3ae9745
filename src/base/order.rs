//! The order the solvers visit circles in: [`CircleOrder`], the circles sorted by their
//! [`CircleSerial`] (the spawn order), and the walks over a query in that order.
//!
//! A query yields circles table by table, in each table in the order they were added. That
//! order is the spawn order until a circle gains or loses a component (it moves to the end of
//! another table), or until the world is rebuilt from a checkpoint or a rollback snapshot. The
//! solvers' results depend on the order they see circles in (which contact is solved first,
//! which event wins a tie), so every solver gathers in serial order: the query's own order
//! where it already is (the common case, checked in one pass), the entities sorted by serial
//! otherwise.

use bevy::ecs::query::{IterQueryData, QueryData, QueryFilter, QueryItem, ROQueryItem};
use bevy::prelude::*;

use crate::base::components::{CircleSerial, Mass, Position, Radius, Sleep, Velocity};

/// The circles every solver steps (those [`SolverCircles`](crate::base::components::SolverCircles)
/// matches), with their serials.
pub type SerialCircles<'w, 's> = Query<
    'w,
    's,
    (Entity, &'static CircleSerial),
    (
        With<Position>,
        With<Velocity>,
        With<Radius>,
        With<Mass>,
        With<Sleep>,
    ),
>;

/// The circles in serial order, as of the start of the running fixed step.
#[derive(Resource, Default, Debug)]
pub struct CircleOrder {
    entities: Vec<Entity>,
    serials: Vec<u64>,
    keyed: Vec<(CircleSerial, Entity)>,
    in_query_order: bool,
}

impl CircleOrder {
    /// Orders `circles`, given in the order a query over them yields them.
    pub fn update(&mut self, circles: impl Iterator<Item = (Entity, CircleSerial)>) {
        self.entities.clear();
        self.serials.clear();
        let mut last = None;
        self.in_query_order = true;
        for (entity, serial) in circles {
            self.in_query_order &= last < Some(serial);
            last = Some(serial);
            self.entities.push(entity);
            self.serials.push(serial.0);
        }
        if !self.in_query_order {
            self.keyed.clear();
            let pairs = self.serials.iter().zip(&self.entities);
            self.keyed
                .extend(pairs.map(|(&s, &e)| (CircleSerial(s), e)));
            self.keyed.sort_unstable();
            self.entities.clear();
            self.serials.clear();
            self.entities.extend(self.keyed.iter().map(|&(_, e)| e));
            self.serials.extend(self.keyed.iter().map(|&(s, _)| s.0));
        }
    }

    /// The circles' entities in serial order.
    pub fn entities(&self) -> &[Entity] {
        &self.entities
    }

    /// The circles' serials, in order: what the solvers key what they keep between steps by
    /// (a circle keeps its serial in a world rebuilt with new entities).
    pub fn serials(&self) -> &[u64] {
        &self.serials
    }

    /// Whether a query over the circles yields them in serial order already.
    pub fn in_query_order(&self) -> bool {
        self.in_query_order
    }

    /// Calls `visit` with each circle of `query` in serial order and its place in that order.
    /// `query` must match the circles the order was made from.
    pub fn each<'w, 's, D: QueryData, F: QueryFilter>(
        &self,
        query: &'s Query<'w, 's, D, F>,
        mut visit: impl FnMut(usize, ROQueryItem<'_, 's, D>),
    ) {
        if self.in_query_order {
            query
                .iter()
                .enumerate()
                .for_each(|(i, item)| visit(i, item));
        } else {
            let items = query.iter_many(&self.entities);
            items.enumerate().for_each(|(i, item)| visit(i, item));
        }
    }

    /// [`CircleOrder::each`] with write access to the circles.
    pub fn each_mut<'w, 's, D: IterQueryData, F: QueryFilter>(
        &self,
        query: &mut Query<'w, 's, D, F>,
        mut visit: impl FnMut(usize, QueryItem<'_, 's, D>),
    ) {
        if self.in_query_order {
            query
                .iter_mut()
                .enumerate()
                .for_each(|(i, item)| visit(i, item));
        } else {
            for (i, &entity) in self.entities.iter().enumerate() {
                if let Ok(item) = query.get_mut(entity) {
                    visit(i, item);
                }
            }
        }
    }
}

/// The serials of `entities`, circles from [`snapshot_with_entities`], which lists only
/// circles with one.
///
/// [`snapshot_with_entities`]: crate::base::circle::snapshot_with_entities
pub fn serials_of(world: &World, entities: &[Entity]) -> Vec<u64> {
    let serial = |&e: &Entity| world.get::<CircleSerial>(e).expect("a circle has a serial");
    entities.iter().map(|e| serial(e).0).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn order_of(serials: &[u64]) -> CircleOrder {
        let mut order = CircleOrder::default();
        let circles = serials
            .iter()
            .enumerate()
            .map(|(i, &s)| (Entity::from_raw_u32(i as u32).unwrap(), CircleSerial(s)));
        order.update(circles);
        order
    }

    #[test]
    fn circles_in_spawn_order_keep_the_query_order() {
        let order = order_of(&[3, 7, 9]);
        assert!(order.in_query_order());
        let indices: Vec<u32> = order.entities().iter().map(|e| e.index_u32()).collect();
        assert_eq!(indices, [0, 1, 2]);
    }

    #[test]
    fn circles_out_of_spawn_order_are_sorted_by_serial() {
        let order = order_of(&[3, 9, 7, 1]);
        assert!(!order.in_query_order());
        let indices: Vec<u32> = order.entities().iter().map(|e| e.index_u32()).collect();
        assert_eq!(indices, [3, 0, 2, 1]);
    }
}
