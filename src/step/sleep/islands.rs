//! The kernels of sleeping, as plain functions over [`Resting`] circles: which islands of
//! circles at rest fall asleep ([`fall_asleep`]), and which sleeping circles a circle that is
//! not at rest wakes ([`wake_touched`]). Two circles touch when their gap is below
//! [`TOUCHING`] of the smaller radius; islands are the groups that touching joins.

use bevy::math::DVec2;

use crate::base::arena::Arena;
use crate::base::collision_layers::{CollisionLayers, pair_meets};
use crate::base::components::Sleep;
use crate::collision::broad_phase::{CellList, overlapping_pairs};
use crate::collision::pair_list::{PairList, SKIN};

/// Gap (in the smaller radius) within which two circles count as touching for an island.
pub const TOUCHING: f64 = 0.05;

/// Groups of circles joined by contacts: a union-find over circle indices.
#[derive(Clone, Debug, Default)]
pub struct Islands {
    parent: Vec<u32>,
}

impl Islands {
    /// `n` circles, each its own island.
    pub fn new(n: usize) -> Self {
        Self {
            parent: (0..n as u32).collect(),
        }
    }

    /// The island of circle `i` (its root).
    pub fn find(&mut self, i: usize) -> usize {
        let mut i = i as u32;
        while self.parent[i as usize] != i {
            let grand = self.parent[self.parent[i as usize] as usize];
            self.parent[i as usize] = grand;
            i = grand;
        }
        i as usize
    }

    /// Joins the islands of `i` and `j` (the smaller root leads, so the result does not depend
    /// on the order of the joins).
    pub fn join(&mut self, i: usize, j: usize) {
        let (a, b) = (self.find(i), self.find(j));
        if a != b {
            let (low, high) = if a < b { (a, b) } else { (b, a) };
            self.parent[high] = low as u32;
        }
    }
}

/// One circle as sleeping sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Resting {
    /// Centre.
    pub position: DVec2,
    /// Radius.
    pub radius: f64,
    /// Whether it can move (an immovable circle is in no island).
    pub movable: bool,
    /// Whether it is immovable and moving: a kinematic circle, which wakes what it touches.
    pub pushing: bool,
    /// Its sleep state, updated in place.
    pub sleep: Sleep,
    /// How far it may travel in the coming step (its speed times the step, and what gravity
    /// adds): a stirring circle wakes what it may touch before the step ends, not only what it
    /// touches now.
    pub travel: f64,
}

impl Resting {
    /// Its centre, and the reach within which it touches another circle.
    fn touching_reach(&self) -> (DVec2, f64) {
        (self.position, self.radius * (1.0 + TOUCHING))
    }

    /// Its centre, and the reach within which it may touch another circle in the coming step.
    fn waking_reach(&self) -> (DVec2, f64) {
        (self.position, self.radius * (1.0 + TOUCHING) + self.travel)
    }

    /// Whether it is awake and not at rest for `time` (a movable circle), or pushing (a
    /// kinematic one): what wakes the sleeping circles it touches.
    fn stirring(&self, time: f64) -> bool {
        self.pushing || (self.movable && !self.sleep.asleep && self.sleep.slow_for < time)
    }
}

/// Buffers reused from call to call: circle indices, their centres and reaches, the broad
/// phase's cells and the pairs it found, and the touching pairs of all circles.
#[derive(Default)]
pub struct IslandScratch {
    /// Each circle's layers (filled by the caller), or empty when every pair meets: circles
    /// that do not meet do not touch.
    pub layers: Vec<CollisionLayers>,
    chosen: Vec<u32>,
    reach: Vec<(DVec2, f64)>,
    cells: CellList,
    pairs: Vec<(u32, u32)>,
    /// The touching pairs of all the circles, kept from call to call: circles that may fall
    /// asleep have barely moved since the last look.
    all: PairList,
}

