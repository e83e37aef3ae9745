//! `moving_circles accuracy`: the accuracy study, each scene a sweep of its settings (planned
//! into `OUT/accuracy-tasks/NAME/` with the `trace` or `pile` measure and run `--jobs` at a
//! time by the runner of `sweep run`); prints its table and fronts and writes `accuracy.csv`
//! with the figure as `accuracy.svg` and `accuracy.png`, then each pile scene's table and
//! picks, and `piles.csv`. Stopped and run again with the same options, it runs only what is
//! missing (a finished study is run again whole).

use std::path::Path;

use anyhow::Context;

use super::sweep::spec::{
    Axis, Combine, SlurmSettings, SpecLength, SweepFigure, SweepSpec, TaskMeasure,
};
use super::{prepare_out, sweep, write_results};
use crate::base::config::Solver;
use crate::tools::accuracy::front::MEASURES;
use crate::tools::accuracy::piles::PILE_SOLVERS;
use crate::tools::accuracy::plot::AccuracyFigure;
use crate::tools::accuracy::report::{to_fronts, to_table};
use crate::tools::accuracy::{Case, SOLVERS, default_cases, pile_cases, steps};
use crate::tools::io::{say, write_csv};

/// Runs the study on the scenes in `scenes` (one step size and shorter runs when `quick`),
/// `jobs` runs at a time, and writes its CSVs and plot into `out`.
pub fn accuracy(out: &Path, scenes: &Path, quick: bool, jobs: usize) -> anyhow::Result<()> {
    // Every scene read and every output checked before the first run: a bad pile scene or an
    // unwritable piles.csv must not end the study after the gases have run and been written.
    let specs = study_specs(scenes, quick)?;
    prepare_out(
        out,
        &["accuracy.csv", "accuracy.svg", "accuracy.png", "piles.csv"],
    )?;
    let tasks = out.join("accuracy-tasks");
    // Every scene is planned before the first runs, so that a folder holding another study's
    // plan is refused before anything runs.
    let dirs: Vec<_> = specs.iter().map(|(name, _)| tasks.join(name)).collect();
    sweep::start_over_if_finished(&tasks, &dirs)?;
    for (name, spec) in &specs {
        sweep::plan_spec(spec, &format!("the study's {name}"), &tasks.join(name))?;
    }
    let (mut rows, mut piles) = (Vec::new(), Vec::new());
    for (name, spec) in &specs {
        let dir = run_case(name, &tasks, jobs)?;
        match spec.measure {
            TaskMeasure::Pile => piles.extend(sweep::pile_rows(&dir)?),
            _ => rows.extend(sweep::trace_rows(&dir)?),
        }
    }
    to_table(&rows).lines().for_each(say);
    to_fronts(&rows, &MEASURES).lines().for_each(say);
    write_results(&rows, &AccuracyFigure::study(&rows), out, "accuracy")?;
    // (Each pile scene's merge printed its table and picks.)
    write_csv(&piles, &out.join("piles.csv"))
}

/// The study's sweeps, one a scene, each with its name: the gases under every solver with the
/// `trace` measure, then the piles under the pile solvers with the `pile` measure, at the
/// study's steps (one when `quick`), the scenes `NAME.ron` in `scenes`. With the default
/// options these are `assets/sweeps/accuracy_study/NAME.ron`.
pub fn study_specs(scenes: &Path, quick: bool) -> anyhow::Result<Vec<(String, SweepSpec)>> {
    let gases = default_cases(scenes, quick)?.into_iter().map(|case| {
        let measure = TaskMeasure::Trace {
            horizon: case.horizon,
        };
        (case, measure, &SOLVERS[..])
    });
    let piles = pile_cases(scenes, quick)?
        .into_iter()
        .map(|case| (case, TaskMeasure::Pile, &PILE_SOLVERS[..]));
    gases
        .chain(piles)
        .map(|(case, measure, solvers)| {
            let spec = case_spec(scenes, &case, measure, solvers, quick)?;
            Ok((case.name, spec))
        })
        .collect()
}

/// The sweep of one case, `case.name.ron` in `scenes` under each of `solvers` at each of the
/// study's steps.
fn case_spec(
    scenes: &Path,
    case: &Case,
    measure: TaskMeasure,
    solvers: &[Solver],
    quick: bool,
) -> anyhow::Result<SweepSpec> {
    let scene = scenes.join(format!("{}.ron", case.name));
    let scene = scene
        .canonicalize()
        .with_context(|| format!("{}", scene.display()))?;
    // The command draws one figure of all its scenes; a sweep run alone draws its own.
    let figure = matches!(measure, TaskMeasure::Trace { .. }).then_some(SweepFigure::Accuracy);
    // The steps first: the study's rows go step by step, each through every solver.
    let spec = SweepSpec {
        scene: Some(scene),
        particles: None,
        boundary: None,
        length: Some(SpecLength::Seconds(case.seconds)),
        measure,
        axes: vec![
            Axis::Dt(steps(quick).to_vec()),
            Axis::Solver(solvers.iter().map(Solver::to_string).collect()),
        ],
        combine: Combine::Product,
        slurm: SlurmSettings::default(),
        figure,
        dump: false,
    };
    spec.check()
        .map_err(|e| anyhow::anyhow!("the study's {} as a sweep: {e}", case.name))?;
    Ok(spec)
}

/// Runs the study's sweep of `name`, planned in `tasks/NAME`; its folder.
fn run_case(name: &str, tasks: &Path, jobs: usize) -> anyhow::Result<std::path::PathBuf> {
    let dir = tasks.join(name);
    say(format_args!("{name}:"));
    sweep::run(&dir, jobs)?;
    Ok(dir)
}
