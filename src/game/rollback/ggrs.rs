//! Rollback through `bevy_ggrs` (feature `ggrs`): [`GgrsCirclesPlugin`] runs the fixed step
//! once per GGRS frame, inside `GgrsSchedule`, and keeps a [`CirclesSnapshot`] of each frame
//! GGRS may roll back to, whose `state_hash` is the frame's checksum.
//!
//! Every circle is a rollback entity (it requires `bevy_ggrs`'s `Rollback`), so the rollback
//! library despawns circles spawned after the frame it goes back to and spawns again, with new
//! entities, circles despawned since; the plugin registers with it what a snapshot does not
//! hold (serial, radius, mass, tint, restitution, friction, inertia, layers, sensors and what
//! they overlap, whether a circle turns). The snapshot then puts back their motion and the solvers' state.

use std::collections::VecDeque;

use bevy::app::FixedMain;
use bevy::ecs::schedule::ScheduleLabel;
use bevy::prelude::*;
use bevy_ggrs::{
    ChecksumPart, ConfirmedFrameCount, GgrsSchedule, LoadWorld, LoadWorldSystems, Rollback,
    RollbackApp, RollbackFrameCount, SaveWorld, SaveWorldSystems,
};

use super::{CirclesSnapshot, RollbackError};
use crate::base::collision_layers::{CollisionLayers, Sensor, SensorOverlaps};
use crate::base::components::{
    AngularVelocity, CircleSerial, Friction, Inertia, Mass, Radius, Restitution, Rotation, Tint,
};
use crate::game::transform_sync::{DefaultSmoothing, Smoothing};

/// Runs the circles' fixed step in GGRS's frames and keeps their state as rollback state.
///
/// Add it with `bevy_ggrs`'s `GgrsPlugin` and the circle plugins. From then on Bevy's clock
/// no longer runs the fixed schedules: each GGRS frame runs them once (`FixedFirst` to
/// `FixedLast`, the circles' step in `FixedUpdate`, one `Time<Fixed>` timestep long; set the
/// step to `1 / RollbackFrameRate` to play in real time). Systems of yours that decide the
/// game go in `GgrsSchedule`, ordered before [`GgrsCirclesSystems::Step`] (the schedule
/// refuses systems it cannot order).
pub struct GgrsCirclesPlugin;

/// Where the circles' step runs in `GgrsSchedule`.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum GgrsCirclesSystems {
    /// One fixed step (Bevy's fixed schedules, once).
    Step,
}

impl Plugin for GgrsCirclesPlugin {
    fn build(&self, app: &mut App) {
        app.register_required_components::<CircleSerial, Rollback>()
            .init_resource::<RollbackFrames>()
            .rollback_component_with_copy::<CircleSerial>()
            .rollback_component_with_copy::<Radius>()
            .rollback_component_with_copy::<Mass>()
            .rollback_component_with_copy::<Tint>()
            .rollback_component_with_copy::<Restitution>()
            .rollback_component_with_copy::<Friction>()
            .rollback_component_with_copy::<Inertia>()
            .rollback_component_with_copy::<CollisionLayers>()
            .rollback_component_with_copy::<Sensor>()
            .rollback_component_with_clone::<SensorOverlaps>()
            .rollback_component_with_copy::<AngularVelocity>()
            .rollback_component_with_copy::<Rotation>()
            .add_systems(GgrsSchedule, step_once.in_set(GgrsCirclesSystems::Step))
            .add_systems(SaveWorld, save_frame.in_set(SaveWorldSystems::Checksum))
            .add_systems(LoadWorld, load_frame.after(LoadWorldSystems::Mapping))
            // Bevy's clock still counts time left over for fixed steps it no longer runs.
            .add_systems(Last, forget_overstep);
    }

    fn finish(&self, app: &mut App) {
        // The fixed schedules run in GGRS's frames, not on Bevy's clock.
        app.world_mut()
            .resource_mut::<Schedules>()
            .remove(FixedMain.intern());
        // Between two GGRS frames there is no time left over to smooth over.
        if let Some(mut smoothing) = app.world_mut().get_resource_mut::<DefaultSmoothing>() {
            smoothing.0 = Smoothing::Off;
        }
    }
}

/// The most frames kept: more than any prediction window GGRS allows in practice (8 by
/// default); a rollback further back is an error, never a silent wrong state.
const KEPT_FRAMES: usize = 128;

