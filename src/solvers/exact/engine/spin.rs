//! Rough circles in the engine: each circle's spin and how far it has turned ([`Turn`]), and
//! the tangential impulse a rough hit trades between moving and turning, at each pair and wall
//! event ([`Roughness`]). A smooth engine (the default) keeps none of this: its circles turn
//! at a constant rate, which the continuous step applies itself. Spin does not bend a course
//! (no lift), so it changes no prediction: only the velocities a hit leaves do.

use bevy::math::DVec2;
use serde::{Deserialize, Serialize};

use super::EventEngine;
use crate::base::circle::inverse_inertia;
use crate::base::components::Rotation;
use crate::collision::rough::{RoughSide, apply_rough_impulse};

/// How rough hits are: the tangential restitution β of circle pairs and of walls (arena and
/// segment walls), each from −1 (smooth: no spin traded, as if there were no roughness) to +1
/// (perfectly rough: the slip at the contact reversed whole).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Roughness {
    /// β between two circles.
    pub circles: f64,
    /// β between a circle and a wall.
    pub walls: f64,
}

impl Roughness {
    /// No roughness anywhere.
    pub const SMOOTH: Self = Self {
        circles: -1.0,
        walls: -1.0,
    };

    /// Whether no hit trades spin.
    pub fn is_smooth(&self) -> bool {
        self.circles == -1.0 && self.walls == -1.0
    }
}

/// One circle's turning: its spin, and the angle it had turned to at time `t_at` (its angle at
/// `t` is `angle + spin (t − t_at)`, kept in `[-π, π]` when read).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub(super) struct Turn {
    pub(super) spin: f64,
    pub(super) angle: f64,
    pub(super) t_at: f64,
}

impl Turn {
    /// The angle turned to at time `t`, in `[-π, π]`.
    pub(super) fn angle_at(&self, t: f64) -> f64 {
        Rotation(self.angle).turned(self.spin * (t - self.t_at)).0
    }
}

/// What a rough engine keeps: its roughness, every circle's [`Turn`], and the circles' own
/// moments of inertia (empty when every one is a uniform disc).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub(super) struct Spins {
    pub(super) roughness: Roughness,
    pub(super) turn: Vec<Turn>,
    pub(super) own_inertia: Vec<Option<f64>>,
}

impl EventEngine {
    /// Makes hits rough as `roughness` says, the circles starting from `turns` (spin and angle
    /// of each, in order); a smooth `roughness` makes the engine smooth again. Rough, the engine
    /// keeps each circle's spin and angle ([`EventEngine::turn`]). Each circle turns as a
    /// uniform disc until [`EventEngine::set_own_inertias`] says otherwise.
    pub fn make_rough(
        &mut self,
        roughness: Roughness,
        turns: impl IntoIterator<Item = (f64, f64)>,
    ) {
        if roughness.is_smooth() {
            self.spins = None;
            return;
        }
        let now = self.now;
        let turn: Vec<Turn> = turns
            .into_iter()
            .map(|(spin, angle)| Turn {
                spin,
                angle,
                t_at: now,
            })
            .collect();
        assert_eq!(turn.len(), self.len(), "one turn per circle");
        let own_inertia = Vec::new();
        self.spins = Some(Spins {
            roughness,
            turn,
            own_inertia,
        });
    }

    /// Gives the circles of a rough engine their own moments of inertia (one per circle, in
    /// order: `None` for a uniform disc; empty: every one a disc). Nothing happens in a smooth
    /// engine.
    pub fn set_own_inertias(&mut self, own: Vec<Option<f64>>) {
        if let Some(spins) = &mut self.spins {
            assert!(own.is_empty() || own.len() == spins.turn.len());
            spins.own_inertia = own;
        }
    }

    /// Circle `i`'s own moment of inertia, if the engine is rough and it has one.
    pub fn own_inertia(&self, i: usize) -> Option<f64> {
        self.spins.as_ref()?.own_inertia.get(i).copied().flatten()
    }

    /// How rough the engine's hits are.
    pub fn roughness(&self) -> Roughness {
        self.spins
            .as_ref()
            .map_or(Roughness::SMOOTH, |s| s.roughness)
    }

