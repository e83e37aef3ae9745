//! The equation-of-state figure ([`EosFigure`], as SVG and PNG): on the left `Z` against area
//! fraction, measured points with their block
//! error bars over Henderson's and Liu's curves (Liu solid where it is meant, to 0.65, dashed
//! beyond) and the large-N literature value at 0.70; on the right each point's deviation from
//! Liu in per cent, with the ±0.5 % band.

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::EosPoint;
use super::theory::{henderson_z, liu_z};
use crate::tools::figure::{Figure, err, font};

/// Liu's and Henderson's equations are for the fluid: drawn solid up to here.
pub const FLUID_LIMIT: f64 = 0.65;
/// `Z ≈ 10.3` at area fraction 0.70 for large N (Bernard & Krauth 2011; Engel et al. 2013).
pub const LARGE_N_AT_070: (f64, f64) = (0.70, 10.3);

const MEASURED: RGBColor = RGBColor(33, 113, 181);
const LIU: RGBColor = RGBColor(215, 48, 39);
const HENDERSON: RGBColor = RGBColor(120, 120, 120);
const LITERATURE: RGBColor = RGBColor(35, 139, 69);

/// The figure of `points`, their error bars said by `bars` (e.g. "block error bars").
pub struct EosFigure<'a> {
    /// The measured points.
    pub points: &'a [EosPoint],
    /// The solver and what the error bars are, for the legend ("exact, block error bars").
    pub bars: &'a str,
}

impl Figure for EosFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (1400, 560)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let (left, right) = root.split_horizontally(760);
        z_panel(&left, self.points, self.bars)?;
        deviation_panel(&right, self.points)
    }
}

fn z_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    points: &[EosPoint],
    bars: &str,
) -> Result<(), String> {
    let lo = points.iter().map(|p| p.n).min().unwrap_or(0);
    let hi = points.iter().map(|p| p.n).max().unwrap_or(0);
    let n = if lo == hi {
        lo.to_string()
    } else {
        format!("{lo} to {hi}")
    };
    let top = points
        .iter()
        .map(|p| p.z + p.z_error)
        .chain([LARGE_N_AT_070.1, henderson_z(0.72)])
        .filter(|z| z.is_finite())
        .fold(1.0, f64::max);
    let caption = format!("hard disks, N = {n}, periodic: Z = PA/(NkT) against area fraction");
    let mut chart = against_eta(area, &caption, 0.0..(top * 1.05).ceil(), "Z")?;
    let curve = |z: fn(f64) -> f64, from: f64, to: f64| {
        (0..=200)
            .map(move |i| from + (to - from) * i as f64 / 200.0)
            .map(move |eta| (eta, z(eta)))
    };
    chart
        .draw_series(LineSeries::new(
            curve(henderson_z, 0.0, 0.72),
            HENDERSON.stroke_width(2),
        ))
        .map_err(err)?
        .label("Henderson 1975")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 24, y)], HENDERSON.stroke_width(2)));
    chart
        .draw_series(LineSeries::new(
            curve(liu_z, 0.0, FLUID_LIMIT),
            LIU.stroke_width(2),
        ))
        .map_err(err)?
        .label("Liu 2020 (fluid; dashed past 0.65)")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 24, y)], LIU.stroke_width(2)));
    chart
        .draw_series(DashedLineSeries::new(
            curve(liu_z, FLUID_LIMIT, 0.72),
            5,
            4,
            LIU.stroke_width(2),
        ))
        .map_err(err)?;
    chart
        .draw_series([TriangleMarker::new(LARGE_N_AT_070, 9, LITERATURE.filled())])
        .map_err(err)?
        .label("large N, 0.70 (Bernard & Krauth 2011, Engel et al. 2013)")
        .legend(|(x, y)| TriangleMarker::new((x + 12, y), 7, LITERATURE.filled()));
    chart
        .draw_series(points.iter().map(|p| {
            ErrorBar::new_vertical(
                p.area_fraction,
                p.z - p.z_error,
                p.z,
                p.z + p.z_error,
                MEASURED.stroke_width(2),
                8,
            )
        }))
        .map_err(err)?;
    chart
        .draw_series(
            points
                .iter()
                .map(|p| Circle::new((p.area_fraction, p.z), 4, MEASURED.filled())),
        )
        .map_err(err)?
        .label(format!("measured, {bars}"))
        .legend(|(x, y)| Circle::new((x + 12, y), 4, MEASURED.filled()));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE)
        .border_style(BLACK)
        .label_font(font(13))
        .draw()
        .map_err(err)
}

