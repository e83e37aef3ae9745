//! `moving_circles sweep`: a planned grid run here gives each task the report `run` gives for
//! the same settings; a task stopped by SIGTERM goes on from its checkpoint to the same
//! result; a finished task is not run again; hostile specs and folders are refused naming
//! what is wrong.

use std::path::Path;
use std::time::Duration;

use crate::common::binary::{
    command, moving_circles, read_report, run_report, scratch_dir, stderr, stdout, successful,
};
use moving_circles::cli::sweep::spec::SweepSpec;
use serde_json::Value;

/// A report without the fields that time the machine.
fn without_timings(mut report: Value) -> Value {
    let object = report.as_object_mut().unwrap();
    object.remove("wall_seconds");
    object.remove("ms_per_step");
    object.remove("source");
    report
}

/// Writes `text` as the spec `name` in `dir`; its path.
fn spec_file(dir: &Path, text: &str) -> String {
    let path = dir.join("spec.ron");
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_owned()
}

/// The scene the tests sweep over, absolute.
fn gas1k() -> String {
    format!("{}/assets/scenes/gas1k.ron", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn each_task_of_a_sweep_reports_what_run_reports_for_its_settings() {
    let dir = scratch_dir("sweep", "grid");
    let spec = spec_file(
        &dir,
        &format!(
            r#"(scene: "{}", length: steps(20), axes: [solver(["discrete", "soft=4"]), seed([1, 2])],
                dump: true)"#,
            gas1k()
        ),
    );
    let out = dir.join("out");
    let out = out.to_str().unwrap();
    successful(&["sweep", "plan", &spec, "--out", out]);
    successful(&["sweep", "run", out, "--jobs", "2"]);
    successful(&["sweep", "merge", out]);
    let merged: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/merged.json")).unwrap())
            .unwrap();
    let rows = merged.as_array().unwrap();
    assert_eq!(rows.len(), 4);
    // Task 3 is the last of the product: soft=4, seed 2.
    let task = &rows[3]["task"];
    assert_eq!(
        (task["solver"].as_str(), task["seed"].as_u64()),
        (Some("soft=4"), Some(2))
    );
    let dump = dir.join("direct.txt");
    let direct = run_report(
        "sweep",
        "direct",
        &[
            "run",
            "--scene",
            &gas1k(),
            "--solver",
            "soft=4",
            "--seed",
            "2",
            "--steps",
            "20",
            "--dump",
            dump.to_str().unwrap(),
        ],
    );
    assert_eq!(
        std::fs::read(dir.join("out/results/3.dump.txt")).unwrap(),
        std::fs::read(&dump).unwrap(),
        "the task's final state is the run's"
    );
    assert_eq!(
        without_timings(rows[3]["report"].clone()),
        without_timings(direct)
    );
    let csv = std::fs::read_to_string(dir.join("out/merged.csv")).unwrap();
    assert_eq!(csv.lines().count(), 5, "a header and four rows");
    assert!(csv.starts_with("task,"));
    // Done tasks are not run again.
    let again = successful(&["sweep", "task", out, "--index", "3"]);
    assert!(
        stdout(&again).contains("done already"),
        "{}",
        stdout(&again)
    );
    let status = successful(&["sweep", "status", out]);
    assert!(stdout(&status).contains("4 done"), "{}", stdout(&status));
    std::fs::remove_dir_all(dir).unwrap();
}

/// Plans a sweep of one long `soft` task into `dir/tried` and `dir/whole`, and runs the
/// second's task whole; the two folders.
fn long_task_twice(dir: &Path) -> [std::path::PathBuf; 2] {
    let spec = spec_file(
        dir,
        &format!(
            r#"(scene: "{}", length: steps(3000), axes: [solver(["soft=4"])])"#,
            gas1k()
        ),
    );
    let folders = ["tried", "whole"].map(|name| dir.join(name));
    for out in &folders {
        successful(&["sweep", "plan", &spec, "--out", out.to_str().unwrap()]);
    }
    successful(&[
        "sweep",
        "task",
        folders[1].to_str().unwrap(),
        "--index",
        "0",
    ]);
    folders
}

#[test]
fn a_task_stopped_by_sigterm_goes_on_from_its_checkpoint_to_the_same_result() {
    let dir = scratch_dir("sweep", "resume");
    let [stopped, whole] = long_task_twice(&dir);
    let mut child = command(&["sweep", "task", stopped.to_str().unwrap()])
        .env("SLURM_ARRAY_TASK_ID", "0")
        .spawn()
        .unwrap();
    // Until it has stepped a while (the first steps place 1000 circles).
    std::thread::sleep(Duration::from_millis(1500));
    let pid = child.id().to_string();
    std::process::Command::new("kill")
        .args(["-TERM", &pid])
        .status()
        .unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(143), "stopped by the signal");
    assert!(stopped.join("work/0.checkpoint").exists());
    assert!(
        !stopped.join("results/0.json").exists(),
        "no result of a stopped task"
    );
    let resumed = successful(&["sweep", "task", stopped.to_str().unwrap(), "--index", "0"]);
    assert!(
        stdout(&resumed).contains("going on from"),
        "{}",
        stdout(&resumed)
    );
    assert!(!stopped.join("work/0.checkpoint").exists());
    let [a, b] = [&stopped, &whole].map(|out| read_report(&out.join("results/0.json")));
    assert_eq!(without_timings(a), without_timings(b));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_field_axis_runs_each_task_on_its_own_scene_file_and_bad_fields_are_refused() {
    let dir = scratch_dir("sweep", "field");
    let spec = spec_file(
        &dir,
        &format!(
            r#"(scene: "{}", length: steps(30),
                axes: [field("effects.restitution", [0.5, 1.0]), seed([1, 2]),
                       field("spawn.radius", [(0.08, 0.08)]),
                       field("spawn.placement", ["lattice"])])"#,
            gas1k()
        ),
    );
    let out = dir.join("out");
    let out = out.to_str().unwrap();
    successful(&["sweep", "plan", &spec, "--out", out]);
    successful(&["sweep", "run", out, "--jobs", "2"]);
    // Two distinct scenes, the restitution's: tasks 0 and 1 share scenes/0.ron.
    let scene = std::fs::read_to_string(dir.join("out/scenes/0.ron")).unwrap();
    assert!(scene.contains("restitution: 0.5,"), "{scene}");
    assert!(scene.contains("placement: lattice"), "{scene}");
    assert!(!dir.join("out/scenes/2.ron").exists());
    let merged: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/merged.json")).unwrap())
            .unwrap();
    let task = &merged[1]["task"];
    assert_eq!(task["fields"]["effects.restitution"].as_f64(), Some(0.5));
    assert_eq!(task["seed"].as_u64(), Some(2));
    let scenes: Vec<_> = (0..4).map(|k| merged[k]["task"]["scene"].clone()).collect();
    assert_eq!(
        scenes,
        [
            "scenes/0.ron",
            "scenes/0.ron",
            "scenes/1.ron",
            "scenes/1.ron"
        ]
    );
    let own = dir.join("out/scenes/0.ron");
    let direct = run_report(
        "sweep",
        "field-direct",
        &[
            "run",
            "--scene",
            own.to_str().unwrap(),
            "--seed",
            "2",
            "--steps",
            "30",
        ],
    );
    assert_eq!(
        without_timings(merged[1]["report"].clone()),
        without_timings(direct)
    );
    // Half the restitution loses energy the elastic tasks keep.
    let drift = |row: usize| merged[row]["report"]["energy_drift"].as_f64().unwrap();
    assert!(
        drift(1) < -0.01 && drift(3).abs() < 1e-6,
        "{} {}",
        drift(1),
        drift(3)
    );
    for (axis, expected) in [
        (
            r#"field("effects.bounciness", [1.0])"#,
            "`effects` has no field `bounciness`",
        ),
        (
            r#"field("effects.restitution", [-2.0])"#,
            "effects.restitution",
        ),
        (
            r#"field("effects.restitution", ["high"])"#,
            "setting effects.restitution",
        ),
        (
            r#"field("drop.rate", [1.0])"#,
            "`drop` is not set in the scene",
        ),
        (r#"field("circles.3.radius", [1.0])"#, "is a list of 0"),
    ] {
        let spec = spec_file(
            &dir,
            &format!(
                r#"(scene: "{}", length: steps(5), axes: [{axis}])"#,
                gas1k()
            ),
        );
        let other = dir.join("refused");
        let refused = moving_circles(&["sweep", "plan", &spec, "--out", other.to_str().unwrap()]);
        assert!(!refused.status.success(), "{axis}");
        assert!(
            stderr(&refused).contains(expected),
            "{axis}: {}",
            stderr(&refused)
        );
        assert!(
            !other.join("spec.ron").exists(),
            "no plan of a refused spec"
        );
        let _ = std::fs::remove_dir_all(other);
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_task_killed_at_any_moment_loses_nothing_and_its_rerun_gives_the_same_result() {
    let dir = scratch_dir("sweep", "killed");
    let [killed, whole] = long_task_twice(&dir);
    let signal = |child: &std::process::Child, name: &str| {
        let pid = child.id().to_string();
        std::process::Command::new("kill")
            .args([name, &pid])
            .status()
            .unwrap();
    };
    let task = || {
        command(&["sweep", "task", killed.to_str().unwrap(), "--index", "0"])
            .spawn()
            .unwrap()
    };
    // Killed while stepping, with nothing saved yet.
    let mut child = task();
    std::thread::sleep(Duration::from_millis(1500));
    signal(&child, "-KILL");
    child.wait().unwrap();
    // Stopped, then killed a few milliseconds later: while its checkpoint is written, or
    // after; whichever it was, the folder holds a whole checkpoint or none.
    let mut child = task();
    std::thread::sleep(Duration::from_millis(2000));
    signal(&child, "-TERM");
    std::thread::sleep(Duration::from_millis(3));
    signal(&child, "-KILL");
    child.wait().unwrap();
    assert!(
        !killed.join("results/0.json").exists(),
        "no result of a killed task"
    );
    // Resumed from whatever was saved, and killed again while it goes on.
    let mut child = task();
    std::thread::sleep(Duration::from_millis(1000));
    signal(&child, "-KILL");
    child.wait().unwrap();
    let saved = killed.join("work/0.checkpoint").exists();
    let last = successful(&["sweep", "task", killed.to_str().unwrap(), "--index", "0"]);
    assert_eq!(
        stdout(&last).contains("going on from"),
        saved,
        "a checkpoint left is gone on from: {}",
        stdout(&last)
    );
    let [a, b] = [&killed, &whole].map(|out| read_report(&out.join("results/0.json")));
    assert_eq!(without_timings(a), without_timings(b));
    let status = successful(&["sweep", "status", killed.to_str().unwrap()]);
    assert!(stdout(&status).contains("1 done"), "{}", stdout(&status));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn an_eos_sweep_draws_the_mean_z_of_each_area_fraction_over_its_seeds() {
    let dir = scratch_dir("sweep", "eos");
    let scene = format!("{}/assets/scenes/eos_box.ron", env!("CARGO_MANIFEST_DIR"));
    let spec = spec_file(
        &dir,
        &format!(
            r#"(scene: "{scene}", length: steps(40),
                axes: [area_fraction([0.2, 0.4]), seed([1, 2])], figure: Some(eos))"#
        ),
    );
    let out = dir.join("out");
    let out = out.to_str().unwrap();
    successful(&["sweep", "plan", &spec, "--out", out]);
    let ran = successful(&["sweep", "run", out, "--jobs", "2"]);
    assert!(
        stdout(&ran).contains("equation of state of 2 area fractions"),
        "{}",
        stdout(&ran)
    );
    let merged: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/merged.json")).unwrap())
            .unwrap();
    let z = |row: usize| merged[row]["report"]["z"].as_f64().unwrap();
    // The product puts the seeds of 0.4 at rows 2 and 3; the figure's point is their mean.
    let mean = (z(2) + z(3)) / 2.0;
    assert!(
        stdout(&ran).contains(&format!("area fraction 0.4: z {mean:.5} ± ")),
        "the mean of {} and {}: {}",
        z(2),
        z(3),
        stdout(&ran)
    );
    let drawing = std::fs::read_to_string(dir.join("out/eos.svg")).unwrap();
    assert!(drawing.starts_with("<svg"), "{}", &drawing[..80]);
    assert!(std::fs::metadata(dir.join("out/eos.png")).unwrap().len() > 1000);
    assert!(mean > 1.5, "Z at 0.4 is about 2.5, not {mean}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn an_accuracy_sweep_draws_each_settings_cost_against_its_errors() {
    let dir = scratch_dir("sweep", "accuracy");
    let spec = spec_file(
        &dir,
        &format!(
            r#"(scene: "{}", length: seconds(0.5),
                axes: [solver(["discrete", "exact"]), dt([0.03333333333333333, 0.016666666666666666]),
                       seed([1, 2])],
                figure: Some(accuracy))"#,
            gas1k()
        ),
    );
    let out = dir.join("out");
    let out = out.to_str().unwrap();
    successful(&["sweep", "plan", &spec, "--out", out]);
    let ran = successful(&["sweep", "run", out, "--jobs", "2"]);
    let said = stdout(&ran);
    // The front of the deepest overlap ends at `exact` (at whichever rate is cheaper), which
    // leaves none.
    let overlap = said
        .lines()
        .find(|l| l.starts_with("gas1k") && l.contains("deepest overlap"))
        .unwrap_or_else(|| panic!("no front of the deepest overlap: {said}"));
    let last = overlap.rsplit(" > ").next().unwrap();
    assert!(last.contains("exact at"), "{overlap}");
    assert!(overlap.ends_with("(0.00e0)"), "{overlap}");
    assert!(said.contains("drew what accuracy costs into"), "{said}");
    let drawing = std::fs::read_to_string(dir.join("out/accuracy.svg")).unwrap();
    for measure in moving_circles::tools::accuracy::front::REPORT_MEASURES {
        assert!(
            drawing.contains(measure.title),
            "no panel of {}",
            measure.title
        );
    }
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(dir.join("out/accuracy.png")).unwrap(),
    ));
    let info = decoder.read_info().unwrap().info().clone();
    assert_eq!(
        (info.width, info.height),
        moving_circles::tools::accuracy::plot::AccuracyFigure::size_for(1)
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_trace_sweep_is_the_accuracy_study_of_its_scene_and_a_pile_sweep_its_pile_rows() {
    let dir = scratch_dir("sweep", "study");
    let spec = spec_file(
        &dir,
        &format!(
            r#"(scene: "{}", length: seconds(0.3), measure: trace(horizon: 0.1),
                axes: [solver(["discrete", "exact"]), dt([0.016666666666666666])],
                figure: Some(accuracy))"#,
            gas1k()
        ),
    );
    let out = dir.join("out");
    let out = out.to_str().unwrap();
    successful(&["sweep", "plan", &spec, "--out", out]);
    successful(&["sweep", "run", out, "--jobs", "2"]);
    // The study's rows: `exact` at 60 Hz is the reference (no error); `discrete` is not.
    let csv = std::fs::read_to_string(dir.join("out/accuracy.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let cell = |solver: &str, column: &str| -> f64 {
        let k = header.iter().position(|&h| h == column).unwrap();
        let line = csv
            .lines()
            .find(|l| l.split(',').nth(2) == Some(solver))
            .unwrap_or_else(|| panic!("no {solver} row: {csv}"));
        line.split(',').nth(k).unwrap().parse().unwrap()
    };
    assert_eq!(cell("exact", "position_error"), 0.0, "{csv}");
    assert!(cell("discrete", "position_error") > 0.0, "{csv}");
    assert!(cell("discrete", "max_penetration") > 0.0, "{csv}");
    // All five of the study's measures are drawn.
    let drawing = std::fs::read_to_string(dir.join("out/accuracy.svg")).unwrap();
    for measure in moving_circles::tools::accuracy::front::MEASURES {
        assert!(
            drawing.contains(measure.title),
            "no panel of {}",
            measure.title
        );
    }
    let pyramid = format!("{}/assets/scenes/pyramid.ron", env!("CARGO_MANIFEST_DIR"));
    let spec = spec_file(
        &dir,
        &format!(
            r#"(scene: "{pyramid}", length: seconds(0.5), measure: pile,
                axes: [solver(["discrete", "soft"])])"#
        ),
    );
    let piles = dir.join("piles");
    let piles = piles.to_str().unwrap();
    successful(&["sweep", "plan", &spec, "--out", piles]);
    successful(&["sweep", "run", piles, "--jobs", "2"]);
    let csv = std::fs::read_to_string(dir.join("piles/piles.csv")).unwrap();
    assert!(csv.starts_with("scene,n,solver,dt,"), "{csv}");
    assert_eq!(csv.lines().count(), 3, "{csv}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_sweep_over_a_particle_file_reports_what_run_reports_for_it() {
    let dir = scratch_dir("sweep", "particles");
    let file = format!(
        "{}/tests/data/particles/p10.txt",
        env!("CARGO_MANIFEST_DIR")
    );
    let spec = spec_file(
        &dir,
        &format!(
            r#"(particles: "{file}", boundary: periodic, length: steps(30),
                axes: [solver(["discrete", "exact"])])"#
        ),
    );
    let out = dir.join("out");
    let out = out.to_str().unwrap();
    successful(&["sweep", "plan", &spec, "--out", out]);
    successful(&["sweep", "run", out, "--jobs", "2"]);
    for (index, solver) in ["discrete", "exact"].iter().enumerate() {
        let swept = read_report(&dir.join(format!("out/results/{index}.json")));
        let direct = run_report(
            "sweep",
            "particles-direct",
            &[
                "run",
                "--particles",
                &file,
                "--boundary",
                "periodic",
                "--solver",
                solver,
                "--steps",
                "30",
            ],
        );
        assert_eq!(swept["boundary"], "periodic");
        assert_eq!(without_timings(swept), without_timings(direct), "{solver}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn hostile_specs_are_refused_naming_the_field() {
    let scene = gas1k();
    let cases = [
        (r#"axes: [seed([])]"#, "axes[0].seed: has no values"),
        (r#"axes: [solver(["magic"])]"#, "axes[0].solver[0]"),
        (r#"axes: [dt([0.0])]"#, "axes[0].dt[0]"),
        (r#"axes: [seed([1]), seed([2])]"#, "already axes[0]"),
        (
            r#"axes: [seed([1, 2]), dt([0.01])], combine: zip"#,
            "combine",
        ),
        (r#"slurm: (time_limit: "soon")"#, "slurm.time_limit"),
        (r#"slurm: (concurrency: 0)"#, "slurm.concurrency"),
        (r#"colour: "red""#, "colour"),
        (r#"axes: [seed([1])], figure: Some(eos)"#, "figure: `eos`"),
        (
            r#"axes: [field("effects restitution", [1.0])]"#,
            "is not a field's path",
        ),
        (
            r#"axes: [field("effects.drag", [0.1]), field("effects.drag", [0.2])]"#,
            "field \"effects.drag\" is already axes[0]",
        ),
        (
            r#"axes: [field("circles.00.radius", [1.0])]"#,
            "is not a field's path",
        ),
        (
            r#"axes: [field("spawn.seed", [4])]"#,
            "set by the `seed` axis",
        ),
        (
            r#"axes: [field("effects.restitution", [0.5, inf])]"#,
            "axes[0].field[1]: inf is not a number",
        ),
        (
            r#"axes: [seed([1, 2, 1])]"#,
            "axes[0].seed[2]: repeats axes[0].seed[0]",
        ),
        (
            r#"axes: [area_fraction([0.2]), seed([1])], figure: Some(eos)"#,
            "a `seed` axis of two",
        ),
        (
            r#"axes: [area_fraction([0.2]), seed([1, 2]), dt([0.01, 0.02])], figure: Some(eos)"#,
            "axes[2] varies `dt` too",
        ),
        (
            r#"axes: [solver(["discrete", "swept"])], figure: Some(accuracy)"#,
            "a `solver` axis that includes \"exact\"",
        ),
        (
            r#"axes: [solver(["discrete", "exact"])], figure: Some(accuracy)"#,
            "`accuracy` compares runs over the same simulated time",
        ),
        (
            r#"axes: [solver(["soft", "soft=4"])]"#,
            "axes[0].solver[1]: repeats axes[0].solver[0]",
        ),
    ];
    // A billion tasks: three axes of a thousand values.
    let thousand = |f: &dyn Fn(usize) -> String| (0..1000).map(f).collect::<Vec<_>>().join(",");
    let billion = format!(
        "axes: [seed([{}]), dt([{}]), area_fraction([{}])]",
        thousand(&|k| k.to_string()),
        thousand(&|k| format!("{}", 0.001 + k as f64 * 1e-5)),
        thousand(&|k| format!("{}", 0.01 + k as f64 * 1e-4)),
    );
    let cases = cases
        .iter()
        .map(|&(extra, expected)| (extra.to_owned(), expected))
        .chain([(billion, "make 1000000000 tasks, more than the 100000")]);
    for (extra, expected) in cases {
        let text = format!(r#"(scene: "{scene}", length: steps(10), {extra})"#);
        let error = SweepSpec::parse(&text, "s.ron").unwrap_err();
        assert!(error.contains(expected), "{extra}: {error}");
    }
    // The `eos` measure places its own disks and counts collisions: no scene, no length, and
    // only area fraction and seed vary; its options are checked as the `eos` command's.
    let eos = r#"measure: eos(n: 100), axes: [area_fraction([0.3])]"#;
    for (text, expected) in [
        ("(length: steps(10))".to_owned(), "scene: missing"),
        (format!(r#"(scene: "{scene}")"#), "length: missing"),
        (
            format!(r#"(scene: "{scene}", {eos})"#),
            "scene: the `eos` measure",
        ),
        (
            format!("(length: steps(10), {eos})"),
            "length: the `eos` measure",
        ),
        (
            r#"(measure: eos(n: 100), axes: [area_fraction([0.3]), dt([0.01])])"#.to_owned(),
            "axes[1]: the `eos` measure varies `area_fraction` and `seed` alone, not `dt`",
        ),
        (
            r#"(measure: eos(n: 1), axes: [area_fraction([0.3])])"#.to_owned(),
            "measure.eos.n: needs 2 to",
        ),
        (
            r#"(measure: eos(n: 100), axes: [area_fraction([0.3, 0.9])])"#.to_owned(),
            "axes[0].area_fraction[1]: each must be in (0, 0.85]",
        ),
        (
            r#"(measure: eos(n: 100))"#.to_owned(),
            "axes: the `eos` measure needs",
        ),
        (
            r#"(measure: eos(n: 100), axes: [area_fraction([0.3])], dump: true)"#.to_owned(),
            "dump: only the `report` measure",
        ),
        (
            format!(r#"(scene: "{scene}", particles: "p.txt", length: steps(10))"#),
            "particles: give a scene or a particle file, not both",
        ),
        (
            r#"(particles: "p.txt", length: steps(10), axes: [seed([1, 2])])"#.to_owned(),
            "axes[0]: a particle file places every circle itself: it has no `seed`",
        ),
        (
            format!(r#"(scene: "{scene}", boundary: periodic, length: steps(10))"#),
            "boundary: goes with a particle file",
        ),
        (
            r#"(particles: "p.txt", measure: eos(n: 100), axes: [area_fraction([0.3])])"#
                .to_owned(),
            "particles: only the `report` measure runs a particle file",
        ),
        (
            format!(
                r#"(scene: "{scene}", length: seconds(1.0), figure: Some(accuracy),
                    axes: [solver(["discrete", "exact"]), dt([0.01, 0.02])])"#
            ),
            "needs 0.016666666666666666 (1/60)",
        ),
        (
            format!(r#"(scene: "{scene}", length: steps(10), measure: trace(horizon: 0.1))"#),
            "length: the `trace` measure runs for a time",
        ),
        (
            format!(r#"(scene: "{scene}", length: seconds(1.0), measure: trace(horizon: 2.0))"#),
            "measure.trace.horizon: must be above 0 and at most the length",
        ),
        (
            format!(
                r#"(scene: "{scene}", length: seconds(1.0), measure: trace(horizon: 0.1),
                    axes: [solver(["discrete", "soft"])])"#
            ),
            "axes: the `trace` measure compares each setting with `exact`",
        ),
        (
            format!(
                r#"(scene: "{scene}", length: seconds(1.0), measure: pile, boundary: periodic)"#
            ),
            "boundary: goes with a particle file",
        ),
        (
            format!(
                r#"(scene: "{scene}", length: seconds(1.0), measure: pile, axes: [seed([1, 2])])"#
            ),
            "axes[0]: the `pile` measure varies `solver` and `dt` alone, not `seed`",
        ),
        (
            format!(
                r#"(scene: "{scene}", length: seconds(1.0), measure: pile, figure: Some(accuracy),
                    axes: [solver(["exact"])])"#
            ),
            "figure: draws what this measure does not measure",
        ),
    ] {
        let error = SweepSpec::parse(&text, "s.ron").unwrap_err();
        assert!(error.contains(expected), "{text}: {error}");
    }
}

#[test]
fn a_folder_holding_another_sweeps_plan_is_refused() {
    let dir = scratch_dir("sweep", "shared");
    let out = dir.join("out");
    let out = out.to_str().unwrap();
    let first = spec_file(
        &dir,
        &format!(
            r#"(scene: "{}", length: steps(5), axes: [seed([1])])"#,
            gas1k()
        ),
    );
    successful(&["sweep", "plan", &first, "--out", out]);
    // The same spec again: nothing to do; also when the plan was written in other words (as
    // an earlier version wrote it: no extensions, `Some(...)`, no `measure`).
    successful(&["sweep", "plan", &first, "--out", out]);
    let planned = dir.join("out/spec.ron");
    let text = std::fs::read_to_string(&planned).unwrap();
    let older: String = text
        .lines()
        .filter(|l| !l.starts_with("#!") && !l.contains("measure:"))
        .map(|l| match l.trim_start().strip_prefix("scene: ") {
            Some(path) => format!("    scene: Some({}),\n", path.trim_end_matches(',')),
            None => format!("{l}\n"),
        })
        .collect();
    assert_ne!(older, text);
    std::fs::write(&planned, older).unwrap();
    let again = successful(&["sweep", "plan", &first, "--out", out]);
    assert!(
        stdout(&again).contains("holds this sweep's plan already"),
        "{}",
        stdout(&again)
    );
    let second = spec_file(
        &dir,
        &format!(
            r#"(scene: "{}", length: steps(5), axes: [seed([2])])"#,
            gas1k()
        ),
    );
    let refused = moving_circles(&["sweep", "plan", &second, "--out", out]);
    assert!(!refused.status.success());
    assert!(
        stderr(&refused).contains("another sweep's plan"),
        "{}",
        stderr(&refused)
    );
    let bad_index = moving_circles(&["sweep", "task", out, "--index", "7"]);
    assert!(
        stderr(&bad_index).contains("has tasks 0 to 0"),
        "{}",
        stderr(&bad_index)
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn the_eos_spec_that_ships_is_the_sweep_the_eos_command_runs() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/sweeps/eos.ron");
    assert_eq!(
        SweepSpec::read(&path).unwrap(),
        moving_circles::cli::eos::sweep_spec(&moving_circles::tools::eos::EosOptions::default())
    );
}

#[test]
fn the_accuracy_specs_that_ship_are_the_sweeps_the_accuracy_command_runs() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let specs =
        moving_circles::cli::accuracy::study_specs(&root.join("assets/scenes"), false).unwrap();
    let dir = root.join("assets/sweeps/accuracy_study");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), specs.len());
    for (name, command) in specs {
        let path = dir.join(format!("{name}.ron"));
        let mut shipped = SweepSpec::read(&path).unwrap();
        // The command names its scene by its absolute path, the file relative to itself.
        shipped.scene = shipped.scene.map(|s| dir.join(s).canonicalize().unwrap());
        assert_eq!(shipped, command, "{}", path.display());
    }
}

#[test]
fn the_specs_that_ship_are_valid_and_name_scenes_that_exist() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/sweeps");
    let mut seen = 0;
    for dir in [root.clone(), root.join("accuracy_study")] {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                continue;
            }
            let spec = SweepSpec::read(&path).unwrap();
            if let Some(scene) = &spec.scene {
                assert!(dir.join(scene).is_file(), "{path:?}: {scene:?}");
            }
            seen += 1;
        }
    }
    assert!(seen >= 9);
}
