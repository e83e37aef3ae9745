//! The contacts of one `soft` step: which circles may touch a circle, an arena wall or a
//! segment wall before the step ends ([`find_contacts`]: the broad phase on each circle's reach
//! over the step, kept from step to step in a [`PairList`], then a speculative margin), each as
//! a [`Constraint`] along a normal fixed for the step.

use bevy::math::DVec2;

use super::bodies::{Bodies, Softness};
pub use super::rules::ContactRules;
use super::rules::impact;
use crate::base::arena::Arena;
use crate::base::collision_layers::{meets_any, pair_meets};
use crate::base::grid::NONE;
use crate::base::hits::{ArenaWall, Wall};
use crate::base::segment::{Segment, SegmentCells};
use crate::collision::contact::{combine_restitution, contact_normal};
use crate::collision::pair_list::{PairList, SKIN};
use crate::collision::toi::pair_time_of_impact;

/// Gap (as a fraction of the smaller radius) within which circles at rest relative to each
/// other get a contact: Box2D's speculative distance (four linear slops, 2 cm) for bodies of
/// radius 0.5 m.
pub const SPECULATIVE_MARGIN: f64 = 0.04;

/// What a contact's second side is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Partner {
    /// Another circle (by its identity).
    Circle(u64),
    /// An arena wall or a segment wall.
    Wall(Wall),
}

/// One contact between circle `a` and a circle `b` or a wall, solved along `normal` (from `a`
/// towards the other side) for the whole step.
#[derive(Clone, Copy, Debug)]
pub struct Constraint {
    /// The first circle.
    pub a: u32,
    /// The second circle, or `NONE` (`u32::MAX`) for a wall.
    pub b: u32,
    /// What the other side is, for matching across steps and for messages.
    pub partner: Partner,
    /// Unit normal from `a` towards the other side.
    pub normal: DVec2,
    /// A pair: what `b`'s position gains to be the image nearest `a` (periodic arenas). A
    /// wall: the point of the wall the contact presses on.
    pub anchor: DVec2,
    /// Distance along the normal at which the two sides touch: `r_a + r_b`, or `r_a` for a wall.
    pub reach: f64,
    /// Inverse masses of the two sides (0 for a wall or an immovable circle).
    pub inv_mass: (f64, f64),
    /// `1 / (w_a + w_b)`.
    pub normal_mass: f64,
    /// How soft the contact is (stiffer against immovable circles and walls).
    pub soft: Softness,
    /// Coefficient of restitution of the pair.
    pub restitution: f64,
    /// Approach speed below which the contact does not bounce.
    pub threshold: f64,
    /// Fastest push-out speed.
    pub push: f64,
    /// Normal velocity of `b` relative to `a` when the step began (negative: approaching), or,
    /// where gravity closes the gap to a wall or an immovable circle, the one they meet with
    /// (`rules.rs`): what a bounce reverses.
    pub relative_velocity: f64,
    /// Impulse accumulated in the current substep (warm started from the last one's).
    pub impulse: f64,
    /// Every impulse applied during the step, added up: the momentum it transferred.
    pub total_impulse: f64,
    /// Fastest approach along the normal the solver met in the step (what a hit's message
    /// calls its normal speed).
    pub approach: f64,
    /// Whether the contact still pressed when the last step ended (a new push is a collision
    /// to count, and may bounce).
    pub was_touching: bool,
    /// Whether it still presses when the step ends: it pushed, and its two sides do not part
    /// faster than its threshold (the next step's `was_touching`; set by the restitution).
    pub pressing: bool,
    /// Its [`TurningRow`]'s index in the step's rows, or `NONE` (`u32::MAX`) without friction.
    pub turn: u32,
}

impl Constraint {
    /// The separation along the normal for `a` at `pa` and the other side at `pb` (a wall's
    /// anchor, or `b`'s position): negative when they overlap.
    #[inline]
    pub fn separation(&self, pa: DVec2, pb: DVec2) -> f64 {
        (pb - pa).dot(self.normal) - self.reach
    }
}

/// `a` if it is greater than `b`, else `b` (a NaN `a` gives `b`): one instruction where
/// `f64::max` takes five to order NaN both ways, and what a vector max does lane by lane.
#[inline(always)]
pub fn larger(a: f64, b: f64) -> f64 {
    if a > b { a } else { b }
}

