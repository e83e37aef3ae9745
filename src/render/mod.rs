//! The windowed app's side (cargo feature `render`): a camera that keeps the whole arena in view
//! at its aspect ratio ([`view`]), one sprite per circle sharing a single disc texture (so
//! thousands draw in a handful of batched draw calls, each with its own tint; a darker radius
//! on the disc turns with the circle's [`Rotation`]), a thin bar per segment wall, and
//! the [`hud`], [`input`] and [`screenshot`] plugins; the app adds the live [`panel`]. The
//! simulation never reads anything from here; the core group's
//! [`transform_sync`](crate::game::transform_sync) moves the sprites.

pub mod hud;
pub mod input;
pub mod panel;
pub mod screenshot;
pub mod view;

use bevy::asset::RenderAssetUsages;
use bevy::prelude::*;
use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};

use crate::base::arena::Arena;
use crate::base::components::{Position, Radius, Rotation, Tint};
use crate::base::segment::Segments;

/// Everything the window shows: arena, circles, HUD and the keyboard and mouse controls.
#[derive(Clone, Copy, Debug, Default)]
pub struct CirclesRenderPlugin;

impl Plugin for CirclesRenderPlugin {
    fn build(&self, app: &mut App) {
        app.insert_resource(ClearColor(Color::srgb(0.02, 0.02, 0.03)))
            .add_plugins((view::ViewPlugin, hud::HudPlugin, input::InputPlugin))
            .add_systems(Startup, (create_disc_texture, spawn_camera_and_arena))
            .add_systems(
                Update,
                fit_backdrop_to_arena.run_if(resource_changed::<Arena>),
            )
            .add_systems(
                Update,
                draw_segment_walls.run_if(resource_changed::<Segments>),
            )
            .add_systems(
                PostUpdate,
                (attach_sprites, resize_sprites, turn_sprites).chain(),
            );
    }
}

/// The one texture every circle sprite shares: a white anti-aliased disc, tinted per circle,
/// with a darker radius towards its right (at rotation 0) that shows how far it has turned.
#[derive(Resource, Clone, Debug)]
pub struct DiscTexture(pub Handle<Image>);

/// Marks the backdrop sprite that shows the arena.
#[derive(Component, Clone, Copy, Debug)]
pub struct ArenaBackdrop;

const DISC_PIXELS: u32 = 128;

