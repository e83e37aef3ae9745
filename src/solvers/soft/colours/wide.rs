//! The groups' passes in AVX2: the four lanes of a group in one register per quantity, each
//! operation the one [`super::each_group`] does lane by lane (no fused multiply-add; a max and
//! a select as `larger` and `if` have them), so the two give the same bits.

use std::arch::x86_64::{
    __m256d, _CMP_GT_OQ, _mm_cvtsd_f64, _mm_set_pd, _mm_unpackhi_pd, _mm256_add_pd,
    _mm256_blendv_pd, _mm256_castpd256_pd128, _mm256_cmp_pd, _mm256_extractf128_pd,
    _mm256_loadu_pd, _mm256_max_pd, _mm256_mul_pd, _mm256_set_m128d, _mm256_set1_pd,
    _mm256_setzero_pd, _mm256_storeu_pd, _mm256_sub_pd, _mm256_unpackhi_pd, _mm256_unpacklo_pd,
    _mm256_xor_pd,
};

use bevy::math::DVec2;

use super::{Colours, Group, LANES, Pass, immovable_work};
use crate::solvers::soft::stats::Work;

/// [`super::passes`] for a processor with AVX2.
#[target_feature(enable = "avx2")]
pub fn passes(
    colours: &mut Colours,
    position: &[DVec2],
    velocity: &mut [DVec2],
    pass: Pass,
    work: &mut Work,
) {
    for g in colours.groups_mut().flatten() {
        if g.live[LANES - 1] {
            each_group(g, position, velocity, pass, work);
        } else {
            // A colour's last group, not full: lane by lane.
            super::each_group(g, position, velocity, pass, work);
        }
    }
}

/// A group's field, its four lanes in one register.
#[inline]
#[target_feature(enable = "avx2")]
fn load(field: &[f64; LANES]) -> __m256d {
    // SAFETY: `field` holds the four f64 the load reads.
    unsafe { _mm256_loadu_pd(field.as_ptr()) }
}

/// A register's four lanes into `field`.
#[inline]
#[target_feature(enable = "avx2")]
fn store(field: &mut [f64; LANES], v: __m256d) {
    // SAFETY: `field` has room for the four f64 the store writes.
    unsafe { _mm256_storeu_pd(field.as_mut_ptr(), v) }
}

/// The x and y of `of[index[l]]` for the four lanes, each in a register.
#[inline]
#[target_feature(enable = "avx2")]
fn gather(of: &[DVec2], index: &[u32; LANES]) -> (__m256d, __m256d) {
    let pair = |l: usize| {
        let p = of[index[l] as usize];
        _mm_set_pd(p.y, p.x)
    };
    // (x0 y0 x2 y2) and (x1 y1 x3 y3), interleaved into (x0 x1 x2 x3) and (y0 y1 y2 y3).
    let even = _mm256_set_m128d(pair(2), pair(0));
    let odd = _mm256_set_m128d(pair(3), pair(1));
    (_mm256_unpacklo_pd(even, odd), _mm256_unpackhi_pd(even, odd))
}

