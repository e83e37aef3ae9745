//! The study's figure ([`AccuracyFigure`], as SVG and PNG): a row
//! of panels per scene, one panel per error measure (the study's [`MEASURES`], or the
//! [`REPORT_MEASURES`] a sweep's reports carry), each plotting error
//! against cost (ms per simulated second) on log axes. A line joins one solver's runs at 30, 60 and 120 Hz
//! (marker shape gives the rate), the `exact` reference is a dashed vertical line at its cost
//! (error 0 by definition), errors of exactly 0 sit on the axis's bottom line labelled `0`,
//! and a grey band marks the Pareto front. The legend has a strip of its own above the panels.

use plotters::coord::{CoordTranslate, Shift};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

#[cfg(doc)]
use super::front::{MEASURES, REPORT_MEASURES};
use super::front::{Measure, Panel, cost, of_scene, rate, scenes};
use super::measure::Row;
use crate::tools::figure::{Figure, decades, err, font};

/// The figure's width in pixels (SVG user units and PNG pixels alike).
pub const FIGURE_WIDTH: u32 = 1600;

/// The height of each scene's row of panels.
pub const ROW_HEIGHT: u32 = 340;

/// Height of the title and legend strip above the panels.
const STRIP: u32 = 280;

/// Width of the column naming each row's scene, left of the panels.
const LABEL: u32 = 44;

/// Text sizes (in pixels of the 1600-wide figure, which a page shows at about half that): the
/// legend's, the panels' captions and their tick labels.
const LEGEND_TEXT: u32 = 28;
const CAPTION_TEXT: u32 = 24;
const TICK_TEXT: u32 = 21;

/// Longest line of the legend, in characters, before it wraps.
const LEGEND_LINE: usize = 118;

/// One colour per solver setting of the study
/// ([`Solver::STUDY`](crate::base::config::Solver::STUDY), in its order; a test holds them
/// equal): a family shares a hue (substeps and soft from light to dark).
const SETTINGS: [(&str, RGBColor); 9] = [
    ("discrete", RGBColor(215, 48, 39)),
    ("substeps=2", RGBColor(161, 217, 155)),
    ("substeps=4", RGBColor(94, 185, 100)),
    ("substeps=8", RGBColor(35, 139, 69)),
    ("substeps=16", RGBColor(0, 90, 50)),
    ("soft", RGBColor(253, 174, 97)),
    ("soft=8", RGBColor(217, 95, 2)),
    ("swept", RGBColor(33, 113, 181)),
    ("exact", RGBColor(117, 80, 170)),
];

/// The reference's colour (the last setting, `exact`).
const EXACT: RGBColor = SETTINGS[SETTINGS.len() - 1].1;
/// A solver the study does not run.
const OTHER: RGBColor = RGBColor(120, 120, 120);
const FRONT: RGBColor = RGBColor(255, 200, 60);
const GRID: RGBColor = RGBColor(225, 225, 225);

/// The figure of `rows`: a row of panels per scene, a panel per measure; `note` is the
/// legend's second line (what the points are, and when position errors were taken).
pub struct AccuracyFigure<'a> {
    /// The rows, each a setting of a scene.
    pub rows: &'a [Row],
    /// The measures, one panel each, left to right.
    pub measures: &'a [Measure],
    /// The second line of the legend.
    pub note: String,
}

impl<'a> AccuracyFigure<'a> {
    /// The study's figure: its five measures, the note naming the horizons.
    pub fn study(rows: &'a [Row]) -> Self {
        Self {
            rows,
            measures: &super::front::MEASURES,
            note: horizons(rows),
        }
    }

    /// Its size in pixels: [`FIGURE_WIDTH`] wide, [`ROW_HEIGHT`] a scene below the legend.
    pub fn size_for(scenes: usize) -> (u32, u32) {
        (FIGURE_WIDTH, STRIP + ROW_HEIGHT * scenes.max(1) as u32)
    }
}