fn create_disc_texture(mut commands: Commands, mut images: ResMut<Assets<Image>>) {
    let size = DISC_PIXELS as f32;
    let radius = size / 2.0;
    let mut data = Vec::with_capacity((DISC_PIXELS * DISC_PIXELS * 4) as usize);
    for y in 0..DISC_PIXELS {
        for x in 0..DISC_PIXELS {
            let offset = Vec2::new(x as f32 + 0.5 - radius, y as f32 + 0.5 - radius);
            let d = offset.length();
            // One pixel of soft edge; coverage in alpha, colour white so `Sprite::color` tints it.
            let alpha = (radius - d).clamp(0.0, 1.0);
            // The mark: a band 1/16 of the diameter wide from the centre to near the edge.
            let mark = offset.x > 0.0 && offset.y.abs() < size / 32.0 && d < radius - 3.0;
            let grey = if mark { 140 } else { 255 };
            data.extend_from_slice(&[grey, grey, grey, (alpha * 255.0) as u8]);
        }
    }
    let image = Image::new(
        Extent3d {
            width: DISC_PIXELS,
            height: DISC_PIXELS,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        data,
        TextureFormat::Rgba8UnormSrgb,
        RenderAssetUsages::RENDER_WORLD,
    );
    commands.insert_resource(DiscTexture(images.add(image)));
}

/// The camera and the arena's backdrop; both are fitted to the arena on the first update
/// (`view`'s `fit_view`, [`fit_backdrop_to_arena`]), as whenever it changes.
fn spawn_camera_and_arena(mut commands: Commands) {
    commands.spawn(Camera2d);
    commands.spawn((
        ArenaBackdrop,
        Sprite::from_color(Color::srgb(0.09, 0.1, 0.14), Vec2::ONE),
    ));
}

type BackdropParts = (&'static mut Sprite, &'static mut Transform);

/// Sizes and places the backdrop on the arena: at the start and after a change (a reloaded
/// scene); `view` fits the camera.
fn fit_backdrop_to_arena(
    arena: Res<Arena>,
    mut backdrop: Single<BackdropParts, With<ArenaBackdrop>>,
) {
    backdrop.0.custom_size = Some(arena.size().as_vec2());
    backdrop.1.translation = arena.center().as_vec2().extend(-1.0);
}

/// Marks a sprite that shows a segment wall.
#[derive(Component, Clone, Copy, Debug)]
pub struct SegmentSprite;

/// Draws each segment wall as a thin bar (again when a reloaded scene changes them).
fn draw_segment_walls(
    mut commands: Commands,
    arena: Res<Arena>,
    segments: Res<Segments>,
    drawn: Query<Entity, With<SegmentSprite>>,
) {
    for entity in &drawn {
        commands.entity(entity).despawn();
    }
    let thickness = (arena.size().min_element() * 0.004) as f32;
    let bars: Vec<_> = segments
        .0
        .iter()
        .map(|s| {
            let (a, b) = (s.a.as_vec2(), s.b.as_vec2());
            let along = b - a;
            (
                SegmentSprite,
                Sprite {
                    color: Color::srgb(0.75, 0.78, 0.85),
                    custom_size: Some(Vec2::new(along.length() + thickness, thickness)),
                    ..default()
                },
                Transform::from_translation(((a + b) / 2.0).extend(-0.5))
                    .with_rotation(Quat::from_rotation_z(along.to_angle())),
            )
        })
        .collect();
    commands.spawn_batch(bars);
}

/// Marks a circle's sprite given by this plugin (a tinted disc).
#[derive(Component, Clone, Copy, Debug)]
pub struct DiscSprite;

/// Gives every new circle without a sprite of its own a tinted disc. Its `Transform` then
/// follows the circle's position ([`transform_sync`](crate::game::transform_sync)).
fn attach_sprites(
    mut commands: Commands,
    disc: Option<Res<DiscTexture>>,
    new_circles: Query<(Entity, &Position, &Radius, &Tint), Without<Sprite>>,
) {
    let Some(disc) = disc else { return };
    for (entity, position, radius, tint) in &new_circles {
        let [r, g, b] = tint.0;
        commands.entity(entity).insert((
            DiscSprite,
            Sprite {
                image: disc.0.clone(),
                color: Color::srgb_u8(r, g, b),
                custom_size: Some(Vec2::splat(2.0 * radius.0 as f32)),
                ..default()
            },
            Transform::from_translation(position.0.as_vec2().extend(0.0)),
        ));
    }
}

/// Turns the sprites this plugin gave circles as the circles turn (a game's own sprites are
/// its own to turn: it reads [`Rotation`] as this does).
fn turn_sprites(mut circles: Query<(&Rotation, &mut Transform), TurnedDiscs>) {
    for (rotation, mut transform) in &mut circles {
        transform.rotation = Quat::from_rotation_z(rotation.0 as f32);
    }
}

/// The circles with a sprite of this plugin that turned.
type TurnedDiscs = (With<DiscSprite>, Changed<Rotation>);

/// The circles with a sprite of this plugin whose radius changed.
type ResizedDiscs = (With<DiscSprite>, Changed<Radius>);

/// Keeps the sprites this plugin gave circles the size of their `Radius` (a game's own sprites
/// are its own to size).
fn resize_sprites(mut circles: Query<(&Radius, &mut Sprite), ResizedDiscs>) {
    for (radius, mut sprite) in &mut circles {
        sprite.custom_size = Some(Vec2::splat(2.0 * radius.0 as f32));
    }
}

/// Why the window cannot open here, if that can be told before trying: no X display (the app is
/// built for X11 only, which Wayland desktops provide through XWayland).
pub fn display_problem() -> Option<String> {
    let display = std::env::var_os("DISPLAY").is_some_and(|v| !v.is_empty());
    if cfg!(target_os = "linux") && !display {
        Some(NO_WINDOW_HINT.to_owned())
    } else {
        None
    }
}

/// What to tell a user whose machine cannot open the window.
pub const NO_WINDOW_HINT: &str = "cannot open a window here (no display, or no \
Vulkan/GL driver). Use the headless commands instead (`moving_circles run --help`), or run the \
app under a virtual display: `xvfb-run -a moving_circles` (Debian packages: xvfb, xauth, \
mesa-vulkan-drivers).";

/// How the app is opened besides its configuration.
#[derive(Clone, Debug, Default)]
pub struct AppOptions {
    /// The scene file the configuration came from: watched and re-applied when it changes.
    pub scene_file: Option<std::path::PathBuf>,
    /// Render this many frames, save a PNG there and exit.
    pub screenshot: Option<(std::path::PathBuf, u32)>,
    /// Whether the live panel starts shown.
    pub panel: bool,
}

/// The complete windowed app: Bevy's default plugins (as far as the enabled features go), the
/// simulation, drawing, HUD and controls, and hot reload of the scene file if there is one.
pub fn app(config: crate::base::config::CirclesConfig, options: AppOptions) -> App {
    use bevy::asset::io::AssetSourceBuilder;

    let mut app = App::new();
    // The scene's folder becomes the `scene://` asset source, so any path works and is watched.
    let watched = options.scene_file.as_ref().and_then(|path| {
        let dir = path
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(std::path::Path::new("."));
        // Absolute, since Bevy reads a relative asset folder from beside the executable.
        let dir = std::path::absolute(dir).ok()?;
        let name = path.file_name()?.to_string_lossy().into_owned();
        app.register_asset_source(
            "scene",
            AssetSourceBuilder::platform_default(&dir.to_string_lossy(), None),
        );
        Some(format!("scene://{name}"))
    });
    app.add_plugins((
        DefaultPlugins
            .set(WindowPlugin {
                primary_window: Some(Window {
                    title: "moving circles".into(),
                    resolution: (1280, 720).into(),
                    ..default()
                }),
                ..default()
            })
            .set(AssetPlugin {
                watch_for_changes_override: Some(watched.is_some()),
                ..default()
            }),
        crate::game::plugins::CirclesPlugins::new(config),
        CirclesRenderPlugin,
        panel::PanelPlugin {
            open: options.panel,
        },
    ));
    if let Some(asset_path) = watched {
        app.add_plugins(crate::tools::scene::asset::SceneReloadPlugin { asset_path });
    }
    if let Some((path, frames)) = options.screenshot {
        app.add_plugins(screenshot::ScreenshotPlugin { path, frames });
    }
    app
}
