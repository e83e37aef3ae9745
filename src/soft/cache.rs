//! The [`ContactCache`]: each contact's impulses at the end of a step (along the normal, along
//! the surface and in turning), kept under its circle's
//! identity and its partner, so the next step starts from last step's answer (warm starting)
//! and knows which contacts were already pushing (those do not bounce again); and
//! [`CacheSnapshot`], the same as plain data for a checkpoint.

use bevy::platform::collections::HashMap;
use serde::{Deserialize, Serialize};

use super::contacts::{Constraint, Partner, TurningRow};
use crate::circle::CircleState;
use crate::grid::NONE;
use crate::hits::Wall;
use crate::range::MAX_MAGNITUDE;

/// Most a cached impulse may change a circle's velocity by, in units of the largest speed an
/// input may give: two circles at that speed meeting head-on trade four times it, and a
/// warm start from a forged impulse must not send a circle off at speeds nothing else can
/// reach (the soft step's energies would overflow).
const MOST_SPEED_CHANGES: f64 = 8.0;

/// One contact's impulse, kept for the next step under its circle's identity and its partner.
#[derive(Clone, Copy, Debug)]
struct Cached {
    partner: Partner,
    impulse: f64,
    touching: bool,
    tangent: f64,
    rolling: f64,
}

/// The impulses of last step's contacts: what warm starting starts from. Kept in the order the
/// step stored them, which is the order the next step finds them in but for the contacts that
/// came, went or moved: a contact is looked for where the one before it was found, and only
/// when it is not there, by its circle (an index by circle made for that step, at most once).
#[derive(Default)]
pub struct ContactCache {
    /// Each circle's identity last step, by its index then.
    ids: Vec<u64>,
    /// Last step's contacts in their order, and each one's first circle (its index then).
    stored: Vec<Cached>,
    owners: Vec<u32>,
    /// Where the next contact is looked for first in `stored`.
    cursor: usize,
    /// `stored[by_circle[start[i]..start[i + 1]]]` are circle `i`'s contacts (as their `a`),
    /// in their order; empty until a contact is not where it was looked for.
    start: Vec<u32>,
    by_circle: Vec<u32>,
    /// Last step's index of each identity, built only when the circles changed order.
    index_of: HashMap<u64, u32>,
    /// Whether a step has stored (or a checkpoint restored) it.
    stepped: bool,
}

impl ContactCache {
    /// Forgets every contact (after a respawn, say).
    pub fn clear(&mut self) {
        *self = Self::default();
    }

    /// Gives every contact in `constraints` the impulse it ended last step with, and whether
    /// it pushed then (and its row in `rows`, if it has friction, the friction and rolling
    /// impulses it ended with). `ids` are the circles' identities now. A step calls it for its
    /// contacts in the order it stores them.
    pub fn warm_start(
        &mut self,
        ids: &[u64],
        constraints: &mut [Constraint],
        rows: &mut [TurningRow],
    ) {
        if self.stored.is_empty() {
            return;
        }
        let same_order = self.ids == ids;
        if !same_order && self.index_of.is_empty() {
            self.index_of = self
                .ids
                .iter()
                .enumerate()
                .map(|(i, &id)| (id, i as u32))
                .collect();
        }
        for c in constraints.iter_mut() {
            let a = c.a as usize;
            let old = if same_order {
                Some(a as u32)
            } else {
                self.index_of.get(&ids[a]).copied()
            };
            let Some(old) = old else { continue };
            let Some(k) = self.find(old, c.partner) else {
                continue;
            };
            self.cursor = k + 1;
            let hit = self.stored[k];
            c.impulse = hit.impulse;
            c.was_touching = hit.touching;
            if c.turn != NONE {
                // Within what the contact allows now: friction or rolling resistance switched
                // off (or a forged checkpoint) must not leave a push no row takes back.
                let row = &mut rows[c.turn as usize];
                let (most_tangent, most_rolling) = row.bounds(c.impulse);
                row.tangent_impulse = hit.tangent.clamp(-most_tangent, most_tangent);
                row.rolling_impulse = hit.rolling.clamp(-most_rolling, most_rolling);
            }
        }
    }

    /// Where in `stored` circle `old`'s contact with `partner` is: at the cursor or just past
    /// it (a contact gone), else by its circle.
    fn find(&mut self, old: u32, partner: Partner) -> Option<usize> {
        let is = |cache: &Self, k: usize| cache.owners[k] == old && cache.stored[k].partner == partner;
        let near = self.cursor..(self.cursor + 2).min(self.stored.len());
        if let Some(k) = near.clone().find(|&k| is(self, k)) {
            return Some(k);
        }
        self.index_by_circle();
        let old = old as usize;
        let mine = &self.by_circle[self.start[old] as usize..self.start[old + 1] as usize];
        mine.iter().map(|&k| k as usize).find(|&k| is(self, k))
    }

