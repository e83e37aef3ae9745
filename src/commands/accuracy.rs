//! `moving_circles accuracy`: run the accuracy study with a progress bar, print its table and
//! write `accuracy.csv` with the figure as `accuracy.svg` and `accuracy.png`.

use std::path::Path;

use anyhow::Context;

use super::write_results;
use crate::accuracy::plot::AccuracyFigure;
use crate::accuracy::report::{to_fronts, to_table};
use crate::accuracy::{default_cases, settings, study};
use crate::io::say;

/// Runs the study on the scenes in `scenes` (one step size and shorter runs when `quick`) and
/// writes its CSV and plot into `out`.
pub fn accuracy(out: &Path, scenes: &Path, quick: bool) -> anyhow::Result<()> {
    let cases = default_cases(scenes, quick)?;
    let settings = settings(quick);
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let bar = indicatif::ProgressBar::new((cases.len() * (settings.len() + 1)) as u64).with_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} runs  {msg}")
            .expect("valid template"),
    );
    let mut runs_done = 0;
    let rows = study(&cases, &settings, |case, setting| {
        bar.set_position(runs_done);
        runs_done += 1;
        bar.set_message(match setting {
            None => format!("{}: exact reference", case.name),
            Some((solver, dt)) => format!("{}: {solver} at {:.0} Hz", case.name, 1.0 / dt),
        });
    });
    bar.finish_and_clear();
    to_table(&rows).lines().for_each(say);
    to_fronts(&rows).lines().for_each(say);
    write_results(&rows, &AccuracyFigure(&rows), out, "accuracy")
}
