//! The event engine's priority queue: a calendar holding exactly one time per circle, popped in
//! `(time, circle)` order.
//!
//! Time is cut into blocks `width` long. Circles due in the current block sit in a binary heap of
//! a few entries; those due in the next `slots - 1` blocks sit in one list per block, joined and
//! left in O(1); later ones wait in an overflow, spread into the lists once every `slots` blocks.
//! A change of time is then O(1) or a heap of a few entries. (The std `BinaryHeap` cannot change
//! a key, and the indexed-queue crates go through a hash map, which costs more than a whole event
//! here.)
//!
//! Block numbers never decrease as time grows (however the subtraction and the product round), so
//! every circle in the heap is due no later than every circle outside it, and equal times share a
//! block. The order of events is therefore `(time, circle)` whatever the block width, the layout
//! or the history of updates, so the width is only a matter of speed: it is fitted to the spread
//! of the pending times whenever the queue is laid out, at the start and every few updates per
//! circle.

use crate::base::grid::{CellMembers, NONE};

/// Where a circle's time is kept.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Place {
    /// At `+∞`, or not a number: in nothing, never popped.
    Never,
    /// In the current block's heap, at `at[i]`.
    Heap,
    /// In the list of a later block, `slot` being the block number modulo `slots`.
    Slot(u32),
    /// In the overflow, at `at[i]`.
    Overflow,
}

/// Updates per circle between two layouts of the calendar.
const UPDATES_PER_LAYOUT: usize = 8;

/// Min-queue of `(time, circle)` with one entry per circle.
#[derive(Clone, Debug)]
pub struct EventQueue {
    time: Vec<f64>,
    place: Vec<Place>,
    /// Block numbers are `⌊(t - origin) / width⌋`, saturating at 0 below `origin`.
    origin: f64,
    inv_width: f64,
    /// The current block's number.
    current: u64,
    /// The current block's circles, a binary heap by `(time, circle)`.
    heap: Vec<u32>,
    /// Each circle's index in the heap or in the overflow.
    at: Vec<u32>,
    /// One list for each of the `slots` blocks after the current one (a power of two), by block
    /// number modulo `slots`.
    lists: CellMembers,
    slots: usize,
    /// Circles in the lists.
    listed: usize,
    /// Circles due `slots` or more blocks after the current one, in no order.
    overflow: Vec<u32>,
    /// Updates left before the next layout: the first comes once every circle can have had a
    /// time set, the next every `UPDATES_PER_LAYOUT` updates a circle.
    until_layout: usize,
    /// Empty blocks stepped over since the last layout.
    empty_blocks: usize,
}

impl EventQueue {
    /// A queue of `n` circles, all at time `+∞`.
    pub fn new(n: usize) -> Self {
        let slots = (2 * n).next_power_of_two().max(2);
        Self {
            time: vec![f64::INFINITY; n],
            place: vec![Place::Never; n],
            origin: 0.0,
            inv_width: 1.0,
            current: 0,
            heap: Vec::new(),
            at: vec![NONE; n],
            lists: CellMembers::new(slots, n),
            slots,
            listed: 0,
            overflow: Vec::new(),
            until_layout: n,
            empty_blocks: 0,
        }
    }

    /// The circle with the earliest time, and that time: `None` when no time is finite.
    #[inline]
    pub fn first(&mut self) -> Option<(usize, f64)> {
        if self.heap.is_empty() && !self.next_block() {
            return None;
        }
        let i = self.heap[0] as usize;
        Some((i, self.time[i]))
    }

    /// Every circle's time, in circle order.
    pub fn times(&self) -> Vec<f64> {
        self.time.clone()
    }

    /// A queue holding `times` (one per circle): it pops in the same order as the queue whose
    /// [`times`](Self::times) these were.
    pub fn with_times(times: &[f64]) -> Self {
        let mut queue = Self::new(times.len());
        queue.time.copy_from_slice(times);
        queue.lay_out();
        queue
    }

    /// Sets circle `i`'s time.
    pub fn set(&mut self, i: usize, time: f64) {
        match self.place[i] {
            Place::Heap => self.heap_remove(i),
            Place::Slot(slot) => self.unlink(i, slot as usize),
            Place::Overflow => self.overflow_remove(i),
            Place::Never => {}
        }
        self.time[i] = time;
        if self.until_layout == 0 {
            self.lay_out();
        } else {
            self.until_layout -= 1;
            self.place_circle(i);
        }
    }