    /// Circle `i`'s spin and angle now (in `[-π, π]`), if the engine is rough; a smooth engine
    /// leaves turning to its caller.
    pub fn turn(&self, i: usize) -> Option<(f64, f64)> {
        let turn = self.spins.as_ref()?.turn[i];
        Some((turn.spin, turn.angle_at(self.now)))
    }

    /// Sets circle `i`'s spin and angle now (something outside the engine turned it: user
    /// code, a kinematic wheel). A sleeper set spinning wakes. Nothing happens in a smooth
    /// engine.
    pub fn set_turn(&mut self, i: usize, spin: f64, angle: f64) {
        let now = self.now;
        let Some(spins) = &mut self.spins else {
            return;
        };
        spins.turn[i] = Turn {
            spin,
            angle,
            t_at: now,
        };
        if self.asleep[i] && spin != 0.0 {
            let (position, velocity) = (self.position(i), self.velocity(i));
            self.set_motion(i, position, velocity);
        }
    }

    /// Circle `i` stops turning now (it fell asleep).
    pub(super) fn stop_turning(&mut self, i: usize) {
        self.spin_to(i, 0.0);
    }

    /// Trades spin at the hit of circles `i` and `j` (brought to now), touching along `n` (from
    /// `i` to `j`), moving with inverse masses `w`: changes their velocities and spins, and
    /// returns the work an immovable one of the two did on the other's turning.
    pub(super) fn rough_pair(&mut self, (i, j): (usize, usize), n: DVec2, w: (f64, f64)) -> f64 {
        let Some(beta) = self.spins.as_ref().map(|s| s.roughness.circles) else {
            return 0.0;
        };
        let (mut a, mut b) = (self.rough_side(i, w.0), self.rough_side(j, w.1));
        let spun = (a.spin, b.spin);
        if apply_rough_impulse(n, &mut a, &mut b, beta) == 0.0 {
            return 0.0;
        }
        self.motion[i].vel = a.velocity;
        self.motion[j].vel = b.velocity;
        self.spin_to(i, a.spin);
        self.spin_to(j, b.spin);
        // The movable side's energy of turning gained from an immovable one.
        match w {
            (0.0, w) if w > 0.0 => turning_energy(&b, spun.1),
            (w, 0.0) if w > 0.0 => turning_energy(&a, spun.0),
            _ => 0.0,
        }
    }

    /// Trades spin at circle `i`'s hit (brought to now) on a wall along `n` (from the circle to
    /// the wall; walls never move along their surface); changes its velocity and spin.
    pub(super) fn rough_wall(&mut self, i: usize, n: DVec2) {
        let Some(beta) = self.spins.as_ref().map(|s| s.roughness.walls) else {
            return;
        };
        let mut a = self.rough_side(i, self.moving_inv_mass(i));
        let mut wall = RoughSide::fixed(DVec2::ZERO);
        if apply_rough_impulse(n, &mut a, &mut wall, beta) != 0.0 {
            self.motion[i].vel = a.velocity;
            self.spin_to(i, a.spin);
        }
    }

    /// Circle `i` as one side of a rough hit now, moving with inverse mass `w`.
    fn rough_side(&self, i: usize, w: f64) -> RoughSide {
        let radius = self.motion[i].radius * (1.0 + self.growth * self.now);
        let spin = self.spins.as_ref().map_or(0.0, |s| s.turn[i].spin);
        RoughSide {
            velocity: self.motion[i].vel,
            spin,
            radius,
            inv_mass: w,
            inv_inertia: inverse_inertia(self.own_inertia(i), w, radius),
        }
    }

    /// Sets circle `i`'s spin from now on, keeping its angle.
    fn spin_to(&mut self, i: usize, spin: f64) {
        let now = self.now;
        if let Some(spins) = &mut self.spins {
            let turn = &mut spins.turn[i];
            turn.angle = turn.angle_at(now);
            turn.t_at = now;
            turn.spin = spin;
        }
    }
}

/// The energy of turning `side` gained since it spun at `before`.
fn turning_energy(side: &RoughSide, before: f64) -> f64 {
    if side.inv_inertia == 0.0 {
        return 0.0;
    }
    0.5 * (side.spin * side.spin - before * before) / side.inv_inertia
}
