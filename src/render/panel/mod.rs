//! The app's live panel (`p` shows and hides it; `--panel` opens the app with it shown): rolling
//! plots of what each solver costs and gets wrong, sliders and toggles that change the running
//! simulation, and a "compare" button that measures every solver from the current state in the
//! background.
//!
//! - [`live`]: the step timer and the rolling samples;
//! - [`controls`]: the [`Control`] messages and how each is applied;
//! - [`compare`]: the background comparison;
//! - [`ui`]: the egui window that shows them and writes the messages.
//!
//! [`PanelStatePlugin`] is everything but the drawing, so headless tests drive it; the app adds
//! [`PanelPlugin`], which adds egui on top.

pub mod compare;
pub mod controls;
pub mod live;
pub mod ui;

use bevy::prelude::*;
use bevy_egui::{EguiPlugin, EguiPrimaryContextPass};

use crate::render::view::PanelEdge;

pub use compare::Comparison;
pub use controls::Control;
pub use live::{LiveHistory, LiveSample, StepTimer};

/// Whether the panel is shown.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PanelOpen(pub bool);

/// The panel's state and systems, without drawing: the [`Control`] messages and their
/// application, the rolling samples (taken while the panel is shown), the comparison and the
/// `p` key.
#[derive(Clone, Copy, Debug, Default)]
pub struct PanelStatePlugin {
    /// Whether the panel starts shown.
    pub open: bool,
}

impl Plugin for PanelStatePlugin {
    fn build(&self, app: &mut App) {
        app.add_message::<Control>()
            .insert_resource(PanelOpen(self.open))
            .init_resource::<StepTimer>()
            .init_resource::<LiveHistory>()
            .init_resource::<Comparison>()
            .add_systems(FixedFirst, live::start_step_timer)
            .add_systems(FixedLast, live::stop_step_timer)
            .add_systems(
                Update,
                (
                    toggle_panel,
                    controls::apply_controls,
                    compare::poll_comparison,
                    live::sample.run_if(|open: Res<PanelOpen>| open.0),
                )
                    .chain(),
            );
    }
}

/// [`PanelStatePlugin`] and the egui window that shows it.
#[derive(Clone, Copy, Debug, Default)]
pub struct PanelPlugin {
    /// Whether the panel starts shown.
    pub open: bool,
}

impl Plugin for PanelPlugin {
    fn build(&self, app: &mut App) {
        app.add_plugins((EguiPlugin::default(), PanelStatePlugin { open: self.open }))
            .init_resource::<ui::Drafts>()
            .init_resource::<PanelEdge>()
            .add_systems(EguiPrimaryContextPass, ui::draw_panel);
    }
}

fn toggle_panel(keys: Res<ButtonInput<KeyCode>>, mut open: ResMut<PanelOpen>) {
    if keys.just_pressed(KeyCode::KeyP) {
        open.0 = !open.0;
    }
}
