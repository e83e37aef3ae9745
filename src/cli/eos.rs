//! `moving_circles eos`: the hard-disk equation of state, each area fraction a task of a
//! sweep (planned into `OUT/eos-tasks/` with the `eos` measure, run `--jobs` at a time by the
//! runner of `sweep run`); prints a table and writes `eos.csv`, `eos.svg` and `eos.png`.
//! Stopped and run again with the same options, it measures only the points not done (a
//! finished run's are measured again); the same options as a spec run on Slurm unchanged
//! (`assets/sweeps/eos.ron`).

use std::path::Path;

use super::sweep::spec::{
    Axis, Combine, EosMeasure, SlurmSettings, SweepFigure, SweepSpec, TaskMeasure,
};
use super::{prepare_out, sweep, write_results};
use crate::tools::eos::plot::EosFigure;
use crate::tools::eos::{EosOptions, EosPoint};
use crate::tools::io::say;

/// Measures every area fraction of `options`, `jobs` at a time, and writes the results into
/// `out`; the tasks' folder is `out/eos-tasks`.
pub fn eos(options: &EosOptions, out: &Path, jobs: usize) -> anyhow::Result<()> {
    options.check()?;
    prepare_out(out, &["eos.csv", "eos.svg", "eos.png"])?;
    let spec = sweep_spec(options);
    spec.check()
        .map_err(|e| anyhow::anyhow!("the options as a sweep: {e}"))?;
    let tasks = out.join("eos-tasks");
    sweep::start_over_if_finished(&tasks, std::slice::from_ref(&tasks))?;
    sweep::plan_spec(&spec, "these `eos` options", &tasks)?;
    sweep::run(&tasks, jobs)?;
    let points = sweep::eos_points(&tasks)?;
    say(format_args!(
        "{:>6} {:>6} {:>9} {:>8} {:>9} {:>9} {:>8} {:>10} {:>7} {:>7}",
        "eta", "n", "Z", "± err", "Henderson", "Liu", "vs Liu", "collisions", "KS", "s"
    ));
    points.iter().map(row).for_each(say);
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

/// The sweep `eos` runs for `options`: the `eos` measure at each area fraction, one seed,
/// the figure drawn at the merge, Slurm's settings the defaults. With the default options it
/// is `assets/sweeps/eos.ron`.
pub fn sweep_spec(options: &EosOptions) -> SweepSpec {
    SweepSpec {
        scene: None,
        particles: None,
        boundary: None,
        length: None,
        measure: TaskMeasure::Eos(EosMeasure::of_options(options)),
        axes: vec![
            Axis::AreaFraction(options.area_fractions.clone()),
            Axis::Seed(vec![options.seed]),
        ],
        combine: Combine::Product,
        slurm: SlurmSettings::default(),
        figure: Some(SweepFigure::Eos),
        dump: false,
    }
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