impl IslandScratch {
    /// The touching pairs that meet among all of `circles`, in no particular order.
    fn all_touching_pairs(&mut self, circles: &[Resting], arena: &Arena) {
        self.reach.clear();
        self.reach
            .extend(circles.iter().map(Resting::touching_reach));
        self.pairs.clear();
        let (pairs, layers) = (&mut self.pairs, &self.layers);
        self.all
            .for_each_overlapping_in_any_order(arena, &self.reach, SKIN, |i, j| {
                if pair_meets(layers, i, j) {
                    pairs.push((i as u32, j as u32));
                }
            });
    }

    /// The pairs that meet among the circles `chosen` selects and whose waking reaches
    /// ([`Resting::waking_reach`]) overlap, as positions in `self.chosen`.
    fn touching_pairs(
        &mut self,
        circles: &[Resting],
        arena: &Arena,
        chosen: impl Fn(&Resting) -> bool,
    ) {
        self.chosen.clear();
        self.chosen
            .extend((0..circles.len() as u32).filter(|&i| chosen(&circles[i as usize])));
        self.reach.clear();
        let reach = self
            .chosen
            .iter()
            .map(|&i| circles[i as usize].waking_reach());
        self.reach.extend(reach);
        self.pairs.clear();
        overlapping_pairs(&mut self.cells, arena, &self.reach, &mut self.pairs);
        if !self.layers.is_empty() {
            let (chosen, layers) = (&self.chosen, &self.layers);
            self.pairs.retain(|&(k, l)| {
                pair_meets(
                    layers,
                    chosen[k as usize] as usize,
                    chosen[l as usize] as usize,
                )
            });
        }
    }
}

/// Puts to sleep each island of `circles` whose circles are all asleep or have been at rest
/// for `time`, and that no kinematic circle touches. Returns the circles that fell asleep.
/// Islands are found among movable circles within [`TOUCHING`] of each other in `arena`.
pub fn fall_asleep(
    circles: &mut [Resting],
    arena: &Arena,
    time: f64,
    scratch: &mut IslandScratch,
) -> Vec<usize> {
    scratch.all_touching_pairs(circles, arena);
    let mut islands = Islands::new(circles.len());
    let mut pushed = vec![false; circles.len()];
    for &(i, j) in &scratch.pairs {
        let (i, j) = (i as usize, j as usize);
        match (circles[i].movable, circles[j].movable) {
            (true, true) => islands.join(i, j),
            (true, false) => pushed[i] |= circles[j].pushing,
            (false, true) => pushed[j] |= circles[i].pushing,
            (false, false) => {}
        }
    }
    let mut ready = vec![true; circles.len()];
    for (i, c) in circles.iter().enumerate() {
        if c.movable {
            let root = islands.find(i);
            ready[root] &= !pushed[i] && (c.sleep.asleep || c.sleep.slow_for >= time);
        }
    }
    let mut fell = Vec::new();
    for i in 0..circles.len() {
        let c = &mut circles[i];
        if c.movable && !c.sleep.asleep && ready[islands.find(i)] {
            c.sleep.asleep = true;
            fell.push(i);
        }
    }
    fell
}

