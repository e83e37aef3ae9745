//! A straight-line scan's pair times in AVX2: the neighbours' motions are copied side by side as
//! the cells list them, a batch at a time, then their pair times are worked out four at a time
//! (one register per quantity) and the soonest kept in the order they were found. Each
//! operation is the one [`EventEngine::look_at`] does for one pair (no fused multiply-add; its
//! branches as masks), so the two give the same bits. A small circle's full prediction takes
//! this path when circles fly straight lines (no gravity), radii do not grow and a pair is
//! looked at through its nearest image only, where the processor has AVX2 and
//! [`crate::base::vector::allow`] lets it; `look_at` one by one elsewhere (and for a crossing's look
//! at the three cells it newly borders, cheaper so, and a large circle's look).
//! Rounding half away from zero, as `f64::round`, is the truncation plus one more where the
//! part cut off is half or more (both exact).

use std::arch::x86_64::{
    __m256d, _CMP_GE_OQ, _CMP_GT_OQ, _CMP_LE_OQ, _CMP_LT_OQ, _CMP_NGE_UQ, _CMP_NLT_UQ,
    _MM_FROUND_NO_EXC, _MM_FROUND_TO_ZERO, _mm256_add_pd, _mm256_and_pd, _mm256_andnot_pd,
    _mm256_blendv_pd, _mm256_cmp_pd, _mm256_div_pd, _mm256_loadu_pd, _mm256_max_pd,
    _mm256_movemask_pd, _mm256_mul_pd, _mm256_or_pd, _mm256_round_pd, _mm256_set1_pd,
    _mm256_setzero_pd, _mm256_sqrt_pd, _mm256_storeu_pd, _mm256_sub_pd, _mm256_xor_pd,
};

use super::EventEngine;
use super::events::{BestPair, Frame, Motion, NO_PAIR};

/// Neighbours in one batch: enough to fill the vector lanes a few times over, few enough to
/// stay near in the cache.
const BATCH: usize = 16;

/// Room for a batch of neighbours, their motions side by side (a field each), and their pair
/// times once worked out. The engine keeps one from scan to scan, so that it is made once.
#[derive(Clone, Debug)]
pub(super) struct Batch {
    index: [u32; BATCH],
    x: [f64; BATCH],
    y: [f64; BATCH],
    vx: [f64; BATCH],
    vy: [f64; BATCH],
    t_at: [f64; BATCH],
    radius: [f64; BATCH],
    time: [f64; BATCH],
}

impl Default for Batch {
    fn default() -> Self {
        let zero = [0.0; BATCH];
        Self {
            index: [0; BATCH],
            x: zero,
            y: zero,
            vx: zero,
            vy: zero,
            t_at: zero,
            radius: zero,
            time: zero,
        }
    }
}

impl Batch {
    #[inline(always)]
    fn set(&mut self, k: usize, j: usize, m: &Motion) {
        self.index[k] = j as u32;
        (self.x[k], self.y[k], self.vx[k], self.vy[k]) = (m.pos.x, m.pos.y, m.vel.x, m.vel.y);
        (self.t_at[k], self.radius[k]) = (m.t_at, m.radius);
    }
}