    /// The block `time` falls in.
    #[inline]
    fn block(&self, time: f64) -> u64 {
        // `as` saturates: below the origin is block 0, beyond u64 the last block.
        ((time - self.origin) * self.inv_width) as u64
    }

    /// Puts circle `i`, in nothing, where its time belongs.
    #[inline]
    fn place_circle(&mut self, i: usize) {
        let time = self.time[i];
        if time.is_nan() || time == f64::INFINITY {
            self.place[i] = Place::Never;
            return;
        }
        let block = self.block(time);
        if block <= self.current {
            self.heap_push(i);
        } else if block - self.current < self.slots as u64 {
            self.link(i, block as usize & (self.slots - 1));
        } else {
            self.place[i] = Place::Overflow;
            self.at[i] = self.overflow.len() as u32;
            self.overflow.push(i as u32);
        }
    }

    /// Moves on to the next block with circles in it and puts them in the heap; false when no
    /// circle has a finite time.
    fn next_block(&mut self) -> bool {
        loop {
            if self.listed == 0 {
                // Only the overflow may be left: jump to its earliest block.
                let Some(earliest) = self
                    .overflow
                    .iter()
                    .map(|&i| self.time[i as usize])
                    .reduce(f64::min)
                else {
                    return false;
                };
                self.current = self.block(earliest);
                self.spread_overflow();
            } else if self.empty_blocks > self.time.len() {
                // Blocks far shorter than the gaps between times: as much time was spent
                // stepping over empty ones as a new layout takes.
                self.lay_out();
            } else {
                self.current += 1;
                if self.current as usize & (self.slots - 1) == 0 {
                    // A new round of the lists: the overflow's circles due in it join them.
                    self.spread_overflow();
                }
                let slot = self.current as usize & (self.slots - 1);
                while let Some(i) = self.lists.members(slot).next() {
                    self.unlink(i, slot);
                    self.heap_push(i);
                }
            }
            if !self.heap.is_empty() {
                return true;
            }
            self.empty_blocks += 1;
        }
    }

    /// Places again every circle of the overflow that is now due within `slots` blocks.
    ///
    /// A circle enters the overflow `slots` or more blocks before its own; exactly one round of
    /// the lists begins in the `slots` blocks up to its own, after it entered, so it is spread
    /// before its block comes.
    fn spread_overflow(&mut self) {
        for i in std::mem::take(&mut self.overflow) {
            self.place_circle(i as usize);
        }
    }

    /// Lays the calendar out afresh from the earliest finite time, with blocks about as long as
    /// one circle's time to its event over the number of circles: about one circle a block.
    fn lay_out(&mut self) {
        self.until_layout = UPDATES_PER_LAYOUT * self.time.len();
        self.empty_blocks = 0;
        self.heap.clear();
        self.lists.clear();
        self.overflow.clear();
        self.listed = 0;
        self.place.fill(Place::Never);
        let mut finite: Vec<f64> = self
            .time
            .iter()
            .copied()
            .filter(|t| t.is_finite())
            .collect();
        let Some(earliest) = finite.iter().copied().reduce(f64::min) else {
            return;
        };
        let middle = finite.len() / 2;
        let (_, &mut median, _) = finite.select_nth_unstable_by(middle, f64::total_cmp);
        let inv_width = finite.len() as f64 / (2.0 * (median - earliest));
        if inv_width.is_normal() {
            self.inv_width = inv_width;
        }
        self.origin = earliest;
        self.current = 0;
        for i in 0..self.time.len() {
            self.place_circle(i);
        }
    }

    fn link(&mut self, i: usize, slot: usize) {
        self.lists.insert(i, slot);
        self.place[i] = Place::Slot(slot as u32);
        self.listed += 1;
    }

    fn unlink(&mut self, i: usize, slot: usize) {
        self.lists.remove(i, slot);
        self.place[i] = Place::Never;
        self.listed -= 1;
    }

    fn overflow_remove(&mut self, i: usize) {
        let k = self.at[i] as usize;
        self.overflow.swap_remove(k);
        if let Some(&moved) = self.overflow.get(k) {
            self.at[moved as usize] = k as u32;
        }
        self.place[i] = Place::Never;
    }

    /// Whether the circle at heap index `k` is due before the one at `l`: by time, then index.
    #[inline]
    fn earlier(&self, k: usize, l: usize) -> bool {
        let (i, j) = (self.heap[k] as usize, self.heap[l] as usize);
        let (a, b) = (self.time[i], self.time[j]);
        a < b || (a == b && i < j)
    }