/// Wakes every sleeping circle of `circles` that a stirring circle (awake and not at rest for
/// `time`, or kinematic and moving) touches or may touch within its [`Resting::travel`],
/// together with every sleeping circle joined to it through sleeping circles, and starts their
/// timers again. Looks only at the sleeping and
/// the stirring circles. Returns the circles that woke.
pub fn wake_touched(
    circles: &mut [Resting],
    arena: &Arena,
    time: f64,
    scratch: &mut IslandScratch,
) -> Vec<usize> {
    scratch.touching_pairs(circles, arena, |c| {
        (c.movable && c.sleep.asleep) || c.stirring(time)
    });
    let chosen = &scratch.chosen;
    let sleeping = |k: u32| circles[chosen[k as usize] as usize].sleep.asleep;
    let mut islands = Islands::new(chosen.len());
    let mut hit = vec![false; chosen.len()];
    for &(k, l) in &scratch.pairs {
        match (sleeping(k), sleeping(l)) {
            (true, true) => islands.join(k as usize, l as usize),
            (true, false) => hit[k as usize] = true,
            (false, true) => hit[l as usize] = true,
            (false, false) => {}
        }
    }
    let mut woken_island = vec![false; chosen.len()];
    for k in 0..chosen.len() {
        if hit[k] {
            woken_island[islands.find(k)] = true;
        }
    }
    let mut woke = Vec::new();
    for k in 0..chosen.len() {
        let i = chosen[k] as usize;
        if circles[i].sleep.asleep && woken_island[islands.find(k)] {
            circles[i].sleep = Sleep {
                anchor: circles[i].position,
                ..Sleep::default()
            };
            woke.push(i);
        }
    }
    woke
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(x: f64, movable: bool, slow_for: f64) -> Resting {
        Resting {
            position: DVec2::new(x, 0.0),
            radius: 0.5,
            movable,
            pushing: false,
            sleep: Sleep {
                anchor: DVec2::new(x, 0.0),
                slow_for,
                asleep: false,
            },
            travel: 0.0,
        }
    }

    #[test]
    fn an_island_sleeps_only_when_all_of_it_has_rested_long_enough() {
        let arena = Arena::default();
        let mut scratch = IslandScratch::default();
        // Two touching circles, one rested long enough, one not; a third apart, rested.
        let mut circles = [
            circle(0.0, true, 1.0),
            circle(1.0, true, 0.1),
            circle(3.0, true, 1.0),
        ];
        assert_eq!(fall_asleep(&mut circles, &arena, 0.5, &mut scratch), [2]);
        circles[1].sleep.slow_for = 0.6;
        assert_eq!(fall_asleep(&mut circles, &arena, 0.5, &mut scratch), [0, 1]);
        assert!(fall_asleep(&mut circles, &arena, 0.5, &mut scratch).is_empty());
    }

    #[test]
    fn a_stirring_circle_wakes_the_sleeping_circles_joined_to_what_it_touches() {
        let arena = Arena::default();
        let mut scratch = IslandScratch::default();
        // A sleeping chain 0-1, a sleeper 2 apart, and circle 3 just arrived next to 0.
        let mut circles = [
            circle(0.0, true, 1.0),
            circle(1.0, true, 1.0),
            circle(3.0, true, 1.0),
        ];
        fall_asleep(&mut circles, &arena, 0.5, &mut scratch);
        let mut arrived = circles.to_vec();
        arrived.push(circle(-1.0, true, 0.0));
        // At rest long enough, it wakes nothing; moving, it wakes the chain it touches.
        arrived[3].sleep.slow_for = 0.5;
        assert!(wake_touched(&mut arrived, &arena, 0.5, &mut scratch).is_empty());
        arrived[3].sleep.slow_for = 0.1;
        assert_eq!(
            wake_touched(&mut arrived, &arena, 0.5, &mut scratch),
            [0, 1]
        );
        assert!(arrived[2].sleep.asleep, "the circle apart sleeps on");
        assert_eq!(arrived[0].sleep.slow_for, 0.0, "a woken circle starts over");
    }

    #[test]
    fn a_static_circle_joins_no_island_and_a_moving_one_wakes_what_it_touches() {
        let arena = Arena::default();
        let mut scratch = IslandScratch::default();
        // Two rested circles on either side of a static peg: two islands, both asleep.
        let mut circles = [
            circle(-1.0, true, 1.0),
            circle(0.0, false, 0.0),
            circle(1.0, true, 1.0),
        ];
        assert_eq!(fall_asleep(&mut circles, &arena, 0.5, &mut scratch), [0, 2]);
        circles[1].pushing = true;
        assert_eq!(
            wake_touched(&mut circles, &arena, 0.5, &mut scratch),
            [0, 2]
        );
        // Awake again and touched by the moving peg, they cannot fall asleep.
        circles[0].sleep.slow_for = 1.0;
        circles[2].sleep.slow_for = 1.0;
        assert!(fall_asleep(&mut circles, &arena, 0.5, &mut scratch).is_empty());
    }
}