    /// Lists `stored` by circle, if not yet done since it was stored.
    fn index_by_circle(&mut self) {
        if self.start.is_empty() {
            let n = self.ids.len();
            by_circle(&self.owners, n, (&mut self.start, &mut self.by_circle));
        }
    }

    /// The cache as plain data for a checkpoint of circles listed with identities `order`:
    /// each one's contacts in that order, partners by their index in it. `None` before the
    /// first step (there is nothing to warm start from).
    pub fn snapshot(&self, order: &[u64]) -> Option<CacheSnapshot> {
        if !self.stepped {
            return None;
        }
        let (mut start, mut listed) = (Vec::new(), Vec::new());
        by_circle(&self.owners, self.ids.len(), (&mut start, &mut listed));
        let position: HashMap<u64, u32> = order
            .iter()
            .enumerate()
            .map(|(i, &id)| (id, i as u32))
            .collect();
        let cached: HashMap<u64, usize> = self
            .ids
            .iter()
            .enumerate()
            .map(|(i, &id)| (id, i))
            .collect();
        let mut snapshot = CacheSnapshot::default();
        for id in order {
            let before = snapshot.entries.len();
            if let Some(&old) = cached.get(id) {
                let mine = &listed[start[old] as usize..start[old + 1] as usize];
                let mine = mine.iter().map(|&k| &self.stored[k as usize]);
                snapshot.entries.extend(mine.filter_map(|e| {
                    let partner = match e.partner {
                        Partner::Circle(id) => SnapshotPartner::Circle(*position.get(&id)?),
                        Partner::Wall(wall) => SnapshotPartner::Wall(wall),
                    };
                    Some(CachedContact {
                        partner,
                        impulse: e.impulse,
                        touching: e.touching,
                        tangent: e.tangent,
                        rolling: e.rolling,
                    })
                }));
            }
            snapshot
                .counts
                .push((snapshot.entries.len() - before) as u32);
        }
        Some(snapshot)
    }

    /// The cache of a checkpoint for circles whose identities are now `ids` (in the order the
    /// checkpoint lists them). Fails, saying why, if it does not fit them.
    pub fn restore(snapshot: &CacheSnapshot, ids: &[u64]) -> Result<Self, String> {
        snapshot.check_lists(ids.len())?;
        let owners = snapshot
            .counts
            .iter()
            .enumerate()
            .flat_map(|(i, &count)| std::iter::repeat_n(i as u32, count as usize));
        let stored = snapshot.entries.iter().map(|e| Cached {
            partner: match e.partner {
                SnapshotPartner::Circle(k) => Partner::Circle(ids[k as usize]),
                SnapshotPartner::Wall(wall) => Partner::Wall(wall),
            },
            impulse: e.impulse,
            touching: e.touching,
            tangent: e.tangent,
            rolling: e.rolling,
        });
        Ok(Self {
            ids: ids.to_vec(),
            stored: stored.collect(),
            owners: owners.collect(),
            stepped: true,
            ..Self::default()
        })
    }

    /// Keeps the impulses `constraints` (and their `rows`) ended the step with, in their
    /// order, for the next step's [`ContactCache::warm_start`].
    pub fn store<'a>(
        &mut self,
        ids: &[u64],
        constraints: impl Iterator<Item = &'a Constraint>,
        rows: &[TurningRow],
    ) {
        self.ids.clear();
        self.ids.extend_from_slice(ids);
        self.index_of.clear();
        self.start.clear();
        self.cursor = 0;
        self.stepped = true;
        self.stored.clear();
        self.owners.clear();
        for c in constraints {
            let (tangent, rolling) = match rows.get(c.turn as usize) {
                Some(row) => (row.tangent_impulse, row.rolling_impulse),
                None => (0.0, 0.0),
            };
            self.owners.push(c.a);
            self.stored.push(Cached {
                partner: c.partner,
                impulse: c.impulse,
                touching: c.total_impulse > 0.0,
                tangent,
                rolling,
            });
        }
    }
}

/// Where each circle's contacts are among contacts whose first circles are `owners` (all below
/// `n`), into `start` and `listed`: circle `i`'s are those at `listed[start[i]..start[i + 1]]`,
/// in their order (a counting sort).
fn by_circle(owners: &[u32], n: usize, (start, listed): (&mut Vec<u32>, &mut Vec<u32>)) {
    start.clear();
    start.resize(n + 1, 0);
    for &a in owners {
        start[a as usize + 1] += 1;
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    listed.clear();
    listed.resize(owners.len(), 0);
    // Each circle's start serves as its next free place, which leaves it at the next
    // circle's start: shifted back by one place after.
    for (k, &a) in owners.iter().enumerate() {
        let next = &mut start[a as usize];
        listed[*next as usize] = k as u32;
        *next += 1;
    }
    start.rotate_right(1);
    start[0] = 0;
}

/// A contact's other side in a [`CacheSnapshot`]: a circle by its index.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum SnapshotPartner {
    /// Circle `k` of the checkpoint.
    Circle(u32),
    /// An arena or segment wall.
    Wall(Wall),
}

