//! The heads-up display, refreshed twice a second: circle count, solver, steps per second,
//! energy drift since the last reset and collisions per second; then pressure (virial and
//! walls), momentum, overlaps, escapes and non-finite values. `h` toggles the help.

use bevy::prelude::*;

use bevy::math::DVec2;

use crate::collide::collision_space;
use crate::components::{Position, Radius};
use crate::config::{Arena, Boundary, Effects, Solver};
use crate::diagnostics::{CircleDiagnostics, CollisionCounters, Overlaps, Pressure};
use crate::spawn::CircleInit;

/// The HUD text and the help overlay.
#[derive(Clone, Copy, Debug, Default)]
pub struct HudPlugin;

impl Plugin for HudPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<HelpVisible>()
            .add_systems(Startup, spawn_hud)
            .add_systems(Update, (update_hud, show_help));
    }
}

/// Whether the key help is shown.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HelpVisible(pub bool);

#[derive(Component)]
struct HudText;

#[derive(Component)]
struct HelpText;

/// The keys, as shown by `h`.
pub const HELP: &str = "\
+ / -     double / halve the number of circles
r         reset (same seed)
space     pause / resume
.         one step (while paused)
[ / ]     half / double speed
1 2 3 4   solver: discrete / substeps=8 / swept / exact
mouse     drag a circle to fling it
h         this help
q, Esc    quit";

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

/// Rates measured over the last refresh window of real time.
#[derive(Default)]
struct RateWindow {
    since: f64,
    steps: u64,
    collisions: u64,
    steps_per_second: f64,
    collisions_per_second: f64,
}

const REFRESH_SECONDS: f64 = 0.5;

/// The HUD's second line: pressure both ways, overlaps, escapes and non-finite values.
fn physics_line(
    diagnostics: &CircleDiagnostics,
    counters: &CollisionCounters,
    arena: &Arena,
    effects: &Effects,
    overlaps: &Overlaps,
) -> String {
    let walls = effects.boundary == Boundary::Walls;
    let p = Pressure::measure(
        counters,
        diagnostics.count,
        diagnostics.kinetic_energy,
        arena,
        walls,
    );
    let z = |z: Option<f64>| z.map_or("-".to_owned(), |z| format!("{z:.3}"));
    format!(
        "pressure z {} (walls {})   momentum ({:+.3e}, {:+.3e})   overlap max {:.3} mean {:.3} r   escaped {}   non-finite {}",
        z(p.z_virial),
        z(p.z_wall),
        diagnostics.momentum.x,
        diagnostics.momentum.y,
        overlaps.max,
        if overlaps.pairs == 0 {
            0.0
        } else {
            overlaps.sum / overlaps.pairs as f64
        },
        diagnostics.escaped,
        diagnostics.non_finite,
    )
}

#[allow(clippy::too_many_arguments)]
fn update_hud(
    real: Res<Time<Real>>,
    virt: Res<Time<Virtual>>,
    solver: Res<Solver>,
    arena: Res<Arena>,
    effects: Res<Effects>,
    diagnostics: Res<CircleDiagnostics>,
    counters: Res<CollisionCounters>,
    circles: Query<(&Position, &Radius)>,
    mut window: Local<RateWindow>,
    mut text: Single<&mut Text, With<HudText>>,
) {
    let now = real.elapsed_secs_f64();
    let elapsed = now - window.since;
    let collisions = counters.pair_collisions + counters.wall_collisions;
    if elapsed < REFRESH_SECONDS && window.since > 0.0 {
        return;
    }
    // Counters restart at a reset; a window that spans one shows zero rather than nonsense.
    window.steps_per_second = counters.steps.saturating_sub(window.steps) as f64 / elapsed;
    window.collisions_per_second = collisions.saturating_sub(window.collisions) as f64 / elapsed;
    window.since = now;
    window.steps = counters.steps;
    window.collisions = collisions;
    let state = if virt.is_paused() {
        "  PAUSED".to_owned()
    } else if virt.relative_speed() != 1.0 {
        format!("  speed ×{}", virt.relative_speed())
    } else {
        String::new()
    };
    // Overlaps are measured here, at the HUD's refresh rate, not every step.
    let snapshot: Vec<CircleInit> = circles
        .iter()
        .map(|(p, r)| CircleInit {
            position: p.0,
            velocity: DVec2::ZERO,
            radius: r.0,
            mass: 1.0,
            tint: [0; 3],
        })
        .collect();
    let overlaps = Overlaps::measure(&snapshot, collision_space(&arena, effects.boundary));
    text.0 = format!(
        "circles {}   solver {}   {:.0} steps/s   energy drift {:+.2e}   {:.0} collisions/s{}   (h: help)\n{}",
        diagnostics.count,
        *solver,
        window.steps_per_second,
        diagnostics.energy_drift(),
        window.collisions_per_second,
        state,
        physics_line(&diagnostics, &counters, &arena, &effects, &overlaps),
    );
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