    fn heap_push(&mut self, i: usize) {
        self.place[i] = Place::Heap;
        self.at[i] = self.heap.len() as u32;
        self.heap.push(i as u32);
        self.sift_up(self.heap.len() - 1);
    }

    fn heap_remove(&mut self, i: usize) {
        let k = self.at[i] as usize;
        let last = self.heap.len() - 1;
        self.swap(k, last);
        self.heap.pop();
        self.place[i] = Place::Never;
        if k < self.heap.len() {
            self.sift_up(k);
            self.sift_down(k);
        }
    }

    fn swap(&mut self, k: usize, l: usize) {
        self.heap.swap(k, l);
        self.at[self.heap[k] as usize] = k as u32;
        self.at[self.heap[l] as usize] = l as u32;
    }

    fn sift_up(&mut self, mut k: usize) {
        while k > 0 {
            let parent = (k - 1) / 2;
            if !self.earlier(k, parent) {
                break;
            }
            self.swap(k, parent);
            k = parent;
        }
    }

    fn sift_down(&mut self, mut k: usize) {
        loop {
            let (left, right) = (2 * k + 1, 2 * k + 2);
            let mut least = k;
            if left < self.heap.len() && self.earlier(left, least) {
                least = left;
            }
            if right < self.heap.len() && self.earlier(right, least) {
                least = right;
            }
            if least == k {
                break;
            }
            self.swap(k, least);
            k = least;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The earliest `(time, circle)` by a sort.
    fn earliest(times: &[f64]) -> Option<(usize, f64)> {
        (0..times.len())
            .filter(|&i| times[i] < f64::INFINITY)
            .min_by(|&a, &b| times[a].total_cmp(&times[b]).then(a.cmp(&b)))
            .map(|i| (i, times[i]))
    }

    /// A fixed pseudo-random sequence of updates like the engine's (the first circle's time
    /// moves on, others change), checked against a sort after each one.
    fn replay(n: usize, steps: usize, spread: u64, seed: u64) {
        let mut q = EventQueue::new(n);
        let mut times = vec![f64::INFINITY; n];
        let mut x = seed;
        let mut now = 0.0;
        for step in 0..steps {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let i = match q.first() {
                Some((first, t)) if step % 3 != 0 => {
                    now = t;
                    first
                }
                _ => (x >> 33) as usize % n,
            };
            // Many ties, some far enough ahead for the overflow, some never.
            let t = match (x >> 20) % 16 {
                0 => f64::INFINITY,
                1 => now + ((x >> 11) % (spread * 40)) as f64,
                _ => now + ((x >> 11) % spread) as f64,
            };
            q.set(i, t);
            times[i] = t;
            assert_eq!(q.first(), earliest(&times), "step {step}");
        }
    }

    #[test]
    fn pops_in_time_order_through_any_sequence_of_updates() {
        replay(37, 20_000, 50, 12345);
        replay(1, 1000, 3, 7);
        replay(500, 20_000, 5000, 99);
    }

    #[test]
    fn a_queue_rebuilt_from_its_times_pops_in_the_same_order() {
        let mut q = EventQueue::new(5);
        for (i, t) in [(3, 1.0), (1, 1.0), (4, 0.5), (0, 7.0), (4, 2.0)] {
            q.set(i, t);
        }
        let times = q.times();
        assert_eq!(times, [7.0, 1.0, f64::INFINITY, 1.0, 2.0]);
        let mut again = EventQueue::with_times(&times);
        for (i, t) in [(1, 1.0), (3, 1.0), (4, 2.0), (0, 7.0)] {
            assert_eq!(again.first(), Some((i, t)));
            assert_eq!(q.first(), Some((i, t)));
            again.set(i, f64::INFINITY);
            q.set(i, f64::INFINITY);
        }
        assert_eq!(again.first(), None);
    }

    #[test]
    fn an_empty_queue_has_no_first() {
        assert_eq!(EventQueue::new(0).first(), None);
        assert_eq!(EventQueue::new(3).first(), None);
    }

    #[test]
    fn times_that_cannot_be_blocked_still_pop_in_order() {
        // Before the origin, far beyond any block and all at one time.
        let mut q = EventQueue::with_times(&[5.0, 5.0, 5.0]);
        q.set(1, 1e300);
        q.set(2, -1.0);
        assert_eq!(q.first(), Some((2, -1.0)));
        q.set(2, f64::INFINITY);
        assert_eq!(q.first(), Some((0, 5.0)));
        q.set(0, f64::INFINITY);
        assert_eq!(q.first(), Some((1, 1e300)));
    }
}
