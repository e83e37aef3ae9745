//! The camera's view: the whole arena at its aspect ratio, with a band above it for the HUD,
//! in the part of the window the live panel leaves free ([`PanelEdge`]), refitted when the
//! arena, the panel or the window changes.

use bevy::camera::ScalingMode;
use bevy::prelude::*;
use bevy::window::{PrimaryWindow, WindowResized};

use crate::base::arena::Arena;

/// How much wider and taller than the arena the view is.
const VIEW_MARGIN: f32 = 1.04;
/// Extra room above the arena for the HUD line, as a fraction of the arena height.
const HUD_BAND: f32 = 0.07;
/// The least share of the window's width the arena keeps, however wide the panel is.
const LEAST_SHARE: f32 = 0.3;

/// Where the shown live panel's left edge is, in logical pixels from the window's left; `None`
/// while it is hidden (or in an app without it). The arena and the HUD keep left of it.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct PanelEdge(pub Option<f32>);

/// Fits the camera to the arena on the first update and whenever the arena, the panel or the
/// window changes.
pub(crate) struct ViewPlugin;

impl Plugin for ViewPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<PanelEdge>().add_systems(
            Update,
            fit_view.run_if(
                resource_changed::<Arena>
                    .or_eager(resource_changed::<PanelEdge>)
                    .or_eager(on_message::<WindowResized>),
            ),
        );
    }
}

/// The camera's projection and position that show `arena` whole, at its aspect ratio, with a
/// band above it for the HUD: in the whole window while `free` (the width left of the panel,
/// in logical pixels of a `window`-sized window) is `None`, else in its left `free` pixels.
fn view_of(arena: &Arena, window: Vec2, free: Option<f32>) -> (Projection, Transform) {
    let size = arena.size().as_vec2();
    let (wide, high) = (size.x * VIEW_MARGIN, size.y * (VIEW_MARGIN + HUD_BAND));
    // Up by half the band, so the band sits above the arena.
    let centre = arena.center().as_vec2() + Vec2::Y * size.y * HUD_BAND / 2.0;
    let (scaling_mode, shift) = match free {
        // AutoMin keeps the whole arena visible at its own aspect ratio whatever the window.
        None => (
            ScalingMode::AutoMin {
                min_width: wide,
                min_height: high,
            },
            0.0,
        ),
        Some(free) => {
            let free = free.clamp(window.x * LEAST_SHARE, window.x);
            // World units a pixel: enough for the arena across `free` and down the window.
            let unit = (wide / free).max(high / window.y);
            // The window's middle lies right of the free part's middle by half the panel.
            let shift = unit * (window.x - free) / 2.0;
            let height = unit * window.y;
            (
                ScalingMode::FixedVertical {
                    viewport_height: height,
                },
                shift,
            )
        }
    };
    let projection = Projection::Orthographic(OrthographicProjection {
        scaling_mode,
        ..OrthographicProjection::default_2d()
    });
    let translation = (centre + Vec2::X * shift).extend(0.0);
    (projection, Transform::from_translation(translation))
}

fn fit_view(
    arena: Res<Arena>,
    edge: Res<PanelEdge>,
    window: Single<&Window, With<PrimaryWindow>>,
    mut camera: Single<(&mut Projection, &mut Transform), With<Camera2d>>,
) {
    // A minimised window has no size to fit into; it is fitted again when it comes back.
    if window.width() <= 0.0 || window.height() <= 0.0 {
        return;
    }
    let (projection, transform) = view_of(&arena, window.size(), edge.0);
    *camera.0 = projection;
    *camera.1 = transform;
}

#[cfg(test)]
mod tests {
    use super::*;
    use bevy::math::DVec2;

    /// The world point at logical pixel `x` across a `window`, under `view`.
    fn world_x(view: &(Projection, Transform), window: Vec2, x: f32) -> f32 {
        let Projection::Orthographic(ortho) = &view.0 else {
            panic!("orthographic")
        };
        let ScalingMode::FixedVertical { viewport_height } = ortho.scaling_mode else {
            panic!("fixed vertical")
        };
        let unit = viewport_height / window.y;
        view.1.translation.x + (x - window.x / 2.0) * unit
    }

    #[test]
    fn beside_the_panel_the_arena_fills_the_free_part_and_stays_whole() {
        let arena = Arena::centered(DVec2::new(16.0, 9.0));
        let window = Vec2::new(1280.0, 720.0);
        let view = view_of(&arena, window, Some(930.0));
        let (left, right) = (world_x(&view, window, 0.0), world_x(&view, window, 930.0));
        // The arena (x from -8 to 8) lies within the free part, centred in it, with the margin.
        assert!(left < -8.0 && right > 8.0, "{left} .. {right}");
        assert!((left + right).abs() < 1e-3, "{left} .. {right}");
        assert!((right - left) / 16.0 <= VIEW_MARGIN * 1.001);
    }
}
