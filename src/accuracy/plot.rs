//! The study's figure: per scene, position error against cost per step on log axes, one
//! colour per solver, as SVG text.

use plotters::prelude::*;

use super::measure::Row;

/// Smallest error the plot shows: `exact` against itself is 0, and a log axis needs a floor.
pub const PLOT_FLOOR: f64 = 1e-12;

/// A log-log plot per scene of position error against cost per step, as SVG text.
pub fn plot(rows: &[Row]) -> Result<String, String> {
    let mut svg = String::new();
    draw(rows, &mut svg)?;
    Ok(svg)
}

fn draw(rows: &[Row], svg: &mut String) -> Result<(), String> {
    let scenes: Vec<&str> = rows.iter().fold(Vec::new(), |mut v, r| {
        if !v.contains(&r.scene.as_str()) {
            v.push(&r.scene);
        }
        v
    });
    let cols = 2usize;
    let rows_of_panels = scenes.len().div_ceil(cols).max(1);
    let root =
        SVGBackend::with_string(svg, (1200, 460 * rows_of_panels as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let panels = root.split_evenly((rows_of_panels, cols));
    for (scene, panel) in scenes.iter().zip(panels.iter()) {
        let mine: Vec<&Row> = rows.iter().filter(|r| r.scene == *scene).collect();
        let x_range = log_range(mine.iter().map(|r| r.ms_per_step));
        let y_range = log_range(mine.iter().map(|r| r.position_error.max(PLOT_FLOOR)));
        let n = mine.first().map_or(0, |r| r.n);
        let horizon = mine.first().map_or(0.0, |r| r.horizon);
        let mut chart = ChartBuilder::on(panel)
            .caption(
                format!("{scene} (n = {n}), position error at t = {horizon} s"),
                ("sans-serif", 20),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(x_range.log_scale(), y_range.log_scale())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .light_line_style(WHITE)
            .x_label_formatter(&|v| format!("{v:.2}"))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .x_desc("ms per step")
            .y_desc("position error vs exact (mean radii)")
            .draw()
            .map_err(|e| e.to_string())?;
        for (family, colour) in FAMILIES {
            let points: Vec<(f64, f64, String)> = mine
                .iter()
                .filter(|r| r.solver == family)
                .map(|r| {
                    (
                        r.ms_per_step,
                        r.position_error.max(PLOT_FLOOR),
                        format!("{:.0}Hz", 1.0 / r.dt),
                    )
                })
                .collect();
            if points.is_empty() {
                continue;
            }
            let colour = colour.to_rgba();
            chart
                .draw_series(
                    points
                        .iter()
                        .map(|(x, y, _)| Circle::new((*x, *y), 5, colour.filled())),
                )
                .map_err(|e| e.to_string())?
                .label(family)
                .legend(move |(x, y)| Circle::new((x, y), 5, colour.filled()));
            chart
                .draw_series(points.iter().map(|(x, y, label)| {
                    Text::new(
                        label.clone(),
                        (*x, *y),
                        ("sans-serif", 11).into_font().color(&BLACK),
                    )
                }))
                .map_err(|e| e.to_string())?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::MiddleRight)
            .draw()
            .map_err(|e| e.to_string())?;
    }
    root.present().map_err(|e| e.to_string())
}

const FAMILIES: [(&str, plotters::style::RGBColor); 7] = [
    ("discrete", plotters::style::RGBColor(220, 50, 47)),
    ("substeps=2", plotters::style::RGBColor(203, 75, 22)),
    ("substeps=4", plotters::style::RGBColor(181, 137, 0)),
    ("substeps=8", plotters::style::RGBColor(133, 153, 0)),
    ("substeps=16", plotters::style::RGBColor(42, 161, 152)),
    ("swept", plotters::style::RGBColor(38, 139, 210)),
    ("exact", plotters::style::RGBColor(108, 113, 196)),
];

fn log_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return 1e-3..1.0;
    }
    (lo / 2.0)..(hi * 2.0)
}
