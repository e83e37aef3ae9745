//! The panel's egui window, docked at the top right: solver buttons; sliders and toggles for
//! the circle count, restitution, gravity, drag, step rate and speed; a rolling plot per
//! measure with one colour per solver; and the comparison's button and table. It only reads
//! resources and writes [`Control`] messages.

use bevy::ecs::system::SystemParam;
use bevy::math::DVec2;
use bevy::prelude::*;
use bevy_egui::{EguiContexts, egui};
use egui_plot::{AxisHints, GridInput, GridMark, Legend, Line, Plot};

use super::PanelOpen;
use super::compare::{COMPARE_SECONDS, Comparison};
use super::controls::{Control, SPEED_RANGE};
use super::live::{LiveHistory, LiveSample};
use crate::base::config::{Effects, Solver};
use crate::game::diagnostics::CircleDiagnostics;
use crate::render::input::MAX_COUNT;
use crate::render::view::PanelEdge;
use crate::tools::accuracy::Row;

/// Slider values being dragged: a change that respawns is sent when the drag ends.
#[derive(Resource, Clone, Copy, Debug, Default)]
pub struct Drafts {
    count: Option<usize>,
}

/// The settings the panel shows and changes.
#[derive(SystemParam)]
pub struct Settings<'w> {
    solver: Res<'w, Solver>,
    effects: Res<'w, Effects>,
    diagnostics: Res<'w, CircleDiagnostics>,
    fixed: Res<'w, Time<Fixed>>,
    virt: Res<'w, Time<Virtual>>,
}

/// Each solver's colour in the plots (as in the accuracy figure, lighter for exact on the dark
/// panel), in the order of [`Solver::APP_CHOICES`].
const COLOURS: [[u8; 3]; Solver::APP_CHOICES.len()] = [
    [215, 48, 39],
    [35, 139, 69],
    [33, 113, 181],
    [160, 120, 230],
    [253, 141, 60],
];

/// Draws the panel when it is shown, and notes where its left edge is.
pub fn draw_panel(
    mut contexts: EguiContexts,
    (open, mut edge): (Res<PanelOpen>, ResMut<PanelEdge>),
    history: Res<LiveHistory>,
    comparison: Res<Comparison>,
    settings: Settings,
    mut drafts: ResMut<Drafts>,
    mut controls: MessageWriter<Control>,
) -> Result {
    if !open.0 {
        edge.set_if_neq(PanelEdge(None));
        return Ok(());
    }
    let ctx = contexts.ctx_mut()?;
    let mut sent = Vec::new();
    let shown = egui::Window::new("moving circles  (p: hide)")
        .anchor(egui::Align2::RIGHT_TOP, [-6.0, 6.0])
        .default_width(330.0)
        .resizable(false)
        .collapsible(false)
        .show(ctx, |ui| {
            let height = ui.ctx().content_rect().height() - 60.0;
            egui::ScrollArea::vertical()
                .max_height(height)
                .min_scrolled_height(height)
                .show(ui, |ui| {
                    solver_buttons(ui, *settings.solver, &mut sent);
                    ui.separator();
                    sliders(ui, &settings, &mut drafts, &mut sent);
                    ui.separator();
                    plots(ui, &history);
                    ui.separator();
                    comparison_section(ui, &comparison, &mut sent);
                });
        });
    // Whole points, so the view is not fitted again for a fraction of a pixel.
    let left = shown.map(|window| window.response.rect.left().floor());
    edge.set_if_neq(PanelEdge(left));
    controls.write_batch(sent);
    Ok(())
}

fn solver_buttons(ui: &mut egui::Ui, current: Solver, sent: &mut Vec<Control>) {
    ui.horizontal(|ui| {
        ui.label("solver");
        for solver in Solver::APP_CHOICES {
            if ui
                .selectable_label(current == solver, solver.to_string())
                .clicked()
                && current != solver
            {
                sent.push(Control::Solver(solver));
            }
        }
    });
}