/// One contact in a [`CacheSnapshot`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
struct CachedContact {
    partner: SnapshotPartner,
    /// Impulse along the normal.
    impulse: f64,
    /// Whether it pushed.
    touching: bool,
    /// Impulse along the surface (friction).
    tangent: f64,
    /// Torque impulse (rolling resistance).
    rolling: f64,
}

/// [`ContactCache`] as plain data for a checkpoint: how many contacts each circle has (as
/// their first circle), and each contact's partner, impulses and whether it pushed.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CacheSnapshot {
    counts: Vec<u32>,
    entries: Vec<CachedContact>,
}

impl CacheSnapshot {
    /// Whether it can belong to `circles`: a count per circle adding up to the entries,
    /// partners among them, impulses finite, not negative, and changing no movable circle's
    /// velocity by more than eight times the largest speed an input may give.
    pub fn check(&self, circles: &[CircleState]) -> Result<(), String> {
        self.check_lists(circles.len())?;
        let owners = self
            .counts
            .iter()
            .enumerate()
            .flat_map(|(i, &count)| std::iter::repeat_n(i, count as usize));
        for (i, e) in owners.zip(&self.entries) {
            let own = &circles[i];
            let (other, smaller) = match e.partner {
                SnapshotPartner::Circle(k) => {
                    let other = &circles[k as usize];
                    (other.inv_mass(), own.radius.min(other.radius))
                }
                SnapshotPartner::Wall(_) => (0.0, own.radius),
            };
            let lightest = own.inv_mass().max(other);
            // A torque impulse k turns a uniform disc's surface by 2 k w / r.
            let turning = 2.0 * e.rolling.abs() * lightest / smaller;
            for (what, change) in [
                ("contact impulse", e.impulse * lightest),
                ("friction impulse", e.tangent.abs() * lightest),
                ("rolling impulse", turning),
            ] {
                if change > MOST_SPEED_CHANGES * MAX_MAGNITUDE {
                    return Err(format!(
                        "a cached {what} on circle {i} is beyond any speed: it would change \
                         a speed by {change:e}"
                    ));
                }
            }
        }
        Ok(())
    }

    /// Whether its lists fit `n` circles: a count per circle adding up to the entries,
    /// partners among them, impulses finite and not negative.
    fn check_lists(&self, n: usize) -> Result<(), String> {
        if self.counts.len() != n {
            return Err(format!(
                "the contact cache lists {} circles, the checkpoint {n}",
                self.counts.len()
            ));
        }
        let total: u64 = self.counts.iter().map(|&c| u64::from(c)).sum();
        if total != self.entries.len() as u64 {
            return Err("the contact cache's lists do not add up".to_owned());
        }
        for e in &self.entries {
            if let SnapshotPartner::Circle(k) = e.partner
                && k as usize >= n
            {
                return Err(format!("a cached contact names circle {k} of {n}"));
            }
            if !(e.impulse.is_finite() && e.impulse >= 0.0) {
                return Err(format!("a cached contact impulse is {}", e.impulse));
            }
            if !(e.tangent.is_finite() && e.rolling.is_finite()) {
                let (t, r) = (e.tangent, e.rolling);
                return Err(format!("a cached friction impulse is {t}, rolling {r}"));
            }
        }
        Ok(())
    }

    /// The segment walls the cached contacts name.
    pub fn segments(&self) -> impl Iterator<Item = u32> + '_ {
        self.entries.iter().filter_map(|e| match e.partner {
            SnapshotPartner::Wall(Wall::Segment(k)) => Some(k),
            _ => None,
        })
    }
}

#[cfg(test)]
mod tests {
    use bevy::math::DVec2;

    use super::*;

    /// A contact of circle `a` with circle `b` (by index, identity `b`) or, for `b` past the
    /// circles, with segment wall `b`.
    fn contact(a: u32, b: u32, impulse: f64) -> Constraint {
        let partner = match b {
            0..8 => Partner::Circle(u64::from(b)),
            _ => Partner::Wall(Wall::Segment(b)),
        };
        Constraint {
            a,
            b: if b < 8 { b } else { NONE },
            partner,
            normal: DVec2::X,
            anchor: DVec2::ZERO,
            reach: 1.0,
            inv_mass: (1.0, 1.0),
            normal_mass: 0.5,
            soft: super::super::Softness::new(30.0, 10.0, 1.0 / 240.0),
            restitution: 0.0,
            threshold: 0.0,
            push: 1.0,
            relative_velocity: 0.0,
            impulse,
            total_impulse: impulse,
            approach: 0.0,
            was_touching: false,
            turn: NONE,
        }
    }

