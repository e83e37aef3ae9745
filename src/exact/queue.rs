//! The event engine's priority queue: a tournament tree holding exactly one time per circle.
//! Changing a circle's time replays at most log₂ N matches on its path to the root, and usually
//! stops much earlier, so the queue never fills with superseded events and never has to skip
//! them when popping. (The std `BinaryHeap` cannot change a key; the indexed-queue crates go
//! through a hash map, which costs more than a whole event here; an indexed 4-ary heap measured
//! about 5 % slower on the 10k gas. Inner nodes hold circle indices, four bytes, beside one
//! array of times: 3-4 % faster on the 10k gases than nodes of 16-byte `(time, circle)` pairs;
//! replaying the whole path without the early stop, or a select without a branch, was not.)
//!
//! Ties are broken by circle index, so the order never depends on the history of updates.

/// Min-queue of `(time, circle)` with one entry per circle.
#[derive(Clone, Debug, Default)]
pub struct EventQueue {
    /// Each circle's time (`+∞` for the padding past the last circle).
    time: Vec<f64>,
    /// Complete binary tree in an array of circle indices: leaves at `leaves..2·leaves`
    /// (circle `i` at `leaves + i`), each inner node `k` holding the earlier of the winners of
    /// its children `2k` and `2k + 1`, so node 1 holds the earliest of all. Four bytes a node,
    /// so the tree of 16 384 circles fits in 128 KiB.
    node: Vec<u32>,
    leaves: usize,
    /// Circles (the rest of the leaves are padding).
    len: usize,
}

impl EventQueue {
    /// A queue of `n` circles, all at time `+∞`.
    pub fn new(n: usize) -> Self {
        let leaves = n.next_power_of_two().max(2);
        let mut queue = Self {
            time: vec![f64::INFINITY; leaves],
            node: (0..2 * leaves)
                .map(|k| k.saturating_sub(leaves) as u32)
                .collect(),
            leaves,
            len: n,
        };
        for k in (1..leaves).rev() {
            queue.node[k] = queue.winner(k);
        }
        queue
    }

    /// The earlier of the winners of node `k`'s children. The left child's circles all have
    /// smaller indices than the right one's, so a tie goes left: to the smaller index.
    #[inline(always)]
    fn winner(&self, k: usize) -> u32 {
        let (left, right) = (self.node[2 * k], self.node[2 * k + 1]);
        if self.time[right as usize] < self.time[left as usize] {
            right
        } else {
            left
        }
    }

    /// The circle with the earliest time, and that time.
    #[inline]
    pub fn first(&self) -> Option<(usize, f64)> {
        let top = self.node[1] as usize;
        (top < self.len).then(|| (top, self.time[top]))
    }

    /// Every circle's time, in circle order.
    pub fn times(&self) -> Vec<f64> {
        self.time[..self.len].to_vec()
    }

    /// A queue holding `times` (one per circle). Each inner node is a function of the leaves
    /// under it alone, so this is the very queue whose [`times`](Self::times) these were.
    pub fn with_times(times: &[f64]) -> Self {
        let mut queue = Self::new(times.len());
        for (i, &time) in times.iter().enumerate() {
            queue.set(i, time);
        }
        queue
    }

    /// Sets circle `i`'s time and replays the matches on its path to the root, stopping where
    /// a node's winner is another circle than before or after (the times above it are then
    /// unchanged).
    pub fn set(&mut self, i: usize, time: f64) {
        self.time[i] = time;
        let mut k = (self.leaves + i) / 2;
        while k >= 1 {
            let (was, now) = (self.node[k], self.winner(k));
            if was == now && now != i as u32 {
                break;
            }
            self.node[k] = now;
            k /= 2;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pops_in_time_order_through_any_sequence_of_updates() {
        // A fixed pseudo-random sequence of updates, checked against a sort after each one.
        let n = 37;
        let mut q = EventQueue::new(n);
        let mut times = vec![f64::INFINITY; n];
        let mut x: u64 = 12345;
        for _ in 0..2000 {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let i = (x >> 33) as usize % n;
            let t = ((x >> 11) % 50) as f64; // many ties
            q.set(i, t);
            times[i] = t;
            let want = (0..n)
                .min_by(|&a, &b| times[a].total_cmp(&times[b]).then(a.cmp(&b)))
                .unwrap();
            assert_eq!(q.first(), Some((want, times[want])));
        }
    }

    #[test]
    fn a_queue_rebuilt_from_its_times_is_the_same_queue() {
        let mut q = EventQueue::new(5);
        for (i, t) in [(3, 1.0), (1, 1.0), (4, 0.5), (0, 7.0), (4, 2.0)] {
            q.set(i, t);
        }
        let times = q.times();
        assert_eq!(times.len(), 5);
        let again = EventQueue::with_times(&times);
        assert_eq!((&again.node, &again.time), (&q.node, &q.time));
        assert_eq!(again.first(), Some((1, 1.0)));
    }

    #[test]
    fn an_empty_queue_has_no_first() {
        assert_eq!(EventQueue::new(0).first(), None);
    }
}
