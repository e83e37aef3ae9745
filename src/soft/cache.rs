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

/// The impulses of last step's contacts, by circle: what warm starting starts from.
#[derive(Default)]
pub struct ContactCache {
    /// Each circle's identity last step, by its index then.
    ids: Vec<u64>,
    /// `entries[start[i]..start[i + 1]]` are circle `i`'s contacts (as their `a`).
    start: Vec<u32>,
    entries: Vec<Cached>,
    /// Last step's index of each identity, built only when the circles changed order.
    index_of: HashMap<u64, u32>,
}

impl ContactCache {
    /// Forgets every contact (after a respawn, say).
    pub fn clear(&mut self) {
        *self = Self::default();
    }

    /// Gives every contact in `constraints` the impulse it ended last step with, and whether
    /// it pushed then (and its row in `rows`, if it has friction, the friction and rolling
    /// impulses it ended with). `ids` are the circles' identities now.
    pub fn warm_start(
        &mut self,
        ids: &[u64],
        constraints: &mut [Constraint],
        rows: &mut [TurningRow],
    ) {
        if self.entries.is_empty() {
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
                Some(a)
            } else {
                self.index_of.get(&ids[a]).map(|&i| i as usize)
            };
            let Some(old) = old else { continue };
            let (from, to) = (self.start[old] as usize, self.start[old + 1] as usize);
            if let Some(hit) = self.entries[from..to]
                .iter()
                .find(|e| e.partner == c.partner)
            {
                c.impulse = hit.impulse;
                c.was_touching = hit.touching;
                if c.turn != NONE {
                    // Within what the contact allows now: friction or rolling resistance
                    // switched off (or a forged checkpoint) must not leave a push no row takes
                    // back.
                    let row = &mut rows[c.turn as usize];
                    let (most_tangent, most_rolling) = row.bounds(c.impulse);
                    row.tangent_impulse = hit.tangent.clamp(-most_tangent, most_tangent);
                    row.rolling_impulse = hit.rolling.clamp(-most_rolling, most_rolling);
                }
            }
        }
    }

    /// The cache as plain data for a checkpoint of circles listed with identities `order`:
    /// each one's contacts in that order, partners by their index in it. `None` before the
    /// first step (there is nothing to warm start from).
    pub fn snapshot(&self, order: &[u64]) -> Option<CacheSnapshot> {
        if self.start.is_empty() {
            return None;
        }
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
                let mine = &self.entries[self.start[old] as usize..self.start[old + 1] as usize];
                snapshot.entries.extend(mine.iter().filter_map(|e| {
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
        let mut start = Vec::with_capacity(ids.len() + 1);
        start.push(0u32);
        for &count in &snapshot.counts {
            start.push(start.last().copied().unwrap_or(0) + count);
        }
        let entries = snapshot
            .entries
            .iter()
            .map(|e| Cached {
                partner: match e.partner {
                    SnapshotPartner::Circle(k) => Partner::Circle(ids[k as usize]),
                    SnapshotPartner::Wall(wall) => Partner::Wall(wall),
                },
                impulse: e.impulse,
                touching: e.touching,
                tangent: e.tangent,
                rolling: e.rolling,
            })
            .collect();
        Ok(Self {
            ids: ids.to_vec(),
            start,
            entries,
            index_of: HashMap::default(),
        })
    }

    /// Keeps the impulses `constraints` (and their `rows`) ended the step with, for the next
    /// step's [`ContactCache::warm_start`].
    pub fn store<'a>(
        &mut self,
        ids: &[u64],
        constraints: impl Iterator<Item = &'a Constraint> + Clone,
        rows: &[TurningRow],
    ) {
        self.ids.clear();
        self.ids.extend_from_slice(ids);
        self.index_of.clear();
        // A counting sort by circle, each circle's contacts in the order given.
        self.start.clear();
        self.start.resize(ids.len() + 1, 0);
        for c in constraints.clone() {
            self.start[c.a as usize + 1] += 1;
        }
        for i in 0..ids.len() {
            self.start[i + 1] += self.start[i];
        }
        let mut next = self.start.clone();
        let empty = Cached {
            partner: Partner::Wall(Wall::Segment(0)),
            impulse: 0.0,
            touching: false,
            tangent: 0.0,
            rolling: 0.0,
        };
        self.entries.clear();
        self.entries.resize(self.start[ids.len()] as usize, empty);
        for c in constraints {
            let (tangent, rolling) = match rows.get(c.turn as usize) {
                Some(row) => (row.tangent_impulse, row.rolling_impulse),
                None => (0.0, 0.0),
            };
            let slot = &mut next[c.a as usize];
            self.entries[*slot as usize] = Cached {
                partner: c.partner,
                impulse: c.impulse,
                touching: c.total_impulse > 0.0,
                tangent,
                rolling,
            };
            *slot += 1;
        }
    }
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