impl Figure for AccuracyFigure<'_> {
    fn size(&self) -> (u32, u32) {
        Self::size_for(scenes(self.rows).len())
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let rows = self.rows;
        let (strip, grid) = root.split_vertically(STRIP);
        legend(&strip, &self.note)?;
        let scenes = scenes(rows);
        let columns = self.measures.len().max(1);
        let (labels, grid) = grid.split_horizontally(LABEL);
        let labels = labels.split_evenly((scenes.len().max(1), 1));
        let panels = grid.split_evenly((scenes.len().max(1), columns));
        let centred = Pos::new(HPos::Center, VPos::Center);
        for (s, scene) in scenes.iter().enumerate() {
            let mine = of_scene(rows, scene);
            let n = mine.first().map_or(0, |r| r.n);
            let name = font(LEGEND_TEXT)
                .transform(FontTransform::Rotate270)
                .pos(centred);
            let middle = (LABEL as i32 / 2, ROW_HEIGHT as i32 / 2);
            labels[s]
                .draw(&Text::new(format!("{scene} (n = {n})"), middle, name))
                .map_err(err)?;
            for (m, measure) in self.measures.iter().enumerate() {
                panel(&panels[s * columns + m], &mine, measure)?;
            }
        }
        Ok(())
    }
}

/// The study's note: when its position errors were taken.
fn horizons(rows: &[Row]) -> String {
    let mut horizons: Vec<(f64, Vec<&str>)> = Vec::new();
    for r in rows {
        match horizons.iter_mut().find(|(h, _)| *h == r.horizon) {
            Some((_, scenes)) if !scenes.contains(&r.scene.as_str()) => scenes.push(&r.scene),
            Some(_) => {}
            None => horizons.push((r.horizon, vec![&r.scene])),
        }
    }
    let horizons: Vec<String> = horizons
        .iter()
        .map(|(h, scenes)| format!("{h} s ({})", scenes.join(", ")))
        .collect();
    format!(
        "Position error is measured after {} (a few collisions per circle; later, chaos saturates it near one radius for every discrete solver). 0 on an axis: no error at all.",
        horizons.join(" and ")
    )
}

/// The title and the legend: settings, rates, the reference and the front; `note` is the
/// second line.
fn legend<DB: DrawingBackend>(strip: &DrawingArea<DB, Shift>, note: &str) -> Result<(), String> {
    let title = "What accuracy costs: error against exact (y) vs CPU ms of stepping per simulated second (x), log axes; lower left is better.";
    let lines: Vec<String> = wrap(title).into_iter().chain(wrap(note)).collect();
    let line_height = LEGEND_TEXT as i32 + 6;
    for (i, line) in lines.iter().enumerate() {
        strip
            .draw(&Text::new(
                line.as_str(),
                (14, 8 + line_height * i as i32),
                font(LEGEND_TEXT),
            ))
            .map_err(err)?;
    }
    let row_y = 18 + line_height * lines.len() as i32;
    let mut x = 14;
    for (name, colour) in SETTINGS {
        let y = row_y + 12;
        strip
            .draw(&PathElement::new(
                vec![(x, y), (x + 28, y)],
                colour.stroke_width(2),
            ))
            .map_err(err)?;
        strip
            .draw(&Circle::new((x + 14, y), 4, colour.filled()))
            .map_err(err)?;
        strip
            .draw(&Text::new(name, (x + 34, row_y), font(CAPTION_TEXT)))
            .map_err(err)?;
        x += 56 + 13 * name.len() as i32;
    }
    let y = row_y + 52;
    let mut x = 14;
    for hz in [30, 60, 120] {
        marker(strip, hz, (x + 6, y), BLACK)?;
        strip
            .draw(&Text::new(
                format!("{hz} Hz"),
                (x + 16, y - 12),
                font(CAPTION_TEXT),
            ))
            .map_err(err)?;
        x += 120;
    }
    strip
        .draw(&Rectangle::new(
            [(x, y - 4), (x + 28, y + 4)],
            FRONT.mix(0.6).filled(),
        ))
        .map_err(err)?;
    strip
        .draw(&Text::new(
            "Pareto front: no cheaper setting is as accurate",
            (x + 34, y - 12),
            font(CAPTION_TEXT),
        ))
        .map_err(err)?;
    // The reference on a line of its own: the two would not fit one line of the figure.
    let (x, y) = (14, y + 40);
    let exact = EXACT;
    for k in 0..4 {
        strip
            .draw(&PathElement::new(
                vec![(x + 4, y - 10 + 6 * k), (x + 4, y - 7 + 6 * k)],
                exact.stroke_width(2),
            ))
            .map_err(err)?;
    }
    strip
        .draw(&Text::new(
            "exact at 60 Hz, the reference: its cost (its error is 0 by definition)",
            (x + 14, y - 12),
            font(CAPTION_TEXT),
        ))
        .map_err(err)
}