/// The friction and rolling rows of a contact: what it needs besides its normal push to stop
/// sliding and turning ([`super::friction`]). Only contacts with friction have one, so a
/// frictionless step carries none.
#[derive(Clone, Copy, Debug, Default)]
pub struct TurningRow {
    /// Coefficient of friction of the pair.
    pub friction: f64,
    /// Rolling resistance times the lever it acts on: the most torque per unit of normal push
    /// (0 when neither side turns).
    pub rolling: f64,
    /// Distances from `a`'s and `b`'s centres to the contact point (`b`'s 0 for a wall).
    pub lever: (f64, f64),
    /// Inverse moments of inertia of the two sides (0 for a side that cannot turn).
    pub inv_inertia: (f64, f64),
    /// `1 / (w_a + w_b + i_a r_a² + i_b r_b²)`: the mass the tangent row moves.
    pub tangent_mass: f64,
    /// `1 / (i_a + i_b)`, or 0 if neither side turns: the inertia the rolling row turns.
    pub rolling_mass: f64,
    /// Tangent impulse accumulated in the current substep (warm started like the normal one).
    pub tangent_impulse: f64,
    /// Rolling (torque) impulse accumulated in the current substep.
    pub rolling_impulse: f64,
}

impl TurningRow {
    /// The largest tangent and rolling impulses the row may hold while its contact pushes
    /// with `impulse`: its friction and its rolling torque times it (never negative, never
    /// NaN, so a clamp by them is safe whatever a game wrote into `Friction`).
    #[inline]
    pub fn bounds(&self, impulse: f64) -> (f64, f64) {
        let most = |k: f64| (k * impulse).max(0.0);
        (most(self.friction), most(self.rolling))
    }
}

/// Whether a step under `rules` with `bodies` may have friction anywhere.
pub fn may_turn(bodies: &Bodies, rules: &ContactRules) -> bool {
    rules.friction.0 > 0.0 || rules.friction.1 > 0.0 || !bodies.friction.is_empty()
}

/// Gives every contact in `contacts` that has friction a [`TurningRow`] in `rows` (its `turn`
/// the row's index); the others keep `NONE`.
pub fn turning_rows<'a>(
    bodies: &Bodies,
    rules: &ContactRules,
    contacts: impl Iterator<Item = &'a mut Constraint>,
    rows: &mut Vec<TurningRow>,
) {
    rows.clear();
    for c in contacts {
        let i = c.a as usize;
        let own = |k: usize| bodies.own_friction(k);
        // Friction, the other side's inverse inertia, the levers and the smaller radius.
        let (friction, ib, lever, smaller) = if c.b == NONE {
            // The walls' coefficient is that of a circle against them; a circle's own meets it.
            let walls = rules.friction.1;
            let friction = own(i).map_or(walls, |own| rules.combine.apply(own, walls));
            let r = bodies.radius[i];
            (friction, 0.0, (r, 0.0), r)
        } else {
            let j = c.b as usize;
            let scene = rules.friction.0;
            let friction = rules
                .combine
                .apply(own(i).unwrap_or(scene), own(j).unwrap_or(scene));
            let lever = (bodies.radius[i], bodies.radius[j]);
            (friction, bodies.inv_inertia[j], lever, lever.0.min(lever.1))
        };
        if friction <= 0.0 || friction.is_nan() {
            continue;
        }
        let (wa, wb) = c.inv_mass;
        let ia = bodies.inv_inertia[i];
        let spin = ia + ib;
        let rolling = rules.rolling_resistance * smaller;
        let rolling_mass = if spin > 0.0 && rolling > 0.0 {
            1.0 / spin
        } else {
            0.0
        };
        c.turn = rows.len() as u32;
        rows.push(TurningRow {
            friction,
            rolling: if rolling_mass > 0.0 { rolling } else { 0.0 },
            lever,
            inv_inertia: (ia, ib),
            tangent_mass: 1.0 / (wa + wb + ia * lever.0 * lever.0 + ib * lever.1 * lever.1),
            rolling_mass,
            tangent_impulse: 0.0,
            rolling_impulse: 0.0,
        });
    }
}

/// Most a circle may travel in a step, as a fraction of its radius, for the pairs to be kept
/// from step to step ([`PairList`], grown by [`SKIN`]): at this speed a list lasts six steps or
/// more. Faster circles (a gas, a pour) find their pairs afresh each step, which costs less
/// than a list made again each step. Which way a step takes depends only on the speeds now, so
/// a run never depends on what an earlier step did (and with one grid in a walled arena both
/// ways hand over the same pairs in the same order).
pub const KEEP_BELOW_TRAVEL: f64 = SKIN / 8.0;

