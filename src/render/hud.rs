//! The heads-up display, refreshed twice a second: circle count, solver, steps per second,
//! energy drift since the last reset and collisions per second; then pressure (virial and
//! walls), momentum, overlaps, escapes and non-finite values. `h` toggles the key help.
//!
//! [`HudRates`] measures the rates over each refresh window; [`hud_text`] writes the two lines
//! from what the diagnostics hold, as a plain function.

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;

use crate::base::arena::Arena;
use crate::base::collision_layers::{LayeredDisc, layered_disc};
use crate::base::config::Solver;
use crate::base::hits::PairCollisions;
use crate::collision::overlaps::Overlaps;
use crate::game::diagnostics::{CircleDiagnostics, Pressure};
use crate::render::view::PanelEdge;
use crate::step::boundary::WallCollisions;
use crate::step::schedule::StepTotals;
use crate::step::sleep::Sleeping;

/// The HUD text and the help overlay.
#[derive(Clone, Copy, Debug, Default)]
pub struct HudPlugin;

impl Plugin for HudPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<HelpVisible>()
            .init_resource::<HudRates>()
            .add_systems(Startup, spawn_hud)
            .add_systems(
                Update,
                (
                    (
                        measure_rates,
                        update_hud.run_if(resource_changed::<HudRates>),
                    )
                        .chain(),
                    show_help,
                    keep_left_of_panel.run_if(resource_exists_and_changed::<PanelEdge>),
                ),
            );
    }
}

/// Whether the key help is shown.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HelpVisible(pub bool);

/// Marks the HUD's text.
#[derive(Component)]
pub struct HudText;

#[derive(Component)]
struct HelpText;

/// The keys, as shown by `h`.
pub const HELP: &str = "\
+ / -     double / halve the number of circles
r         reset (same seed)
space     pause / resume
.         one step (while paused)
[ / ]     half / double speed
1 2 3 4 5 solver: discrete / substeps=8 / swept / exact / soft
mouse     drag a circle to fling it
h         this help
p         live panel: plots, sliders, compare
q, Esc    quit";

/// Wraps the HUD's lines short of the live panel while it is shown.
fn keep_left_of_panel(edge: Res<PanelEdge>, mut hud: Single<&mut Node, With<HudText>>) {
    hud.max_width = match edge.0 {
        // Its own left offset and a gap as wide.
        Some(left) => px((left - 12.0).max(0.0)),
        None => Val::Auto,
    };
}

fn spawn_hud(mut commands: Commands) {
    let panel = (
        BackgroundColor(Color::srgba(0.0, 0.0, 0.0, 0.55)),
        TextFont::from_font_size(15.0),
        TextColor(Color::srgb(0.92, 0.92, 0.92)),
    );
    commands.spawn((
        HudText,
        Text::new("…"),
        Node {
            position_type: PositionType::Absolute,
            top: px(6),
            left: px(6),
            padding: UiRect::all(px(6)),
            ..default()
        },
        panel.clone(),
    ));
    commands.spawn((
        HelpText,
        Text::new(HELP),
        Node {
            position_type: PositionType::Absolute,
            bottom: px(6),
            left: px(6),
            padding: UiRect::all(px(8)),
            ..default()
        },
        Visibility::Hidden,
        panel,
    ));
}

/// Steps and collisions per second of real time, over the last refresh window. Changes only
/// when a window completes, which is when the HUD redraws.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct HudRates {
    since: f64,
    steps: u64,
    collisions: u64,
    /// Fixed steps per second.
    pub steps_per_second: f64,
    /// Circle and wall collisions per second.
    pub collisions_per_second: f64,
}

/// Seconds of real time between HUD refreshes.
pub const REFRESH_SECONDS: f64 = 0.5;

/// What the simulation measured, as the HUD reads it.
#[derive(SystemParam)]
pub struct Measured<'w> {
    diagnostics: Res<'w, CircleDiagnostics>,
    elapsed: Res<'w, StepTotals>,
    pairs: Res<'w, PairCollisions>,
    walls: Res<'w, WallCollisions>,
    arena: Res<'w, Arena>,
    sleeping: Res<'w, Sleeping>,
}

fn measure_rates(real: Res<Time<Real>>, measured: Measured, mut rates: ResMut<HudRates>) {
    let now = real.elapsed_secs_f64();
    let elapsed = now - rates.since;
    if elapsed < REFRESH_SECONDS && rates.since > 0.0 {
        return;
    }
    let steps = measured.elapsed.steps;
    let collisions = measured.pairs.count + measured.walls.count;
    let window = elapsed.max(f64::MIN_POSITIVE);
    // Counters restart at a reset; a window that spans one shows zero rather than nonsense.
    *rates = HudRates {
        since: now,
        steps,
        collisions,
        steps_per_second: steps.saturating_sub(rates.steps) as f64 / window,
        collisions_per_second: collisions.saturating_sub(rates.collisions) as f64 / window,
    };
}

fn update_hud(
    virt: Res<Time<Virtual>>,
    solver: Res<Solver>,
    measured: Measured,
    rates: Res<HudRates>,
    circles: Query<LayeredDisc>,
    mut text: Single<&mut Text, With<HudText>>,
) {
    // Overlaps are measured here, at the HUD's refresh rate, not every step.
    let overlaps = Overlaps::measure_layered(circles.iter().map(layered_disc), &measured.arena);
    let d = &*measured.diagnostics;
    let pressure = Pressure::measure(
        &measured.elapsed,
        &measured.pairs,
        &measured.walls,
        d.count,
        d.kinetic_energy,
        &measured.arena,
    );
    let state = if virt.is_paused() {
        "  PAUSED".to_owned()
    } else if virt.relative_speed() != 1.0 {
        format!("  speed ×{}", virt.relative_speed())
    } else {
        String::new()
    };
    let asleep = measured.sleeping.count;
    text.0 = hud_text(d, asleep, *solver, &rates, &pressure, &overlaps, &state);
}

/// The HUD's two lines: counts (with how many of the circles sleep), cost and conservation;
/// then pressure both ways, momentum, overlaps, escapes and non-finite values. `state` is
/// appended to the first line (pause, speed).
pub fn hud_text(
    d: &CircleDiagnostics,
    asleep: usize,
    solver: Solver,
    rates: &HudRates,
    pressure: &Pressure,
    overlaps: &Overlaps,
    state: &str,
) -> String {
    let z = |z: Option<f64>| z.map_or("-".to_owned(), |z| format!("{z:.3}"));
    format!(
        "circles {} ({asleep} asleep)   solver {solver}   {:.0} steps/s   energy drift {:+.2e}   {:.0} collisions/s{state}   (h: help)\n\
         pressure z {} (walls {})   momentum ({:+.3e}, {:+.3e})   overlap max {:.3} mean {:.3} r   escaped {}   non-finite {}",
        d.count,
        rates.steps_per_second,
        d.energy_drift(),
        rates.collisions_per_second,
        z(pressure.z_virial),
        z(pressure.z_wall),
        d.momentum.x,
        d.momentum.y,
        overlaps.max,
        overlaps.mean(),
        d.escaped,
        d.non_finite,
    )
}

fn show_help(
    keys: Res<ButtonInput<KeyCode>>,
    mut visible: ResMut<HelpVisible>,
    mut help: Single<&mut Visibility, With<HelpText>>,
) {
    if keys.just_pressed(KeyCode::KeyH) {
        visible.0 = !visible.0;
    }
    **help = if visible.0 {
        Visibility::Visible
    } else {
        Visibility::Hidden
    };
}