/// One scene's panel for one measure.
fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    rows: &[&Row],
    measure: &Measure,
) -> Result<(), String> {
    let panel = Panel::new(rows, measure);
    let front = panel.front();
    let (reference, plotted) = (panel.reference, panel.points);
    let caption = measure.title;
    if plotted.is_empty() {
        return area
            .draw(&Text::new(
                format!("{caption}: not measured"),
                (20, 20),
                font(CAPTION_TEXT),
            ))
            .map_err(err);
    }
    let costs = rows.iter().map(|r| cost(r));
    let (x_lo, x_hi) = decades(costs.clone().filter(|c| *c > 0.0)).unwrap_or((1e-3, 1.0));
    let zero =
        decades(plotted.iter().map(|p| p.1).filter(|e| *e > 0.0)).map_or(0.1, |(lo, _)| lo / 10.0);
    let y_hi = decades(plotted.iter().map(|p| p.1).filter(|e| *e > 0.0))
        .map_or(zero * 100.0, |(_, hi)| hi);
    let y = |e: f64| if e > zero { e } else { zero };
    let mut chart = ChartBuilder::on(area)
        .caption(caption, font(CAPTION_TEXT))
        .margin(8)
        .margin_right(20)
        .x_label_area_size(56)
        .y_label_area_size(80)
        .build_cartesian_2d(
            (x_lo..x_hi).log_scale().with_key_points(ticks(x_lo, x_hi)),
            (zero..y_hi).log_scale().with_key_points(ticks(zero, y_hi)),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .light_line_style(WHITE)
        .bold_line_style(GRID)
        .x_label_formatter(&|v| decade_label(*v, None))
        .y_label_formatter(&|v| decade_label(*v, Some(zero)))
        .label_style(font(TICK_TEXT))
        .axis_desc_style(font(TICK_TEXT))
        .x_desc("ms per simulated second")
        .y_desc(measure.unit)
        .draw()
        .map_err(err)?;
    // The front first, under the data: a step line through the settings no cheaper one beats,
    // ending at the reference, and a halo on each.
    let mut steps: Vec<(f64, f64)> = Vec::new();
    for p in &front {
        if let Some(&(_, previous)) = steps.last() {
            steps.push((p.cost, previous));
        }
        steps.push((p.cost, y(p.error)));
    }
    chart
        .draw_series(LineSeries::new(steps, FRONT.mix(0.6).stroke_width(9)))
        .map_err(err)?;
    chart
        .draw_series(
            front
                .iter()
                .map(|p| Circle::new((p.cost, y(p.error)), 10, FRONT.filled())),
        )
        .map_err(err)?;
    if let Some(reference) = reference {
        chart
            .draw_series(DashedLineSeries::new(
                [(cost(reference), zero), (cost(reference), y_hi)],
                4,
                4,
                EXACT.stroke_width(2),
            ))
            .map_err(err)?;
    }
    // The study's settings in their colours; any other (a sweep's `substeps=3`) in grey.
    let mut lines: Vec<(&str, RGBColor)> = SETTINGS.to_vec();
    for (r, _) in &plotted {
        if !lines.iter().any(|(name, _)| *name == r.solver) {
            lines.push((&r.solver, OTHER));
        }
    }
    for (name, colour) in lines {
        let mut line: Vec<(&Row, f64)> = plotted
            .iter()
            .filter(|(r, _)| r.solver == name)
            .copied()
            .collect();
        line.sort_by(|a, b| a.0.dt.total_cmp(&b.0.dt).reverse());
        chart
            .draw_series(LineSeries::new(
                line.iter().map(|(r, e)| (cost(r), y(*e))),
                colour.stroke_width(2),
            ))
            .map_err(err)?;
        for (r, e) in line {
            marker(chart.plotting_area(), rate(r), (cost(r), y(e)), colour)?;
        }
    }
    Ok(())
}

/// Draws the marker for a rate at `at`: a triangle for 30 Hz, a circle for 60 Hz, a square
/// for 120 Hz (and a cross for any other).
fn marker<DB: DrawingBackend, CT: CoordTranslate>(
    area: &DrawingArea<DB, CT>,
    hz: u32,
    at: CT::From,
    colour: RGBColor,
) -> Result<(), String> {
    let style = colour.filled();
    let at = EmptyElement::at(at);
    match hz {
        30 => area.draw(&(at + TriangleMarker::new((0, 0), 6, style))),
        60 => area.draw(&(at + Circle::new((0, 0), 5, style))),
        120 => area.draw(&(at + Rectangle::new([(-4, -4), (4, 4)], style))),
        _ => area.draw(&(at + Cross::new((0, 0), 5, colour.stroke_width(2)))),
    }
    .map_err(err)
}

/// `text` in lines of at most [`LEGEND_LINE`] characters, broken between words.
fn wrap(text: &str) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split(' ') {
        match lines.last_mut() {
            Some(line) if line.len() + 1 + word.len() <= LEGEND_LINE => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_owned()),
        }
    }
    lines
}

