//! A frictionless step's pair contacts solved colour by colour, four at a time: contacts are
//! coloured greedily in their order (no two of a colour move the same circle), each colour cut
//! into groups of four, and a pass solves group after group. The four contacts of a group
//! share no movable circle, so they are worked out side by side: in AVX2 vector instructions
//! where the processor has them (`wide`), else lane by lane, with the same operations in the same
//! order (no fused multiply-add), so both give the same result bit for bit (a test compares
//! them). Contacts that find no colour free (more than [`MAX_COLOURS`] around one circle) are
//! solved after the groups, one by one.
//!
//! The colours change the order of the Gauss-Seidel passes from the broad phase's, and with it
//! how fast a pile settles (measured in `docs/piles.md`).

use bevy::math::DVec2;

use super::contacts::{Constraint, larger};
use super::stats::Work;

#[cfg(target_arch = "x86_64")]
mod wide;

/// Contacts solved side by side.
pub const LANES: usize = 4;

/// Most colours (a bit each in a circle's mask).
pub const MAX_COLOURS: u32 = 64;

/// Four contacts of one colour, field by field (a lane each); a lane past the colour's end is
/// empty (`live` false) and writes nothing. Only a colour's last group can have empty lanes.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(32))]
struct Group {
    /// Each lane's contact, as its index in the step's pairs.
    contact: [u32; LANES],
    live: [bool; LANES],
    a: [u32; LANES],
    b: [u32; LANES],
    normal_x: [f64; LANES],
    normal_y: [f64; LANES],
    anchor_x: [f64; LANES],
    anchor_y: [f64; LANES],
    reach: [f64; LANES],
    inv_mass_a: [f64; LANES],
    inv_mass_b: [f64; LANES],
    normal_mass: [f64; LANES],
    bias_rate: [f64; LANES],
    mass_scale: [f64; LANES],
    impulse_scale: [f64; LANES],
    push: [f64; LANES],
    impulse: [f64; LANES],
    total_impulse: [f64; LANES],
    approach: [f64; LANES],
    /// Whether one side is immovable (its work is counted); false for an empty lane.
    immovable: [bool; LANES],
}

/// The step's pairs in colour order: each colour's groups, then what found no colour.
#[derive(Default)]
pub struct Colours {
    /// Each colour's groups of four (more than this step's, kept for the next).
    groups: Vec<Vec<Group>>,
    /// How many pairs each colour has this step.
    counts: Vec<u32>,
    /// Pairs that found no colour free, by index, in their order.
    pub rest: Vec<u32>,
    masks: Vec<u64>,
}

impl Colours {
    /// Colours `pairs` between `circles` circles greedily in their order (a contact takes the
    /// first colour neither of its movable circles has yet) and packs them into groups, in one
    /// pass over the pairs.
    pub fn pack(&mut self, circles: usize, pairs: &[Constraint]) {
        self.masks.clear();
        self.masks.resize(circles, 0);
        self.rest.clear();
        self.groups.resize_with(MAX_COLOURS as usize, Vec::new);
        self.counts.clear();
        self.counts.resize(MAX_COLOURS as usize, 0);
        for (k, c) in pairs.iter().enumerate() {
            let (a, b) = (c.a as usize, c.b as usize);
            let (wa, wb) = c.inv_mass;
            let mine = |w: f64, i: usize| if w > 0.0 { self.masks[i] } else { 0 };
            let colour = (!(mine(wa, a) | mine(wb, b))).trailing_zeros();
            if colour >= MAX_COLOURS {
                self.rest.push(k as u32);
                continue;
            }
            for (w, i) in [(wa, a), (wb, b)] {
                if w > 0.0 {
                    self.masks[i] |= 1 << colour;
                }
            }
            // Groups are filled over last step's: only the lanes past a colour's end are
            // emptied, below.
            let (groups, count) = (
                &mut self.groups[colour as usize],
                &mut self.counts[colour as usize],
            );
            let (group, lane) = (*count as usize / LANES, *count as usize % LANES);
            if group == groups.len() {
                groups.push(Group::default());
            }
            fill(&mut groups[group], lane, k, c);
            *count += 1;
        }
        for (groups, &n) in self.groups.iter_mut().zip(&self.counts) {
            let used = n as usize % LANES;
            if used > 0 {
                let last = &mut groups[n as usize / LANES];
                last.live[used..].fill(false);
                last.immovable[used..].fill(false);
                // An empty lane still reads a circle: circle 0, which a step with pairs has.
                last.a[used..].fill(0);
                last.b[used..].fill(0);
            }
        }
    }

