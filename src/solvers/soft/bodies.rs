//! What the `soft` solver works on: [`Bodies`], the circles of a step as plain arrays, and
//! [`Softness`], the coefficients that make a contact a damped spring for one substep.

use std::f64::consts::TAU;
use std::ops::{Deref, DerefMut};

use crate::base::circle::inverse_inertia;
use crate::base::components::Mass;
use crate::step::bodies::BodyStore;

/// The circles of one `soft` step: the step's [`BodyStore`] (reached through `Deref`), and
/// what `soft` adds beside it, all in one order (serial order).
#[derive(Clone, Debug, Default)]
pub struct Bodies {
    /// Centres, velocities, radii, masses, own restitutions and layers.
    pub(crate) circles: BodyStore,
    /// Inverse masses: 0 for an immovable (static, kinematic or sleeping) circle.
    pub inv_mass: Vec<f64>,
    /// Angular velocities (counter-clockwise, radians per second); these three are empty in a
    /// step in which nothing turns ([`Bodies::start_turning`]).
    pub angular_velocity: Vec<f64>,
    /// Rotations (radians, in `[-π, π]`).
    pub rotation: Vec<f64>,
    /// Inverse moments of inertia: `2 / (m r²)` for a uniform disc, 0 for a circle that
    /// cannot turn (immovable, asleep, or without an angular velocity).
    pub inv_inertia: Vec<f64>,
    /// Each circle's own friction coefficient (NaN for one without), or empty when every
    /// circle takes the scene's.
    pub friction: Vec<f64>,
    /// A stable identity per circle (its serial), so a contact is recognised next step.
    pub id: Vec<u64>,
}

impl Deref for Bodies {
    type Target = BodyStore;

    fn deref(&self) -> &BodyStore {
        &self.circles
    }
}

impl DerefMut for Bodies {
    fn deref_mut(&mut self) -> &mut BodyStore {
        &mut self.circles
    }
}

impl Bodies {
    /// Takes what `soft` adds beside the store from the circles gathered into it, with their
    /// `serials`: inverse masses (0 while asleep) and identities; nothing turns yet.
    pub fn beside_gathered(&mut self, serials: &[u64]) {
        let store = &self.circles;
        self.inv_mass.clear();
        self.inv_mass.extend(
            store
                .mass
                .iter()
                .zip(&store.asleep)
                .map(|(&m, &asleep)| if asleep { 0.0 } else { Mass(m).inverse() }),
        );
        self.id.clear();
        self.id.extend_from_slice(serials);
        self.angular_velocity.clear();
        self.rotation.clear();
        self.inv_inertia.clear();
        self.friction.clear();
    }

    /// Adds a circle that does not turn (without an App: the kernel's tests).
    #[cfg(test)]
    pub fn push(
        &mut self,
        id: u64,
        (position, velocity): (bevy::math::DVec2, bevy::math::DVec2),
        radius: f64,
        inv_mass: f64,
    ) {
        let mass = if inv_mass > 0.0 {
            1.0 / inv_mass
        } else {
            f64::INFINITY
        };
        self.circles.push(position, velocity, radius, mass);
        self.id.push(id);
        self.inv_mass.push(inv_mass);
    }

    /// Makes room for every circle to turn (none turning yet): the step may turn circles.
    pub fn start_turning(&mut self) {
        let n = self.len();
        for spin in [
            &mut self.angular_velocity,
            &mut self.rotation,
            &mut self.inv_inertia,
        ] {
            spin.resize(n, 0.0);
        }
    }

    /// Lets circle `i` turn: at its angular velocity, from its rotation, with its `own` moment
    /// of inertia or as a uniform disc (`m r² / 2`), if it is movable. Call
    /// [`Bodies::start_turning`] first.
    pub fn turning(
        &mut self,
        i: usize,
        (angular_velocity, rotation): (f64, f64),
        own: Option<f64>,
    ) {
        self.angular_velocity[i] = angular_velocity;
        self.rotation[i] = rotation;
        self.inv_inertia[i] = inverse_inertia(own, self.inv_mass[i], self.radius[i]);
    }

    /// Circle `i`'s own restitution, or `scene`'s if circles have none.
    #[inline]
    pub fn restitution_of(&self, i: usize, scene: f64) -> f64 {
        self.restitution.get(i).copied().unwrap_or(scene)
    }

    /// Circle `i`'s own friction coefficient, if it has one.
    #[inline]
    pub fn own_friction(&self, i: usize) -> Option<f64> {
        self.friction.get(i).copied().filter(|f| !f.is_nan())
    }
}

/// A soft constraint for one substep of length `h`: the position error is fed back as a
/// velocity at `bias_rate`, the impulse is scaled by `mass_scale`, and `impulse_scale` of the
/// impulse already applied is taken back. Together they make the contact a spring of a given
/// frequency and damping ratio, integrated implicitly, so it is stable at any stiffness the
/// substep can resolve (Erin Catto, "Solver2D", 2024).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Softness {
    /// How fast an overlap is pushed out, per unit of overlap (1/s).
    pub bias_rate: f64,
    /// Scale of the rigid impulse.
    pub mass_scale: f64,
    /// Share of the accumulated impulse taken back.
    pub impulse_scale: f64,
}

impl Softness {
    /// A rigid constraint: no bias, full impulse.
    pub const RIGID: Softness = Softness {
        bias_rate: 0.0,
        mass_scale: 1.0,
        impulse_scale: 0.0,
    };

    /// A spring of `hertz` with damping ratio `zeta`, for substeps of `h` seconds.
    ///
    /// ```
    /// use moving_circles::solvers::soft::Softness;
    ///
    /// let soft = Softness::new(30.0, 10.0, 1.0 / 240.0);
    /// // Nearly rigid impulses, an overlap fed back at under ω / (2ζ) per second.
    /// assert!(soft.mass_scale > 0.5 && soft.mass_scale < 1.0);
    /// assert!((soft.mass_scale + soft.impulse_scale - 1.0).abs() < 1e-12);
    /// assert!(soft.bias_rate < std::f64::consts::TAU * 30.0 / 20.0);
    /// ```
    pub fn new(hertz: f64, zeta: f64, h: f64) -> Self {
        if hertz <= 0.0 {
            return Self::RIGID;
        }
        let omega = TAU * hertz;
        let a1 = 2.0 * zeta + h * omega;
        let a2 = h * omega * a1;
        let a3 = 1.0 / (1.0 + a2);
        Self {
            bias_rate: omega / a1,
            mass_scale: a2 * a3,
            impulse_scale: a3,
        }
    }
}