impl EventEngine {
    /// [`EventEngine::scan`] for circles on straight lines whose radii do not grow, through the
    /// nearest image only, with `batch` for room.
    ///
    /// # Safety
    ///
    /// The processor must have AVX2.
    pub(super) unsafe fn scan_straight(
        &self,
        i: usize,
        cells: impl IntoIterator<Item = usize>,
        batch: &mut Batch,
    ) -> BestPair {
        let (me, frame) = (self.motion[i], self.frame());
        let settle = |batch: &mut Batch, len: usize, best: &mut BestPair| {
            // SAFETY: the processor has AVX2, as the caller promises.
            unsafe { times(&me, frame, batch, len) };
            for k in 0..len {
                if batch.time[k] < best.time {
                    let j = batch.index[k];
                    *best = BestPair {
                        time: batch.time[k],
                        partner: j,
                        partner_count: self.counter[j as usize],
                    };
                }
            }
        };
        let meets = self.meeting(i);
        let (mut len, mut best) = (0, NO_PAIR);
        let mut take = |j: usize| {
            if j != i && meets(j) {
                batch.set(len, j, &self.motion[j]);
                len += 1;
                if len == BATCH {
                    settle(batch, len, &mut best);
                    len = 0;
                }
            }
        };
        // Nested loops, not one chained iterator: that one checks which part it is in at
        // every neighbour.
        for c in cells {
            for j in self.cells.members(c) {
                take(j);
            }
        }
        for &j in &self.large {
            take(j as usize);
        }
        settle(batch, len, &mut best);
        best
    }
}

/// The first `len` of the batch's pair times with `me` (infinite where a pair does not meet), by
/// whole fours: the lanes past `len` hold what an earlier batch left there (or zeros), worked
/// out like the others (no floating-point trap is enabled) and not read.
#[target_feature(enable = "avx2")]
fn times(me: &Motion, frame: Frame, batch: &mut Batch, len: usize) {
    let splat = _mm256_set1_pd;
    let (mx, my, mvx, mvy) = (
        splat(me.pos.x),
        splat(me.pos.y),
        splat(me.vel.x),
        splat(me.vel.y),
    );
    let (mt, mr, now) = (splat(me.t_at), splat(me.radius), splat(frame.now));
    let zero = _mm256_setzero_pd();
    let sign = splat(-0.0);
    let infinity = splat(f64::INFINITY);
    for k in (0..len).step_by(4) {
        let load = |field: &[f64; BATCH]| {
            let four = &field[k..k + 4];
            // SAFETY: `four` holds the four f64 the load reads.
            unsafe { _mm256_loadu_pd(four.as_ptr()) }
        };
        let (ox, oy, ovx, ovy) = (
            load(&batch.x),
            load(&batch.y),
            load(&batch.vx),
            load(&batch.vy),
        );
        let (ot, or) = (load(&batch.t_at), load(&batch.radius));
        // `a.max(b)` is `b` where `b > a`, else `a`; `_mm256_max_pd(b, a)` the same, to the
        // zero's sign when the two are equal.
        let since = _mm256_max_pd(ot, mt);
        // `other.at(since) - me.at(since)`, axis by axis.
        let at = |p, v, t| _mm256_add_pd(p, _mm256_mul_pd(v, _mm256_sub_pd(since, t)));
        let mut dpx = _mm256_sub_pd(at(ox, ovx, ot), at(mx, mvx, mt));
        let mut dpy = _mm256_sub_pd(at(oy, ovy, ot), at(my, mvy, mt));
        let dvx = _mm256_sub_pd(ovx, mvx);
        let dvy = _mm256_sub_pd(ovy, mvy);
        if let Some(period) = frame.period {
            let ahead = _mm256_sub_pd(now, since);
            let wx = _mm256_add_pd(dpx, _mm256_mul_pd(dvx, ahead));
            let wy = _mm256_add_pd(dpy, _mm256_mul_pd(dvy, ahead));
            let far = |w, period: f64| {
                let half = splat(0.5 * period);
                _mm256_cmp_pd::<_CMP_GT_OQ>(_mm256_andnot_pd(sign, w), half)
            };
            let (far_x, far_y) = (far(wx, period.x), far(wy, period.y));
            // Lanes within half a period take no period off (`dp - 0·period` is `dp`): when
            // all are, as near the arena's seams only some are not, the rounding is skipped.
            if _mm256_movemask_pd(_mm256_or_pd(far_x, far_y)) != 0 {
                let off = |w, far, period: f64| {
                    _mm256_mul_pd(splat(period), _mm256_and_pd(far, whole(w, period, sign)))
                };
                dpx = _mm256_sub_pd(dpx, off(wx, far_x, period.x));
                dpy = _mm256_sub_pd(dpy, off(wy, far_y, period.y));
            }
        }
        let sum = _mm256_add_pd(mr, or);
        let dot = |ax, ay, bx, by| _mm256_add_pd(_mm256_mul_pd(ax, bx), _mm256_mul_pd(ay, by));
        let b = dot(dpx, dpy, dvx, dvy);
        let a = dot(dvx, dvy, dvx, dvy);
        let c = _mm256_sub_pd(dot(dpx, dpy, dpx, dpy), _mm256_mul_pd(sum, sum));
        // `a·σ² - (dp × dv)²`, as `pair_time_of_impact` takes it.
        let cross = _mm256_sub_pd(_mm256_mul_pd(dpx, dvy), _mm256_mul_pd(dpy, dvx));
        let disc = _mm256_sub_pd(
            _mm256_mul_pd(a, _mm256_mul_pd(sum, sum)),
            _mm256_mul_pd(cross, cross),
        );
        let root = _mm256_add_pd(_mm256_xor_pd(b, sign), _mm256_sqrt_pd(disc));
        let t = _mm256_div_pd(c, root);
        // `pair_time_of_impact`'s branches: none if `b >= 0`; else 0 if `c <= 0`; else none if
        // `disc < 0`; else `t` if finite.
        let closing = _mm256_cmp_pd::<_CMP_NGE_UQ>(b, zero);
        let touching = _mm256_cmp_pd::<_CMP_LE_OQ>(c, zero);
        let meets = _mm256_and_pd(
            _mm256_cmp_pd::<_CMP_NLT_UQ>(disc, zero),
            _mm256_cmp_pd::<_CMP_LT_OQ>(_mm256_andnot_pd(sign, t), infinity),
        );
        let valid = _mm256_and_pd(closing, _mm256_or_pd(touching, meets));
        // `t.max(0.0)`: `t` is not below +0 here (`c > 0`, `-b > 0`).
        let t = _mm256_blendv_pd(t, zero, touching);
        let time = _mm256_max_pd(now, _mm256_add_pd(since, t));
        let time = _mm256_blendv_pd(infinity, time, valid);
        let four = &mut batch.time[k..k + 4];
        // SAFETY: `four` has room for the four f64 the store writes.
        unsafe { _mm256_storeu_pd(four.as_mut_ptr(), time) };
    }
}