/// Ticks at whole decades from `lo` to `hi` (both decades), every decade or every few so there
/// are at most seven, always including `lo`.
fn ticks(lo: f64, hi: f64) -> Vec<f64> {
    let (lo, hi) = (lo.log10().round() as i32, hi.log10().round() as i32);
    let step = ((hi - lo) as usize).div_ceil(6).max(1);
    (lo..=hi).step_by(step).map(|k| 10f64.powi(k)).collect()
}

/// A tick label: decades only (`0.01`, `1`, `100`, `1e-6`), `0` at the zero line, nothing in
/// between, so labels never run together.
fn decade_label(v: f64, zero: Option<f64>) -> String {
    if zero.is_some_and(|z| (v / z - 1.0).abs() < 1e-6) {
        return "0".into();
    }
    let e = v.log10();
    if (e - e.round()).abs() > 1e-6 {
        return String::new();
    }
    match e.round() as i32 {
        k @ -2..=3 => format!("{}", 10f64.powi(k)),
        k => format!("1e{k}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::config::Solver;

    #[test]
    fn every_setting_of_the_study_has_its_colour_and_the_reference_comes_last() {
        let names: Vec<String> = Solver::STUDY.iter().map(Solver::to_string).collect();
        let coloured: Vec<&str> = SETTINGS.iter().map(|(name, _)| *name).collect();
        assert_eq!(names, coloured);
        assert_eq!(Solver::STUDY.last(), Some(&Solver::REFERENCE));
    }

    #[test]
    fn the_legend_wraps_between_words_and_keeps_them_all() {
        let note = horizons(&[]).repeat(3);
        let lines = wrap(&note);
        assert!(lines.len() > 1);
        assert!(lines.iter().all(|l| l.len() <= LEGEND_LINE), "{lines:?}");
        assert_eq!(lines.join(" "), note);
    }
}
