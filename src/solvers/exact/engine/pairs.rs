//! A pair collision: both circles brought to the moment of contact, a sleeping one woken if
//! the hit is hard (or comes from an immovable mover) and otherwise treated as immovable, the
//! restitution impulse (and a rough hit's tangential one, `spin`), and a falling circle's bounce on a support checked for rest.

use bevy::math::DVec2;

use super::EventEngine;
use crate::base::hits::CircleHit;
use crate::collision::contact::{
    apply_impulse, combine_restitution, contact_normal, work_by_immovable,
};

impl EventEngine {
    pub(super) fn collide(&mut self, i: usize, j: usize) {
        let now = self.now;
        self.advance_circle(i, now);
        self.advance_circle(j, now);
        let (a, b) = (self.motion[i], self.motion[j]);
        let (n, _) = contact_normal(self.offset(a.pos, b.pos), a.vel - b.vel);
        let approach = (a.vel - b.vel).dot(n);
        for (sleeper, hitter) in [(j, i), (i, j)] {
            if self.asleep[sleeper] && self.wakes(sleeper, hitter, approach) {
                self.wake(sleeper);
            }
        }
        let (mut va, mut vb) = (a.vel, b.vel);
        let (wa, wb) = (self.moving_inv_mass(i), self.moving_inv_mass(j));
        let e = match self.own_restitution.as_slice() {
            [] => self.restitution,
            own => combine_restitution(own[i], own[j]),
        };
        let bounce = self.contact_time_restitution(&[i, j], e);
        // Growing radii bounce as if `b` came in slower by the rate the surfaces close at.
        let surfaces = n * ((a.radius + b.radius) * self.growth);
        vb -= surfaces;
        if let Some(impulse) = apply_impulse(n, &mut va, &mut vb, wa, wb, bounce) {
            self.motion[i].vel = va;
            self.motion[j].vel = vb + surfaces;
            let turning_work = self.rough_pair((i, j), n, (wa, wb));
            self.stats.pair_collisions += 1;
            self.stats.virial += (a.radius + b.radius) * impulse;
            if wa == 0.0 || wb == 0.0 {
                let (va, vb) = (self.motion[i].vel, self.motion[j].vel - surfaces);
                let (work, gained) = work_by_immovable((wa, wb), (a.vel, va), (b.vel, vb));
                self.stats.immovable_work += work + turning_work;
                self.stats.immovable_impulse += gained;
            }
            if let Some(log) = &mut self.hits {
                log.circles.push(CircleHit {
                    a: i as u32,
                    b: j as u32,
                    point: a.pos + n * a.radius,
                    normal: n,
                    impulse,
                    normal_speed: approach,
                    time: now,
                });
            }
        }
        // A falling circle that bounced off something at rest that does not move (a peg, a
        // sleeper) may come to rest on it.
        if wb == 0.0 && self.motion[j].vel == DVec2::ZERO {
            self.rest_on_support(i, n, e);
        }
        if wa == 0.0 && self.motion[i].vel == DVec2::ZERO {
            self.rest_on_support(j, -n, e);
        }
        self.sleep_if_jammed(i, e);
        self.sleep_if_jammed(j, e);
        self.counter[i] += 1;
        self.counter[j] += 1;
        self.predict(i);
        self.predict(j);
    }
}