/// `f64::round` of `d / period`, four lanes at once: the truncation, plus one more away from
/// zero where the part cut off is half or more.
#[inline]
#[target_feature(enable = "avx2")]
fn whole(d: __m256d, period: f64, sign: __m256d) -> __m256d {
    let q = _mm256_div_pd(d, _mm256_set1_pd(period));
    let cut = _mm256_round_pd::<{ _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC }>(q);
    let half_or_more = _mm256_cmp_pd::<_CMP_GE_OQ>(
        _mm256_andnot_pd(sign, _mm256_sub_pd(q, cut)),
        _mm256_set1_pd(0.5),
    );
    // ±1 with the sign of `q`.
    let one = _mm256_or_pd(_mm256_and_pd(sign, q), _mm256_set1_pd(1.0));
    _mm256_add_pd(cut, _mm256_and_pd(half_or_more, one))
}

#[cfg(test)]
mod tests {
    use bevy::math::DVec2;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::base::arena::{Arena, Boundary};
    use crate::base::circle::CircleState;

    /// Motions that try the kernel's every branch: pairs closing, parting, missing, touching
    /// and overlapping, at rest against each other, references times apart, displacements of
    /// whole and half periods (rounding ties) and far beyond, speeds across twelve decades.
    /// `now` is 2.
    fn hard_motions(rng: &mut ChaCha8Rng, period: f64) -> Vec<Motion> {
        let mut motions = Vec::new();
        for k in 0..400 {
            let scale = 10f64.powi(rng.random_range(-6..6));
            let pos = DVec2::new(rng.random_range(-2.0..3.0), rng.random_range(-2.0..3.0));
            let vel = match k % 7 {
                0 => DVec2::ZERO,
                _ => DVec2::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)) * scale,
            };
            let t_at = if k % 3 == 0 {
                0.0
            } else {
                rng.random_range(0.0..2.0)
            };
            let radius = [0.01, 0.2, 0.6][k % 3];
            motions.push(Motion {
                pos,
                vel,
                t_at,
                radius,
            });
        }
        // The first at rest at (0, ¼) now; every fifth exactly ±1½ or ±2½ periods from it along
        // x (past half a period, so rounded), flying along x, its reference time now too: a
        // rounding tie that decides whether they meet, as `f64::round` takes ±2½ away from zero
        // and ties to even would not.
        motions[0] = Motion {
            pos: DVec2::new(0.0, 0.25),
            vel: DVec2::ZERO,
            t_at: 2.0,
            radius: 0.1,
        };
        for k in (5..400).step_by(5) {
            let n = [-3.0, -2.0, 1.0, 2.0][rng.random_range(0..4)];
            motions[k].pos = DVec2::new((n + 0.5) * period, 0.25);
            motions[k].vel = DVec2::new(if k % 10 == 0 { 1.0 } else { -1.0 }, 0.0);
            motions[k].t_at = 2.0;
        }
        motions[1].pos = motions[0].pos; // overlapping, at the same point
        motions[2].pos = motions[0].pos + DVec2::new(motions[0].radius + motions[2].radius, 0.0);
        motions
    }

    #[test]
    fn the_vector_pair_times_are_the_pairs_one_by_one_bit_for_bit() {
        if !std::is_x86_feature_detected!("avx2") {
            eprintln!("no AVX2 here: nothing to compare");
            return;
        }
        let mut rng = ChaCha8Rng::seed_from_u64(29);
        for boundary in [Boundary::Walls, Boundary::Periodic] {
            let arena = Arena::unit_square(boundary);
            let circles: Vec<_> = (0..400)
                .map(|k| CircleState::new(DVec2::splat(0.5 + k as f64 * 1e-3), DVec2::ZERO, 1e-4))
                .collect();
            let mut engine = EventEngine::new(&circles, &arena, &[], 1.0, 1.0);
            engine.motion = hard_motions(&mut rng, 1.0);
            engine.now = 2.0;
            let frame = engine.frame();
            let mut batch = Batch::default();
            let (mut met, mut tested) = (0, 0);
            for i in 0..40 {
                let me = engine.motion[i];
                for start in (0..engine.len()).step_by(BATCH) {
                    let others: Vec<usize> = (start..engine.len().min(start + BATCH)).collect();
                    for (k, &j) in others.iter().enumerate() {
                        batch.set(k, j, &engine.motion[j]);
                    }
                    // SAFETY: the processor has AVX2 (asked above).
                    unsafe { times(&me, frame, &mut batch, others.len()) };
                    for (k, &j) in others.iter().enumerate() {
                        let mut alone = NO_PAIR;
                        let nearest = |d| engine.nearest_image(d);
                        engine.look_at::<false>(&me, j, nearest, &mut alone);
                        let (wide, one) = (batch.time[k], alone.time);
                        assert!(
                            wide.to_bits() == one.to_bits(),
                            "{boundary:?}: pair {i}, {j}: {wide:e} against {one:e} one by one"
                        );
                        met += usize::from(one.is_finite());
                        tested += 1;
                    }
                }
            }
            // Both ways of the branches were taken: many pairs meet, many do not.
            assert!(
                met > tested / 20 && met < tested * 9 / 10,
                "{boundary:?}: {met} of {tested}"
            );
        }
    }
}