/// What contact finding keeps from step to step: the broad phase's pairs, and buffers.
#[derive(Default)]
pub struct ContactScratch {
    /// The circles the broad phase searches, by index.
    searched: Vec<u32>,
    travel: Vec<f64>,
    reach: Vec<(DVec2, f64)>,
    list: PairList,
    near: Vec<u32>,
}

/// Every contact the circles in `bodies` may make during a step under `rules`: pairs (into
/// `pairs`) and walls (into `walls`), in an order that depends only on the circles now, not
/// on when `scratch`'s list was made. A circle's reach over the step (its radius, plus how far
/// its speed and gravity can take it, plus the speculative margin) finds the candidates. A
/// candidate pair becomes a contact when it overlaps (along the normal now), when its straight
/// relative path meets this step (along the normal where it touches), or when a push from
/// another contact could close its gap within the step (along the normal where it comes
/// closest); a wall, when its gap can close within the step.
pub fn find_contacts(
    bodies: &Bodies,
    arena: &Arena,
    segments: (&[Segment], &SegmentCells),
    rules: &ContactRules,
    scratch: &mut ContactScratch,
    (pairs, walls): (&mut Vec<Constraint>, &mut Vec<Constraint>),
) {
    pairs.clear();
    walls.clear();
    let dt = rules.dt;
    let fall = rules.gravity.length() * dt * dt;
    // How far each circle can get this step, worked out once for the reaches, the choice of
    // list and the walls.
    scratch.travel.clear();
    let each = bodies.velocity.iter().map(|v| v.length() * dt + fall);
    scratch.travel.extend(each);
    let travel = &scratch.travel;
    if rules.collisions {
        // With layers, circles that meet nothing (sensors) stay out of the search, so they
        // change neither its cells nor the order of the contacts; `searched` lists the others.
        let (layers, all) = (&bodies.layers, bodies.layers.is_empty());
        let reach_of = |i: usize| {
            let r = bodies.radius[i];
            (
                bodies.position[i],
                r * (1.0 + SPECULATIVE_MARGIN) + travel[i],
            )
        };
        scratch.searched.clear();
        scratch.reach.clear();
        if all {
            scratch.reach.extend((0..bodies.len()).map(reach_of));
        } else {
            let searched = (0..bodies.len() as u32).filter(|&i| meets_any(layers[i as usize]));
            scratch.searched.extend(searched);
            let reach = scratch.searched.iter().map(|&i| reach_of(i as usize));
            scratch.reach.extend(reach);
        }
        let slow = |(t, r): (&f64, &f64)| *t <= KEEP_BELOW_TRAVEL * r;
        let keep = travel.iter().zip(&bodies.radius).all(slow);
        let (list, reach, searched) = (&mut scratch.list, &scratch.reach, &scratch.searched);
        list.for_each_overlapping(arena, reach, (keep, SKIN), |k, l| {
            let (i, j) = match all {
                true => (k, l),
                false => (searched[k] as usize, searched[l] as usize),
            };
            if !pair_meets(layers, i, j) {
                return;
            }
            if let Some(c) = pair_contact(bodies, arena, rules, (i, j)) {
                pairs.push(c);
            }
        });
    }
    if arena.is_periodic() {
        return;
    }
    // Arena walls if it has them; segment walls also in an open arena.
    let axes = if arena.has_walls() { 0..2 } else { 0..0 };
    for (i, &travel) in travel.iter().enumerate() {
        if bodies.inv_mass[i] == 0.0 {
            continue; // immovable circles are kept inside by whoever steers them
        }
        let (p, r) = (bodies.position[i], bodies.radius[i]);
        let limit = r * SPECULATIVE_MARGIN + travel;
        for axis in axes.clone() {
            for high in [false, true] {
                let wall = ArenaWall::on_axis(axis, high);
                let (anchor, normal) = wall.contact(p, arena);
                let gap = (anchor - p).dot(normal) - r;
                if gap < limit {
                    walls.push(wall_contact(
                        bodies,
                        rules,
                        i,
                        Wall::Arena(wall),
                        anchor,
                        normal,
                    ));
                }
            }
        }
        let (list, cells) = segments;
        scratch.near.clear();
        cells.near(p, r + limit, |k| scratch.near.push(k));
        scratch.near.sort_unstable();
        scratch.near.dedup();
        for &k in &scratch.near {
            let (point, out, distance) = list[k as usize].contact(p, bodies.velocity[i]);
            if distance - r < limit {
                walls.push(wall_contact(
                    bodies,
                    rules,
                    i,
                    Wall::Segment(k),
                    point,
                    -out,
                ));
            }
        }
    }
}