    #[test]
    fn each_contact_warm_starts_from_its_own_impulse_whatever_came_went_or_moved() {
        let ids: Vec<u64> = (0..8).collect();
        // Last step: every pair (a, b), a < b, of 8 circles and a wall each, in a fixed
        // order; its impulse names it.
        let named = |a: u32, b: u32| f64::from(a * 100 + b);
        let mut last: Vec<Constraint> = (0..8)
            .flat_map(|a| (a + 1..8).chain([20 + a]).map(move |b| (a, b)))
            .map(|(a, b)| contact(a, b, named(a, b)))
            .collect();
        let mut cache = ContactCache::default();
        cache.store(&ids, last.iter(), &[]);
        // This step: some gone, some new, a block moved far, neighbours swapped; in two
        // calls, as a step warm starts its walls and then its pairs.
        last.retain(|c| (c.a + c.b) % 5 != 0);
        last.rotate_left(7);
        last.swap(3, 4);
        last.extend([contact(0, 30, 0.0), contact(5, 31, 0.0)]);
        let mut now: Vec<Constraint> = last.iter().map(|c| contact(c.a, c.b, -1.0)).collect();
        let (first, second) = now.split_at_mut(10);
        cache.warm_start(&ids, first, &mut []);
        cache.warm_start(&ids, second, &mut []);
        for c in &now {
            let expected = match c.partner {
                Partner::Circle(b) => named(c.a, b as u32),
                Partner::Wall(Wall::Segment(w)) if w < 30 => named(c.a, w),
                Partner::Wall(_) => -1.0,
            };
            assert_eq!(c.impulse, expected, "contact {} {:?}", c.a, c.partner);
        }
        // With the circles in another order the same contacts are found by identity.
        let reversed: Vec<u64> = ids.iter().rev().copied().collect();
        let mut renamed: Vec<Constraint> =
            now.iter().map(|c| contact(7 - c.a, c.b, -1.0)).collect();
        let (first, second) = renamed.split_at_mut(5);
        cache.warm_start(&reversed, first, &mut []);
        cache.warm_start(&reversed, second, &mut []);
        for (c, was) in renamed.iter().zip(&now) {
            assert_eq!(c.impulse, was.impulse, "contact {} {:?}", c.a, c.partner);
        }
        // Where the contact looked for first has the same partner but another circle.
        let two = [contact(0, 5, 1.0), contact(1, 5, 2.0)];
        cache.store(&ids, two.iter(), &[]);
        let mut one = [contact(1, 5, -1.0)];
        cache.warm_start(&ids, &mut one, &mut []);
        assert_eq!(one[0].impulse, 2.0);
    }

    #[test]
    fn a_cached_impulse_beyond_any_speed_is_refused() {
        // Circle 0 has one contact, with circle 1: a light pair (the fuzz target's forged
        // impulse of 2.6e307 sent them to infinity on the warm start).
        let light = |x| CircleState::new(DVec2::new(x, 0.0), DVec2::ZERO, 0.1).with_mass(0.03);
        let circles = [light(0.0), light(0.2)];
        let contact = |partner, impulse, tangent, rolling| CachedContact {
            partner,
            impulse,
            touching: true,
            tangent,
            rolling,
        };
        let cache = |impulse, tangent, rolling| CacheSnapshot {
            counts: vec![1, 0],
            entries: vec![contact(
                SnapshotPartner::Circle(1),
                impulse,
                tangent,
                rolling,
            )],
        };
        assert!(cache(0.5, -0.2, 0.01).check(&circles).is_ok());
        assert!(cache(1e28, -1e28, 1e26).check(&circles).is_ok());
        for forged in [2.6e307, 1e30, -1.0, f64::NAN] {
            assert!(cache(forged, 0.0, 0.0).check(&circles).is_err(), "{forged}");
        }
        for forged in [-2.6e307, 1e30, f64::NAN, f64::INFINITY] {
            assert!(cache(0.5, forged, 0.0).check(&circles).is_err(), "{forged}");
            assert!(cache(0.5, 0.0, forged).check(&circles).is_err(), "{forged}");
        }
        // Against a wall only the circle's own mass counts; an immovable circle takes none.
        let wall = CacheSnapshot {
            counts: vec![1, 0],
            entries: vec![contact(
                SnapshotPartner::Wall(Wall::Segment(0)),
                1e30,
                0.0,
                0.0,
            )],
        };
        assert!(wall.check(&circles).is_err());
        let pegs = [circles[0].with_mass(f64::INFINITY), circles[1]];
        assert!(wall.check(&pegs).is_ok());
    }
}
