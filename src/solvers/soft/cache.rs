//! The [`ContactCache`]: each contact's impulses at the end of a step (along the normal, along
//! the surface and in turning), kept under its circle's
//! identity and its partner, so the next step starts from last step's answer (warm starting)
//! and knows which contacts were already pushing (those do not bounce again); and
//! [`CacheSnapshot`], the same as plain data for a checkpoint.

use bevy::platform::collections::HashMap;
use serde::{Deserialize, Serialize};

use super::contacts::{Constraint, Partner, TurningRow};
use crate::base::circle::CircleState;
use crate::base::grid::NONE;
use crate::base::hits::Wall;
use crate::base::range::MAX_MAGNITUDE;

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

impl Clone for ContactCache {
    fn clone(&self) -> Self {
        let mut copy = Self::default();
        copy.copy_kept_from(self);
        copy
    }

    fn clone_from(&mut self, source: &Self) {
        self.copy_kept_from(source);
    }
}

impl ContactCache {
    /// Becomes a copy of what `other` keeps for the next step (its circles, contacts and
    /// impulses; the lookups a step makes are made again), reusing its own buffers: what a
    /// rollback saves and restores.
    pub fn copy_kept_from(&mut self, other: &ContactCache) {
        self.ids.clone_from(&other.ids);
        self.stored.clone_from(&other.stored);
        self.owners.clone_from(&other.owners);
        self.stepped = other.stepped;
        self.cursor = 0;
        self.index_of.clear();
        self.start.clear();
    }

    /// Bytes of what [`ContactCache::copy_kept_from`] copies.
    pub fn kept_bytes(&self) -> usize {
        size_of_val(&self.ids[..]) + size_of_val(&self.stored[..]) + size_of_val(&self.owners[..])
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
        let is =
            |cache: &Self, k: usize| cache.owners[k] == old && cache.stored[k].partner == partner;
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
                touching: c.pressing,
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

/// The contacts kept for warm starting (`ContactCache`) as plain data for a checkpoint: how
/// many contacts each circle has (as their first circle), and each contact's partner, impulses
/// and whether it pushed.
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
mod tests;
