//! What the panel's sliders and toggles ask for, as [`Control`] messages, and
//! [`apply_controls`], which makes each change the way a reloaded scene does: effects by writing
//! the resource, which the next step reconciles
//! ([`reconcile_effects`](crate::step::effects::reconcile_effects): an effect switched off loses its
//! systems), the step through the fixed
//! clock, the count through a respawn; `Compare` starts the background comparison. A value that fails the scene's own checks is refused
//! with a warning, never clamped.

use std::time::Duration;

use bevy::math::DVec2;
use bevy::prelude::*;

use super::compare::start_comparison;
use crate::base::config::{CirclesConfig, Effects, Solver, SpawnConfig};
use crate::game::spawn::Respawn;
use crate::step::schedule::allow_long_steps;

/// One change asked for in the panel.
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub enum Control {
    /// Switch the solver.
    Solver(Solver),
    /// Respawn with this many random circles.
    Count(usize),
    /// Restitution between circles.
    Restitution(f64),
    /// Gravity on (with this acceleration) or off.
    Gravity(Option<DVec2>),
    /// Drag on (with this rate, 1/s) or off.
    Drag(Option<f64>),
    /// The fixed step, in seconds.
    Dt(f64),
    /// Simulated seconds per real second.
    Speed(f64),
    /// Start a comparison of every solver from the current state (see [`super::compare`]).
    Compare,
}

/// Slowest and fastest simulation speed the panel offers.
pub const SPEED_RANGE: (f64, f64) = (1.0 / 64.0, 16.0);

/// Applies the [`Control`]s written since the last frame, in order.
pub fn apply_controls(world: &mut World) {
    let controls: Vec<Control> = world.resource_mut::<Messages<Control>>().drain().collect();
    for control in controls {
        if let Err(problem) = apply(world, control) {
            warn!("panel: {control:?} refused: {problem}");
        }
    }
}

fn apply(world: &mut World, control: Control) -> Result<(), String> {
    match control {
        Control::Solver(solver) => {
            // Only names the command line and scenes accept (substeps 1 to 1024).
            solver
                .to_string()
                .parse::<Solver>()
                .map_err(|e| e.to_string())?;
            world.insert_resource(solver);
        }
        Control::Count(count) => {
            let mut spawn = world.resource::<SpawnConfig>().clone();
            spawn.count = count;
            spawn.area_fraction = None;
            spawn
                .check(world.resource())
                .map_err(|e| e.within("spawn").to_string())?;
            world.insert_resource(spawn);
            world.write_message(Respawn);
        }
        Control::Restitution(_) | Control::Gravity(_) | Control::Drag(_) => {
            let mut effects = *world.resource::<Effects>();
            match control {
                Control::Restitution(e) => effects.restitution = e,
                Control::Gravity(g) => effects.gravity = g,
                Control::Drag(d) => effects.drag = d,
                _ => unreachable!("only effect controls reach here"),
            }
            effects.check().map_err(|e| e.to_string())?;
            world.insert_resource(effects);
        }
        Control::Dt(dt) => {
            let config = CirclesConfig {
                dt,
                ..CirclesConfig::default()
            };
            config.check().map_err(|e| e.to_string())?;
            world
                .resource_mut::<Time<Fixed>>()
                .set_timestep(Duration::from_secs_f64(dt));
            let _ = world.run_system_cached(allow_long_steps);
        }
        Control::Compare => start_comparison(world),
        Control::Speed(speed) => {
            if !(SPEED_RANGE.0..=SPEED_RANGE.1).contains(&speed) {
                return Err(format!(
                    "speed must be in [{}, {}], got {speed}",
                    SPEED_RANGE.0, SPEED_RANGE.1
                ));
            }
            world
                .resource_mut::<Time<Virtual>>()
                .set_relative_speed_f64(speed);
        }
    }
    Ok(())
}