/// The contact of circles `i` and `j`, if both exist to the solver (one at least movable) and
/// their gap can close within the step.
fn pair_contact(
    bodies: &Bodies,
    arena: &Arena,
    rules: &ContactRules,
    (i, j): (usize, usize),
) -> Option<Constraint> {
    let (wa, wb) = (bodies.inv_mass[i], bodies.inv_mass[j]);
    if wa + wb == 0.0 {
        return None;
    }
    let (pa, pb) = (bodies.position[i], bodies.position[j]);
    let (va, vb) = (bodies.velocity[i], bodies.velocity[j]);
    let d = arena.offset(pa, pb);
    let reach = bodies.radius[i] + bodies.radius[j];
    let smaller = bodies.radius[i].min(bodies.radius[j]);
    // Under gravity an immovable partner bends the relative path by up to g·dt²/2.
    let fall = if wa == 0.0 || wb == 0.0 {
        rules.gravity.length() * rules.dt * rules.dt
    } else {
        0.0
    };
    let margin = smaller * SPECULATIVE_MARGIN + fall;
    let dv = vb - va;
    let (now, distance) = contact_normal(d, -dv);
    let normal = if distance < reach {
        now
    } else if let Some(t) = pair_time_of_impact(d, dv, reach).filter(|&t| t <= rules.dt) {
        // They meet this step: along the normal where they touch.
        contact_normal(d + dv * t, -dv).0
    } else if distance - reach < margin + (va.length() + vb.length()) * rules.dt {
        // Not meeting on the straight path, but near enough that a push from another contact
        // could bring them together within the step (or at rest against each other): along
        // the normal where they come closest this step, so a pair that passes by (or grazes)
        // gets no push from its own motion.
        let closest = (-d.dot(dv) / dv.length_squared()).clamp(0.0, rules.dt);
        let closest = if closest.is_finite() { closest } else { 0.0 };
        contact_normal(d + dv * closest, -dv).0
    } else {
        return None;
    };
    let restitution = combine_restitution(
        bodies.restitution_of(i, rules.restitution.0),
        bodies.restitution_of(j, rules.restitution.0),
    );
    // Gravity closes the gap only against an immovable partner.
    let accel = match (wa > 0.0, wb > 0.0) {
        (true, false) => -rules.gravity.dot(normal),
        (false, true) => rules.gravity.dot(normal),
        _ => 0.0,
    };
    let relative_velocity = impact(rules, dv.dot(normal), accel, d.dot(normal) - reach);
    Some(Constraint {
        a: i as u32,
        b: j as u32,
        partner: Partner::Circle(bodies.id[j]),
        normal,
        anchor: pa + d - pb,
        reach,
        inv_mass: (wa, wb),
        normal_mass: 1.0 / (wa + wb),
        soft: if wa == 0.0 || wb == 0.0 {
            rules.soft.1
        } else {
            rules.soft.0
        },
        restitution,
        threshold: rules.threshold * smaller,
        push: rules.push_speed * smaller,
        relative_velocity,
        impulse: 0.0,
        total_impulse: 0.0,
        approach: 0.0,
        was_touching: false,
        pressing: false,
        turn: NONE,
    })
}

/// The contact of movable circle `i` with a wall at `anchor` whose normal (from the circle) is
/// `normal`.
fn wall_contact(
    bodies: &Bodies,
    rules: &ContactRules,
    i: usize,
    wall: Wall,
    anchor: DVec2,
    normal: DVec2,
) -> Constraint {
    let (r, w) = (bodies.radius[i], bodies.inv_mass[i]);
    let own = bodies.restitution_of(i, rules.restitution.1);
    let relative_velocity = impact(
        rules,
        -bodies.velocity[i].dot(normal),
        -rules.gravity.dot(normal),
        (anchor - bodies.position[i]).dot(normal) - r,
    );
    Constraint {
        a: i as u32,
        b: NONE,
        partner: Partner::Wall(wall),
        normal,
        anchor,
        reach: r,
        inv_mass: (w, 0.0),
        normal_mass: 1.0 / w,
        soft: rules.soft.1,
        restitution: combine_restitution(own, rules.restitution.1),
        threshold: rules.threshold * r,
        push: rules.push_speed * r,
        relative_velocity,
        impulse: 0.0,
        total_impulse: 0.0,
        approach: 0.0,
        was_touching: false,
        pressing: false,
        turn: NONE,
    }
}