/// The snapshots of the frames GGRS may roll back to, with the memory of the ones it no longer
/// needs kept to save the next frames into (no allocation once warm), and the last frame's
/// checksum.
#[derive(Resource, Default)]
pub struct RollbackFrames {
    saved: VecDeque<(i32, CirclesSnapshot)>,
    spare: Vec<CirclesSnapshot>,
    last: Option<(i32, u64)>,
    checksum: Option<Entity>,
}

impl RollbackFrames {
    /// The last frame saved and its [`CirclesSnapshot::state_hash`].
    pub fn last_saved(&self) -> Option<(i32, u64)> {
        self.last
    }

    /// The snapshot kept of `frame`, if GGRS may still roll back to it.
    pub fn get(&self, frame: i32) -> Option<&CirclesSnapshot> {
        self.saved.iter().find(|(f, _)| *f == frame).map(|(_, s)| s)
    }

    /// Frames kept.
    pub fn len(&self) -> usize {
        self.saved.len()
    }

    /// Whether no frame is kept.
    pub fn is_empty(&self) -> bool {
        self.saved.is_empty()
    }

    /// Sets aside (for reuse) the frames `drop` says GGRS no longer needs.
    fn forget(&mut self, drop: impl Fn(i32) -> bool) {
        let mut k = 0;
        while k < self.saved.len() {
            if drop(self.saved[k].0) {
                let (_, snapshot) = self.saved.remove(k).expect("k < len");
                self.spare.push(snapshot);
            } else {
                k += 1;
            }
        }
    }
}

/// One fixed step: Bevy's fixed schedules, once, with `Time` the fixed clock as in Bevy's loop
/// (and GGRS's clock again after).
fn step_once(world: &mut World) {
    let frame_clock = *world.resource::<Time>();
    *world.resource_mut::<Time>() = world.resource::<Time<Fixed>>().as_generic();
    FixedMain::run_fixed_main(world);
    *world.resource_mut::<Time>() = frame_clock;
}

/// Saves the circles of this frame and gives its checksum to GGRS.
fn save_frame(world: &mut World) {
    let frame = world.resource::<RollbackFrameCount>().0;
    let confirmed = world
        .get_resource::<ConfirmedFrameCount>()
        .map_or(-1, |c| c.0);
    let (hash, entity) = world.resource_scope(|world, mut frames: Mut<RollbackFrames>| {
        // A frame saved again (after a rollback) replaces the frames from it on; GGRS never
        // loads a frame before the confirmed one, nor more than its prediction window back.
        frames.forget(|f| f >= frame || f < confirmed);
        while frames.saved.len() >= KEPT_FRAMES {
            let (_, oldest) = frames.saved.pop_front().expect("not empty");
            frames.spare.push(oldest);
        }
        let mut snapshot = frames.spare.pop().unwrap_or_default();
        snapshot.save(world);
        let hash = snapshot.state_hash();
        frames.saved.push_back((frame, snapshot));
        frames.last = Some((frame, hash));
        (hash, frames.checksum)
    });
    let part = ChecksumPart(u128::from(hash));
    match entity.and_then(|e| world.get_entity_mut(e).ok()) {
        Some(mut e) => {
            e.insert(part);
        }
        None => {
            let e = world.spawn(part).id();
            world.resource_mut::<RollbackFrames>().checksum = Some(e);
        }
    }
}

/// Puts back the circles of the frame GGRS rolls back to, after the rollback library has
/// despawned and spawned their entities.
fn load_frame(world: &mut World) -> Result {
    let frame = world.resource::<RollbackFrameCount>().0;
    world.resource_scope(|world, frames: Mut<RollbackFrames>| {
        let snapshot = frames.get(frame).ok_or(LoadError::NotSaved(frame))?;
        snapshot
            .restore(world)
            .map_err(|e| LoadError::Restore(frame, e))?;
        Ok(())
    })
}

/// Why the circles of a frame could not be put back.
#[derive(Debug, thiserror::Error)]
enum LoadError {
    #[error("GGRS rolls back to frame {0}, which was not saved or is no longer kept")]
    NotSaved(i32),
    #[error("rolling back to frame {0}: {1}")]
    Restore(i32, RollbackError),
}

/// Drops the time Bevy's clock counted towards fixed steps, which GGRS's frames run instead.
fn forget_overstep(mut fixed: ResMut<Time<Fixed>>) {
    let overstep = fixed.overstep();
    fixed.discard_overstep(overstep);
}