/// One full group, as [`super::each_group`].
#[inline]
#[target_feature(enable = "avx2")]
fn each_group(
    g: &mut Group,
    position: &[DVec2],
    velocity: &mut [DVec2],
    pass: Pass,
    work: &mut Work,
) {
    let zero = _mm256_setzero_pd();
    let sign = _mm256_set1_pd(-0.0);
    let (mut vax, mut vay) = gather(velocity, &g.a);
    let (mut vbx, mut vby) = gather(velocity, &g.b);
    let (nx, ny) = (load(&g.normal_x), load(&g.normal_y));
    let impulse = load(&g.impulse);
    let j = match pass {
        Pass::WarmStart => _mm256_max_pd(impulse, zero),
        Pass::Solve { inv_h, bias } => {
            let (pax, pay) = gather(position, &g.a);
            let (pbx, pby) = gather(position, &g.b);
            let dx = _mm256_sub_pd(_mm256_add_pd(pbx, load(&g.anchor_x)), pax);
            let dy = _mm256_sub_pd(_mm256_add_pd(pby, load(&g.anchor_y)), pay);
            let s = _mm256_sub_pd(
                _mm256_add_pd(_mm256_mul_pd(dx, nx), _mm256_mul_pd(dy, ny)),
                load(&g.reach),
            );
            let (soft_bias, mass_scale, impulse_scale) = if bias {
                let push = _mm256_xor_pd(load(&g.push), sign);
                (
                    _mm256_max_pd(_mm256_mul_pd(load(&g.bias_rate), s), push),
                    load(&g.mass_scale),
                    load(&g.impulse_scale),
                )
            } else {
                (zero, _mm256_set1_pd(1.0), zero)
            };
            let open = _mm256_cmp_pd::<_CMP_GT_OQ>(s, zero);
            let b = _mm256_blendv_pd(soft_bias, _mm256_mul_pd(s, _mm256_set1_pd(inv_h)), open);
            let mass_scale = _mm256_blendv_pd(mass_scale, _mm256_set1_pd(1.0), open);
            let impulse_scale = _mm256_blendv_pd(impulse_scale, zero, open);
            let vn = _mm256_add_pd(
                _mm256_mul_pd(_mm256_sub_pd(vbx, vax), nx),
                _mm256_mul_pd(_mm256_sub_pd(vby, vay), ny),
            );
            let approach = _mm256_max_pd(_mm256_xor_pd(vn, sign), load(&g.approach));
            store(&mut g.approach, approach);
            let minus_mass = _mm256_xor_pd(load(&g.normal_mass), sign);
            let step = _mm256_sub_pd(
                _mm256_mul_pd(_mm256_mul_pd(minus_mass, mass_scale), _mm256_add_pd(vn, b)),
                _mm256_mul_pd(impulse_scale, impulse),
            );
            let total = _mm256_max_pd(_mm256_add_pd(impulse, step), zero);
            store(&mut g.impulse, total);
            _mm256_sub_pd(total, impulse)
        }
    };
    let total_impulse = _mm256_add_pd(load(&g.total_impulse), j);
    store(&mut g.total_impulse, total_impulse);
    let (px, py) = (_mm256_mul_pd(nx, j), _mm256_mul_pd(ny, j));
    let (wa, wb) = (load(&g.inv_mass_a), load(&g.inv_mass_b));
    vax = _mm256_sub_pd(vax, _mm256_mul_pd(px, wa));
    vay = _mm256_sub_pd(vay, _mm256_mul_pd(py, wa));
    vbx = _mm256_add_pd(vbx, _mm256_mul_pd(px, wb));
    vby = _mm256_add_pd(vby, _mm256_mul_pd(py, wb));
    if g.immovable.contains(&true) {
        let (mut x, mut y) = ([0.0; LANES], [0.0; LANES]);
        store(&mut x, px);
        store(&mut y, py);
        immovable_work(g, velocity, [x, y], work);
    }
    scatter(velocity, &g.a, (vax, vay));
    scatter(velocity, &g.b, (vbx, vby));
}

/// Writes the four lanes' new velocities `(x, y)` to the circles at `index` (a full group's,
/// all live; an immovable circle gets its own velocity back, as [`super::each_group`] writes it).
#[inline]
#[target_feature(enable = "avx2")]
fn scatter(velocity: &mut [DVec2], index: &[u32; LANES], (x, y): (__m256d, __m256d)) {
    // (x0 y0 x2 y2) and (x1 y1 x3 y3): each lane's velocity in one half.
    let (even, odd) = (_mm256_unpacklo_pd(x, y), _mm256_unpackhi_pd(x, y));
    let halves = [
        _mm256_castpd256_pd128(even),
        _mm256_castpd256_pd128(odd),
        _mm256_extractf128_pd::<1>(even),
        _mm256_extractf128_pd::<1>(odd),
    ];
    for (l, half) in halves.into_iter().enumerate() {
        let v = DVec2::new(
            _mm_cvtsd_f64(half),
            _mm_cvtsd_f64(_mm_unpackhi_pd(half, half)),
        );
        velocity[index[l] as usize] = v;
    }
}
