//! `moving_circles accuracy`: run the accuracy study with a progress bar, print its table and
//! write `accuracy.csv` with the figure as `accuracy.svg` and `accuracy.png`; then the pile
//! scenes, their table and picks printed and written to `piles.csv`.

use std::path::Path;

use anyhow::Context;

use super::{prepare_out, write_results};
use crate::tools::accuracy::front::MEASURES;
use crate::tools::accuracy::piles::{pile_study, pile_table};
use crate::tools::accuracy::plot::AccuracyFigure;
use crate::tools::accuracy::report::{to_fronts, to_table};
use crate::tools::accuracy::{Case, default_cases, pile_cases, pile_settings, settings, study};
use crate::tools::io::{csv_text, say, write_atomically};

/// Runs the study on the scenes in `scenes` (one step size and shorter runs when `quick`) and
/// writes its CSV and plot into `out`.
pub fn accuracy(out: &Path, scenes: &Path, quick: bool) -> anyhow::Result<()> {
    // Every scene read and every output checked before the first run: a bad pile scene or an
    // unwritable piles.csv must not end the study after the gases have run and been written.
    let cases = default_cases(scenes, quick)?;
    let pile_cases = pile_cases(scenes, quick)?;
    let settings = settings(quick);
    prepare_out(
        out,
        &["accuracy.csv", "accuracy.svg", "accuracy.png", "piles.csv"],
    )?;
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
    to_fronts(&rows, &MEASURES).lines().for_each(say);
    write_results(&rows, &AccuracyFigure::study(&rows), out, "accuracy")?;
    piles(out, &pile_cases, quick)
}

/// The pile part of the study on `cases`: runs it with a progress bar, prints its table and
/// picks, and writes `piles.csv` into `out`.
fn piles(out: &Path, cases: &[Case], quick: bool) -> anyhow::Result<()> {
    let settings = pile_settings(quick);
    let bar = indicatif::ProgressBar::new((cases.len() * settings.len()) as u64).with_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} pile runs  {msg}")
            .expect("valid template"),
    );
    let mut runs_done = 0;
    let rows = pile_study(cases, &settings, |case, (solver, dt)| {
        bar.set_position(runs_done);
        runs_done += 1;
        bar.set_message(format!("{}: {solver} at {:.0} Hz", case.name, 1.0 / dt));
    });
    bar.finish_and_clear();
    pile_table(&rows).lines().for_each(say);
    let csv = out.join("piles.csv");
    let text = csv_text(&rows).context("formatting the CSV")?;
    write_atomically(&csv, text.as_bytes())
        .with_context(|| format!("writing {}", csv.display()))?;
    say(format_args!("wrote {}", csv.display()));
    Ok(())
}
