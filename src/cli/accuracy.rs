//! `moving_circles accuracy`: the accuracy study, each scene a sweep of its settings (planned
//! into `OUT/accuracy-tasks/NAME/` with the `trace` or `pile` measure and run `--jobs` at a
//! time by the runner of `sweep run`); prints its table and fronts and writes `accuracy.csv`
//! with the figure as `accuracy.svg` and `accuracy.png`, then each pile scene's table and
//! picks, and `piles.csv`. Run again with the same options, it runs only what is missing.

use std::path::Path;

use anyhow::Context;

use super::sweep::spec::{Axis, Combine, SlurmSettings, SpecLength, SweepSpec, TaskMeasure};
use super::{prepare_out, sweep, write_results};
use crate::base::config::Solver;
use crate::tools::accuracy::front::MEASURES;
use crate::tools::accuracy::piles::PILE_SOLVERS;
use crate::tools::accuracy::plot::AccuracyFigure;
use crate::tools::accuracy::report::{to_fronts, to_table};
use crate::tools::accuracy::{Case, SOLVERS, default_cases, pile_cases, steps};
use crate::tools::io::{csv_text, say, write_atomically};

/// Runs the study on the scenes in `scenes` (one step size and shorter runs when `quick`),
/// `jobs` runs at a time, and writes its CSVs and plot into `out`.
pub fn accuracy(out: &Path, scenes: &Path, quick: bool, jobs: usize) -> anyhow::Result<()> {
    // Every scene read and every output checked before the first run: a bad pile scene or an
    // unwritable piles.csv must not end the study after the gases have run and been written.
    let cases = default_cases(scenes, quick)?;
    let pile_cases = pile_cases(scenes, quick)?;
    prepare_out(
        out,
        &["accuracy.csv", "accuracy.svg", "accuracy.png", "piles.csv"],
    )?;
    let tasks = out.join("accuracy-tasks");
    let mut rows = Vec::new();
    for case in &cases {
        let measure = TaskMeasure::Trace {
            horizon: case.horizon,
        };
        let dir = run_case(scenes, case, measure, &SOLVERS, quick, &tasks, jobs)?;
        rows.extend(sweep::trace_rows(&dir)?);
    }
    to_table(&rows).lines().for_each(say);
    to_fronts(&rows, &MEASURES).lines().for_each(say);
    write_results(&rows, &AccuracyFigure::study(&rows), out, "accuracy")?;
    let mut piles = Vec::new();
    for case in &pile_cases {
        let dir = run_case(
            scenes,
            case,
            TaskMeasure::Pile,
            &PILE_SOLVERS,
            quick,
            &tasks,
            jobs,
        )?;
        piles.extend(sweep::pile_rows(&dir)?);
    }
    // (Each pile scene's merge printed its table and picks.)
    let csv = out.join("piles.csv");
    let text = csv_text(&piles).context("formatting the CSV")?;
    write_atomically(&csv, text.as_bytes())
        .with_context(|| format!("writing {}", csv.display()))?;
    say(format_args!("wrote {}", csv.display()));
    Ok(())
}

/// The sweep of one case, `case.name.ron` in `scenes` under each of `solvers` at each of the
/// study's steps: planned into `tasks/NAME` and run; its folder.
fn run_case(
    scenes: &Path,
    case: &Case,
    measure: TaskMeasure,
    solvers: &[Solver],
    quick: bool,
    tasks: &Path,
    jobs: usize,
) -> anyhow::Result<std::path::PathBuf> {
    let scene = scenes.join(format!("{}.ron", case.name));
    let scene = scene
        .canonicalize()
        .with_context(|| format!("{}", scene.display()))?;
    // The steps first: the study's rows go step by step, each through every solver.
    let spec = SweepSpec {
        scene: Some(scene),
        length: Some(SpecLength::Seconds(case.seconds)),
        measure,
        axes: vec![
            Axis::Dt(steps(quick).to_vec()),
            Axis::Solver(solvers.iter().map(Solver::to_string).collect()),
        ],
        combine: Combine::Product,
        slurm: SlurmSettings::default(),
        // The study draws one figure of all its scenes.
        figure: None,
        dump: false,
    };
    spec.check()
        .map_err(|e| anyhow::anyhow!("the study's {} as a sweep: {e}", case.name))?;
    let dir = tasks.join(&case.name);
    say(format_args!("{}:", case.name));
    sweep::plan_spec(&spec, &format!("the study's {}", case.name), &dir)?;
    sweep::run(&dir, jobs)?;
    Ok(dir)
}
