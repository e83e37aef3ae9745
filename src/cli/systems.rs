//! `moving_circles systems`: the systems a scene schedules, one `schedule system` per line.

use std::path::Path;

use crate::step::schedule::{SolverSteps, scheduled_systems};
use crate::tools::io::say;
use crate::tools::run::headless_app;
use crate::tools::scene::Scene;

/// Prints the systems the scene at `scene` schedules, for the step schedule its solver runs.
pub fn systems(scene: &Path) -> anyhow::Result<()> {
    let config = Scene::load(scene)?;
    let solver = config.solver;
    let mut app = headless_app(config);
    // Each solver runs one of the step schedules; the others' systems never run for it.
    let steps = app.world().resource::<SolverSteps>();
    let step = steps.of(solver).map(|s| format!("{:?}", s.schedule));
    let step = step.unwrap_or_default();
    for (schedule, system) in scheduled_systems(&mut app) {
        if schedule.ends_with("Step") && schedule != step {
            continue;
        }
        let name = system.rsplit("::").next().unwrap_or(&system);
        say(format_args!("{schedule} {name}"));
    }
    Ok(())
}