fn sliders(ui: &mut egui::Ui, settings: &Settings, drafts: &mut Drafts, sent: &mut Vec<Control>) {
    let now = settings.diagnostics.count;
    let mut count = drafts.count.unwrap_or(now);
    let response = ui.add(
        egui::Slider::new(&mut count, 1..=MAX_COUNT)
            .logarithmic(true)
            .text("circles (respawns)"),
    );
    if response.dragged() {
        drafts.count = Some(count);
    }
    if (response.drag_stopped() || (response.changed() && !response.dragged())) && count != now {
        sent.push(Control::Count(count));
        drafts.count = None;
    }

    let effects = *settings.effects;
    let mut restitution = effects.restitution;
    if ui
        .add(egui::Slider::new(&mut restitution, 0.0..=1.0).text("restitution"))
        .changed()
    {
        sent.push(Control::Restitution(restitution));
    }

    let gravity = effects.gravity.unwrap_or(DVec2::new(0.0, -9.81));
    let (mut on, mut g) = (effects.gravity.is_some(), gravity.length());
    ui.horizontal(|ui| {
        let toggled = ui.checkbox(&mut on, "gravity").changed();
        let moved = ui
            .add_enabled(on, egui::Slider::new(&mut g, 0.0..=50.0).suffix(" m/s²"))
            .changed();
        if toggled || moved {
            let direction = gravity.try_normalize().unwrap_or(DVec2::NEG_Y);
            sent.push(Control::Gravity(on.then_some(direction * g)));
        }
    });

    let (mut on, mut rate) = (effects.drag.is_some(), effects.drag.unwrap_or(0.5));
    ui.horizontal(|ui| {
        let toggled = ui.checkbox(&mut on, "drag").changed();
        let moved = ui
            .add_enabled(on, egui::Slider::new(&mut rate, 0.0..=10.0).suffix(" /s"))
            .changed();
        if toggled || moved {
            sent.push(Control::Drag(on.then_some(rate)));
        }
    });

    let mut hz = (1.0 / settings.fixed.timestep().as_secs_f64()).round();
    if ui
        .add(
            egui::Slider::new(&mut hz, 15.0..=480.0)
                .logarithmic(true)
                .integer()
                .text("steps per simulated s"),
        )
        .changed()
    {
        sent.push(Control::Dt(1.0 / hz));
    }

    let mut speed = settings.virt.relative_speed_f64();
    if ui
        .add(
            egui::Slider::new(&mut speed, SPEED_RANGE.0..=SPEED_RANGE.1)
                .logarithmic(true)
                .text("speed (simulated s per s)"),
        )
        .changed()
    {
        sent.push(Control::Speed(speed));
    }
}