    /// This step's groups of each colour, colour after colour.
    fn groups_mut(&mut self) -> impl Iterator<Item = &mut [Group]> {
        let each = self.groups.iter_mut().zip(&self.counts);
        each.map(|(groups, &n)| &mut groups[..(n as usize).div_ceil(LANES)])
    }

    /// This step's groups, colour after colour.
    fn groups(&self) -> impl Iterator<Item = &Group> {
        let each = self.groups.iter().zip(&self.counts);
        each.flat_map(|(groups, &n)| &groups[..(n as usize).div_ceil(LANES)])
    }

    /// Writes the groups' impulses back into `pairs`.
    pub fn unpack(&self, pairs: &mut [Constraint]) {
        for g in self.groups() {
            for l in 0..LANES {
                if g.live[l] {
                    let c = &mut pairs[g.contact[l] as usize];
                    c.impulse = g.impulse[l];
                    c.total_impulse = g.total_impulse[l];
                    c.approach = g.approach[l];
                }
            }
        }
    }
}

/// Puts pair `k`, contact `c`, in lane `l` of group `g`.
#[inline]
fn fill(g: &mut Group, l: usize, k: usize, c: &Constraint) {
    g.contact[l] = k as u32;
    g.live[l] = true;
    (g.a[l], g.b[l]) = (c.a, c.b);
    (g.normal_x[l], g.normal_y[l]) = (c.normal.x, c.normal.y);
    (g.anchor_x[l], g.anchor_y[l]) = (c.anchor.x, c.anchor.y);
    g.reach[l] = c.reach;
    (g.inv_mass_a[l], g.inv_mass_b[l]) = c.inv_mass;
    g.normal_mass[l] = c.normal_mass;
    g.bias_rate[l] = c.soft.bias_rate;
    g.mass_scale[l] = c.soft.mass_scale;
    g.impulse_scale[l] = c.soft.impulse_scale;
    g.push[l] = c.push;
    g.impulse[l] = c.impulse;
    g.total_impulse[l] = c.total_impulse;
    g.approach[l] = c.approach;
    g.immovable[l] = c.inv_mass.0 == 0.0 || c.inv_mass.1 == 0.0;
}

/// What a pass over the groups does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pass {
    /// Applies each contact's impulse again.
    WarmStart,
    /// Solves each contact, with its soft push-out if `bias`.
    Solve {
        /// One over the substep.
        inv_h: f64,
        /// Whether an overlap is pushed out (else the relax pass).
        bias: bool,
    },
}

/// One pass over the groups of `colours`, colour after colour, on circles at `position` moving
/// at `velocity`: with AVX2 where the processor has it (and [`crate::base::vector::allow`] lets it),
/// else lane by lane; the same result either way.
pub fn passes(
    colours: &mut Colours,
    position: &[DVec2],
    velocity: &mut [DVec2],
    pass: Pass,
    work: &mut Work,
) {
    #[cfg(target_arch = "x86_64")]
    if crate::base::vector::avx2() {
        // SAFETY: the processor has AVX2, all that `wide::passes` asks of it.
        return unsafe { wide::passes(colours, position, velocity, pass, work) };
    }
    passes_by_lane(colours, position, velocity, pass, work);
}

/// [`passes`] lane by lane: what any processor runs.
fn passes_by_lane(
    colours: &mut Colours,
    position: &[DVec2],
    velocity: &mut [DVec2],
    pass: Pass,
    work: &mut Work,
) {
    for g in colours.groups_mut().flatten() {
        each_group(g, position, velocity, pass, work);
    }
}

