//! Scenes as Bevy assets: [`SceneLoader`] reads and checks a `.ron` scene into a [`SceneAsset`];
//! [`SceneReloadPlugin`] watches one and, when the file changes, applies the new configuration
//! to the running app ([`apply_config`]: resources, the effect systems in the schedule, a fresh
//! spawn). An edit that does not load logs why and the last good scene keeps running.

use std::time::Duration;

use bevy::asset::io::Reader;
use bevy::asset::{AssetLoadFailedEvent, AssetLoader, LoadContext};
use bevy::prelude::*;
use bevy::tasks::futures_lite::AsyncReadExt;

use super::schema::Scene;
use crate::base::arena::Arena;
use crate::base::config::{CirclesConfig, DropConfig, Effects, Solver, SpawnConfig};
use crate::base::error::InputError;
use crate::base::error::printable;
use crate::base::segment::Segments;
use crate::game::spawn::{FixedCircles, Respawn};
use crate::step::schedule::allow_long_steps;
use crate::tools::io::{MAX_SCENE_BYTES, read_limited};

/// A scene file, checked and turned into a configuration.
#[derive(Asset, TypePath, Clone, Debug)]
pub struct SceneAsset {
    /// What the scene asks for.
    pub config: CirclesConfig,
}

/// Loads `.ron` scene files ([`Scene`]) as [`SceneAsset`]s.
#[derive(Default, TypePath)]
pub struct SceneLoader;

impl AssetLoader for SceneLoader {
    type Asset = SceneAsset;
    type Settings = ();
    type Error = InputError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        _settings: &(),
        load_context: &mut LoadContext<'_>,
    ) -> Result<SceneAsset, InputError> {
        let origin = load_context.path().to_string();
        // Read in chunks up to the limit, as `Scene::load` does: a scene that never ends costs
        // at most the limit.
        let mut bytes = Vec::new();
        let mut chunk = vec![0; 64 << 10];
        loop {
            let read = reader
                .read(&mut chunk)
                .await
                .map_err(|e| InputError::whole(&origin, format!("cannot read: {e}")))?;
            if read == 0 {
                break;
            }
            bytes.extend_from_slice(&chunk[..read]);
            if bytes.len() as u64 > MAX_SCENE_BYTES {
                break;
            }
        }
        let text = read_limited(bytes.as_slice(), MAX_SCENE_BYTES)
            .map_err(|message| InputError::whole(&origin, message))?;
        let config = Scene::parse(&text, &origin)?.to_config(&origin)?;
        Ok(SceneAsset { config })
    }

    fn extensions(&self) -> &[&str] {
        &["ron"]
    }
}

/// Replaces the running simulation's configuration with `config`: arena, solver, effects (whose
/// systems the next step reconciles), fixed step, spawn rules; then respawns.
pub fn apply_config(world: &mut World, config: &CirclesConfig) {
    world.insert_resource::<Arena>(config.arena);
    world.insert_resource::<Solver>(config.solver);
    world.insert_resource::<Effects>(config.effects);
    world.insert_resource::<Segments>(config.segments.clone());
    world.insert_resource::<SpawnConfig>(config.spawn.clone());
    world.insert_resource(FixedCircles(config.circles.clone()));
    match config.drop {
        Some(drop) => world.insert_resource(drop),
        None => drop(world.remove_resource::<DropConfig>()),
    }
    world
        .resource_mut::<Time<Fixed>>()
        .set_timestep(Duration::from_secs_f64(config.dt));
    let _ = world.run_system_cached(allow_long_steps);
    world.write_message(Respawn);
}

/// The scene being watched.
#[derive(Resource, Clone, Debug)]
pub struct WatchedScene(pub Handle<SceneAsset>);

/// Loads the scene at `asset_path` through the asset server and re-applies it whenever the file
/// changes (with Bevy's `file_watcher` on). The app must already run the same scene: the first
/// load is not applied again.
#[derive(Clone, Debug)]
pub struct SceneReloadPlugin {
    /// Asset path of the scene, e.g. `scene://gas.ron`.
    pub asset_path: String,
}

impl Plugin for SceneReloadPlugin {
    fn build(&self, app: &mut App) {
        app.init_asset::<SceneAsset>()
            .init_asset_loader::<SceneLoader>()
            .add_systems(Update, (apply_reloaded_scene, report_failed_reload));
        let handle = app
            .world()
            .resource::<AssetServer>()
            .load::<SceneAsset>(self.asset_path.clone());
        app.insert_resource(WatchedScene(handle));
    }
}

fn apply_reloaded_scene(
    mut events: MessageReader<AssetEvent<SceneAsset>>,
    watched: Res<WatchedScene>,
    scenes: Res<Assets<SceneAsset>>,
    mut commands: Commands,
) {
    for event in events.read() {
        if let AssetEvent::Modified { id } = event
            && *id == watched.0.id()
            && let Some(scene) = scenes.get(*id)
        {
            info!("scene reloaded");
            let config = scene.config.clone();
            commands.queue(move |world: &mut World| apply_config(world, &config));
        }
    }
}

fn report_failed_reload(mut failures: MessageReader<AssetLoadFailedEvent<SceneAsset>>) {
    for failure in failures.read() {
        error!(
            "scene {} was not (re)loaded, the last good scene keeps running: {}",
            printable(&failure.path.to_string()),
            printable(&failure.error.to_string())
        );
    }
}