/// The rolling plots: one per measure, a line per solver (broken where another solver ran).
fn plots(ui: &mut egui::Ui, history: &LiveHistory) {
    type Measure = (&'static str, fn(&LiveSample) -> Option<f64>);
    let measures: [Measure; 5] = [
        ("ms per step", |s| s.ms_per_step),
        ("collisions per simulated s", |s| s.collisions_per_second),
        ("deepest overlap (radii)", |s| Some(s.overlap)),
        ("pressure z", |s| s.z),
        ("energy drift", |s| Some(s.energy_drift)),
    ];
    let count = measures.len();
    for (k, (title, value)) in measures.into_iter().enumerate() {
        ui.label(title);
        // Labels closer than egui_plot's default (20 px), so a short plot shows two or three;
        // the time axis once, under the last plot.
        let y_axis = AxisHints::new_y()
            .formatter(|mark, _| tick(mark.value))
            .label_spacing(12.0..=18.0);
        let last = k + 1 == count;
        let mut plot = Plot::new(title)
            .height(if last { 80.0 } else { 58.0 })
            .allow_zoom(false)
            .allow_drag(false)
            .allow_scroll(false)
            .allow_boxed_zoom(false)
            .allow_double_click_reset(false)
            .show_axes([last, true])
            .custom_y_axes(vec![y_axis])
            .y_grid_spacer(round_marks);
        if last {
            plot = plot.x_axis_label("simulated s");
        }
        if k == 0 {
            plot = plot.legend(Legend::default());
        }
        plot.show(ui, |plot| {
            for (solver, colour, points) in runs(history, value) {
                let [r, g, b] = colour;
                plot.line(
                    Line::new(solver.to_string(), points)
                        .color(egui::Color32::from_rgb(r, g, b))
                        .width(2.0),
                );
            }
        });
    }
}

/// The samples as runs of one solver each: `(solver, colour, points)`.
fn runs(
    history: &LiveHistory,
    value: fn(&LiveSample) -> Option<f64>,
) -> Vec<(Solver, [u8; 3], Vec<[f64; 2]>)> {
    let mut runs: Vec<(Solver, [u8; 3], Vec<[f64; 2]>)> = Vec::new();
    for sample in &history.samples {
        let Some(y) = value(sample).filter(|y| y.is_finite()) else {
            continue;
        };
        match runs.last_mut() {
            Some((solver, _, points)) if *solver == sample.solver => points.push([sample.t, y]),
            _ => runs.push((sample.solver, colour(sample.solver), vec![[sample.t, y]])),
        }
    }
    runs
}

/// Grid marks at the largest round step (1, 2 or 5 times a power of ten) that puts at least
/// two of them (and at most five) across the plot's range, so a short plot labels more than one
/// value; but never closer than egui_plot shows a label (18 pixels apart), where a plot is too
/// short for two.
fn round_marks(input: GridInput) -> Vec<GridMark> {
    let (lo, hi) = input.bounds;
    let span = hi - lo;
    // `base_step_size` is the value 8 pixels cover.
    let closest = input.base_step_size * 18.0 / 8.0;
    if !(span.is_finite() && span > 0.0 && closest.is_finite()) {
        return Vec::new();
    }
    let (mantissa, exponent) = match round_step_at_most(span / 2.0) {
        (m, e) if m * 10f64.powi(e) >= closest => (m, e),
        _ => round_step_at_least(closest),
    };
    let step = mantissa * 10f64.powi(exponent);
    // k · mantissa / 10^-e rather than k · step, so 3 · 0.2 is 0.6 and not 0.6000000000000001.
    let value = |k: f64| match exponent {
        e if e < 0 => k * mantissa / 10f64.powi(-e),
        _ => k * step,
    };
    let (first, last) = ((lo / step).ceil(), (hi / step).floor());
    let count = (last - first + 1.0).clamp(0.0, 8.0) as usize;
    (0..count)
        .map(|i| GridMark {
            value: value(first + i as f64),
            step_size: step,
        })
        .collect()
}

/// The largest round step (`mantissa` 1, 2 or 5 times 10^`exponent`) no wider than `widest`.
fn round_step_at_most(widest: f64) -> (f64, i32) {
    let exponent = widest.log10().floor() as i32;
    let power = 10f64.powi(exponent);
    let mantissa = [5.0, 2.0, 1.0]
        .into_iter()
        .find(|&m| m * power <= widest)
        .unwrap_or(1.0);
    (mantissa, exponent)
}

/// The smallest round step no narrower than `narrowest`.
fn round_step_at_least(narrowest: f64) -> (f64, i32) {
    let exponent = narrowest.log10().floor() as i32;
    let power = 10f64.powi(exponent);
    match [1.0, 2.0, 5.0]
        .into_iter()
        .find(|&m| m * power >= narrowest)
    {
        Some(m) => (m, exponent),
        None => (1.0, exponent + 1),
    }
}

/// A compact axis label: `1.5e-14`, `0.25`, `7000`.
fn tick(v: f64) -> String {
    if v != 0.0 && (v.abs() < 1e-2 || v.abs() >= 1e5) {
        format!("{v:.0e}")
    } else {
        format!("{v}")
    }
}

fn colour(solver: Solver) -> [u8; 3] {
    Solver::APP_CHOICES
        .iter()
        .zip(COLOURS)
        .find(|(s, _)| std::mem::discriminant(*s) == std::mem::discriminant(&solver))
        .map_or([200, 200, 200], |(_, c)| c)
}

fn comparison_section(ui: &mut egui::Ui, comparison: &Comparison, sent: &mut Vec<Control>) {
    let running = comparison.is_running();
    let label = format!("compare every solver ({COMPARE_SECONDS} s from now)");
    if ui.add_enabled(!running, egui::Button::new(label)).clicked() {
        sent.push(Control::Compare);
    }
    match comparison {
        Comparison::Idle => {}
        Comparison::Running { done, from, .. } => {
            let done = done.load(std::sync::atomic::Ordering::Relaxed);
            ui.label(format!(
                "running in the background from {from}: {done} of {} runs",
                Comparison::RUNS
            ));
        }
        Comparison::Failed(why) => {
            ui.colored_label(egui::Color32::LIGHT_RED, why);
        }
        Comparison::Done { from, rows } => {
            ui.label(format!("from {from}, against exact:"));
            comparison_table(ui, rows);
        }
    }
}

fn comparison_table(ui: &mut egui::Ui, rows: &[Row]) {
    egui::Grid::new("comparison").striped(true).show(ui, |ui| {
        for head in [
            "solver",
            "ms/step",
            "collisions",
            "z",
            "overlap",
            "tunnelled",
        ] {
            ui.strong(head);
        }
        ui.end_row();
        for row in rows {
            ui.label(&row.solver);
            ui.label(format!("{:.3}", row.ms_per_step));
            ui.label(format!("{:+.1} %", 100.0 * row.collision_error));
            ui.label(
                row.z_error
                    .map_or("-".into(), |z| format!("{:+.1} %", 100.0 * z)),
            );
            ui.label(format!("{:.2}", row.max_penetration));
            ui.label(row.tunnelled.to_string());
            ui.end_row();
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The marks of a plot showing `lo..hi` over `pixels` pixels.
    fn marks_over(lo: f64, hi: f64, pixels: f64) -> Vec<f64> {
        let input = GridInput {
            bounds: (lo, hi),
            base_step_size: (hi - lo) * 8.0 / pixels,
        };
        round_marks(input).into_iter().map(|m| m.value).collect()
    }

    fn marks(lo: f64, hi: f64) -> Vec<f64> {
        marks_over(lo, hi, 800.0)
    }

    #[test]
    fn a_short_plot_gets_two_to_five_round_marks() {
        assert_eq!(marks(0.9, 2.6), [1.0, 1.5, 2.0, 2.5]);
        assert_eq!(marks(0.55, 0.95), [0.6, 0.7, 0.8, 0.9]);
        assert_eq!(marks(12.5, 13.0), [12.6, 12.8, 13.0]);
        assert_eq!(marks(7100.0, 9300.0), [8000.0, 9000.0]);
        assert_eq!(marks(-3e-16, 4e-16), [-2e-16, 0.0, 2e-16, 4e-16]);
        for (lo, hi) in [
            (0.0, 1.0),
            (1e-9, 3e-9),
            (0.31, 0.99),
            (-50.0, 700.0),
            (3.0, 3.001),
        ] {
            let n = marks(lo, hi).len();
            assert!((2..=5).contains(&n), "{lo}..{hi}: {n} marks");
        }
        // A 40-pixel plot keeps its labels 18 pixels apart: fewer, wider steps.
        assert_eq!(marks_over(0.55, 0.95, 64.0), [0.6, 0.8]);
        assert_eq!(marks_over(0.0, 1.0, 40.0), [0.0, 0.5, 1.0]);
        assert_eq!(marks_over(0.0, 1.0, 30.0), [0.0, 1.0]);
        assert!(marks(1.0, 1.0).is_empty());
        assert!(marks(0.0, f64::INFINITY).is_empty());
    }
}