/// One group: gather its circles, work out its four impulses lane by lane, scatter.
// Lane `l` of a dozen arrays at once reads clearest as an index.
#[allow(clippy::needless_range_loop)]
fn each_group(
    g: &mut Group,
    position: &[DVec2],
    velocity: &mut [DVec2],
    pass: Pass,
    work: &mut Work,
) {
    let zero = [0.0; LANES];
    let (mut vax, mut vay, mut vbx, mut vby) = (zero, zero, zero, zero);
    for l in 0..LANES {
        let (va, vb) = (velocity[g.a[l] as usize], velocity[g.b[l] as usize]);
        (vax[l], vay[l], vbx[l], vby[l]) = (va.x, va.y, vb.x, vb.y);
    }
    let mut j = zero;
    match pass {
        Pass::WarmStart => {
            for l in 0..LANES {
                j[l] = larger(g.impulse[l], 0.0);
            }
        }
        Pass::Solve { inv_h, bias } => {
            let (mut pax, mut pay, mut pbx, mut pby) = (zero, zero, zero, zero);
            for l in 0..LANES {
                let (pa, pb) = (position[g.a[l] as usize], position[g.b[l] as usize]);
                (pax[l], pay[l], pbx[l], pby[l]) = (pa.x, pa.y, pb.x, pb.y);
            }
            for l in 0..LANES {
                let dx = pbx[l] + g.anchor_x[l] - pax[l];
                let dy = pby[l] + g.anchor_y[l] - pay[l];
                let s = dx * g.normal_x[l] + dy * g.normal_y[l] - g.reach[l];
                // A gap still open: approach by as much as closes it; an overlap: pushed out
                // softly with the bias, else (relax) held rigidly.
                let soft_bias = if bias {
                    larger(g.bias_rate[l] * s, -g.push[l])
                } else {
                    0.0
                };
                let (mass_scale, impulse_scale) = if bias {
                    (g.mass_scale[l], g.impulse_scale[l])
                } else {
                    (1.0, 0.0)
                };
                let open = s > 0.0;
                let b = if open { s * inv_h } else { soft_bias };
                let mass_scale = if open { 1.0 } else { mass_scale };
                let impulse_scale = if open { 0.0 } else { impulse_scale };
                let vn = (vbx[l] - vax[l]) * g.normal_x[l] + (vby[l] - vay[l]) * g.normal_y[l];
                g.approach[l] = larger(-vn, g.approach[l]);
                let step = -g.normal_mass[l] * mass_scale * (vn + b) - impulse_scale * g.impulse[l];
                let total = larger(g.impulse[l] + step, 0.0);
                j[l] = total - g.impulse[l];
                g.impulse[l] = total;
            }
        }
    }
    let (mut px, mut py) = (zero, zero);
    for l in 0..LANES {
        g.total_impulse[l] += j[l];
        px[l] = g.normal_x[l] * j[l];
        py[l] = g.normal_y[l] * j[l];
    }
    for l in 0..LANES {
        vax[l] -= px[l] * g.inv_mass_a[l];
        vay[l] -= py[l] * g.inv_mass_a[l];
        vbx[l] += px[l] * g.inv_mass_b[l];
        vby[l] += py[l] * g.inv_mass_b[l];
    }
    if g.immovable.contains(&true) {
        immovable_work(g, velocity, [px, py], work);
    }
    // An immovable side is written too, unchanged but for the sign of a zero (`v ∓ p·0`).
    for l in 0..LANES {
        if g.live[l] {
            velocity[g.a[l] as usize] = DVec2::new(vax[l], vay[l]);
            velocity[g.b[l] as usize] = DVec2::new(vbx[l], vby[l]);
        }
    }
}

/// Adds to `work` what the immovable sides of `g`'s contacts did with pushes `p` (x and y by
/// lane), from their velocities (which no contact changes).
fn immovable_work(g: &Group, velocity: &[DVec2], [px, py]: [[f64; LANES]; 2], work: &mut Work) {
    for l in 0..LANES {
        if g.immovable[l] {
            // The immovable side's push times its own velocity along it, and the push.
            let p = DVec2::new(px[l], py[l]);
            let (push, pusher) = if g.inv_mass_a[l] == 0.0 {
                (p, velocity[g.a[l] as usize])
            } else {
                (-p, velocity[g.b[l] as usize])
            };
            work.energy += push.dot(pusher);
            work.momentum += push;
        }
    }
}

#[cfg(test)]
mod tests;