fn deviation_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    points: &[EosPoint],
) -> Result<(), String> {
    let percent = |p: &EosPoint| (100.0 * p.vs_liu, 100.0 * p.z_error / p.liu);
    // Scaled to the fluid points; the dense ones past Liu's range are marked at the edge with
    // their value.
    let reach = 1.3
        * points
            .iter()
            .filter(|p| p.area_fraction <= FLUID_LIMIT)
            .map(|p| {
                let (d, e) = percent(p);
                d.abs() + e
            })
            .filter(|v| v.is_finite())
            .fold(0.8, f64::max);
    let caption = "measured Z against Liu's, per cent";
    let mut chart = against_eta(area, caption, -reach..reach, "Z / Z_Liu − 1 (%)")?;
    chart
        .draw_series([Rectangle::new(
            [(0.0, -0.5), (FLUID_LIMIT, 0.5)],
            LIU.mix(0.12).filled(),
        )])
        .map_err(err)?;
    chart
        .draw_series(LineSeries::new(
            [(0.0, 0.0), (0.75, 0.0)],
            LIU.stroke_width(1),
        ))
        .map_err(err)?;
    let (inside, outside): (Vec<&EosPoint>, Vec<&EosPoint>) = points
        .iter()
        .partition(|p| percent(p).0.abs() + percent(p).1 <= reach);
    chart
        .draw_series(inside.iter().map(|p| {
            let (d, e) = percent(p);
            ErrorBar::new_vertical(
                p.area_fraction,
                d - e,
                d,
                d + e,
                MEASURED.stroke_width(2),
                8,
            )
        }))
        .map_err(err)?;
    chart
        .draw_series(inside.iter().map(|p| {
            let (d, _) = percent(p);
            Circle::new((p.area_fraction, d), 4, MEASURED.filled())
        }))
        .map_err(err)?;
    chart
        .draw_series(outside.iter().map(|p| {
            let edge = reach.copysign(percent(p).0) * 0.94;
            TriangleMarker::new((p.area_fraction, edge), 6, MEASURED.filled())
        }))
        .map_err(err)?;
    let past: Vec<String> = outside
        .iter()
        .map(|p| format!("{}: {:+.1} %", p.area_fraction, percent(p).0))
        .collect();
    if !past.is_empty() {
        area.draw(&Text::new(
            format!("past the edge (triangles): {}", past.join(", ")),
            (70, 80),
            font(13),
        ))
        .map_err(err)?;
    }
    area.draw(&Text::new(
        "shaded: ±0.5 % over the fluid range (to 0.65)",
        (70, 60),
        font(13),
    ))
    .map_err(err)
}

/// A panel over area fractions 0 to 0.75 with `caption`, `y` as its vertical range and
/// `y_desc` as its label, its mesh drawn.
fn against_eta<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: &str,
    y: std::ops::Range<f64>,
    y_desc: &str,
) -> Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>, String> {
    let mut chart = ChartBuilder::on(area)
        .caption(caption, font(18))
        .margin(14)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d(0.0..0.75, y)
        .map_err(err)?;
    chart
        .configure_mesh()
        .light_line_style(WHITE)
        .label_style(font(13))
        .axis_desc_style(font(14))
        .x_desc("area fraction η")
        .y_desc(y_desc)
        .draw()
        .map_err(err)?;
    Ok(chart)
}
