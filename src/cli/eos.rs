//! `moving_circles eos`: the hard-disk equation of state, one area fraction after another with
//! a progress bar; prints a table and writes `eos.csv`, `eos.svg` and `eos.png`.

use std::path::Path;

use super::{prepare_out, write_results};
use crate::tools::eos::plot::EosFigure;
use crate::tools::eos::{EosOptions, EosPoint, measure};
use crate::tools::io::say;

/// Measures every area fraction of `options` and writes the results into `out`.
pub fn eos(options: &EosOptions, out: &Path) -> anyhow::Result<()> {
    options.check()?;
    prepare_out(out, &["eos.csv", "eos.svg", "eos.png"])?;
    let bar = indicatif::ProgressBar::new(options.area_fractions.len() as u64).with_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} area fractions  {msg}")
            .expect("valid template"),
    );
    say(format_args!(
        "{:>6} {:>6} {:>9} {:>8} {:>9} {:>9} {:>8} {:>10} {:>7} {:>7}",
        "eta", "n", "Z", "± err", "Henderson", "Liu", "vs Liu", "collisions", "KS", "s"
    ));
    let mut points = Vec::new();
    for &phi in &options.area_fractions {
        bar.set_message(format!("η = {phi}"));
        let point = measure(options, phi).map_err(anyhow::Error::msg)?;
        bar.suspend(|| say(row(&point)));
        bar.inc(1);
        points.push(point);
    }
    bar.finish_and_clear();
    write_results(
        &points,
        &EosFigure {
            points: &points,
            bars: "exact, block error bars",
        },
        out,
        "eos",
    )
}

fn row(p: &EosPoint) -> String {
    format!(
        "{:>6} {:>6} {:>9.4} {:>8.4} {:>9.4} {:>9.4} {:>+7.2}% {:>10} {:>7.4} {:>7.1}",
        p.area_fraction,
        p.n,
        p.z,
        p.z_error,
        p.henderson,
        p.liu,
        100.0 * p.vs_liu,
        p.collisions,
        p.speed_ks,
        p.wall_seconds
    )
}
