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
            r#"(scene: "{}", length: steps(20), axes: [solver(["discrete", "soft=4"]), seed([1, 2])])"#,
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
        ],
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

#[test]
fn a_task_stopped_by_sigterm_goes_on_from_its_checkpoint_to_the_same_result() {
    let dir = scratch_dir("sweep", "resume");
    let spec = spec_file(
        &dir,
        &format!(
            r#"(scene: "{}", length: steps(1500), axes: [solver(["soft=4"])])"#,
            gas1k()
        ),
    );
    let [stopped, whole] = ["stopped", "whole"].map(|name| dir.join(name));
    for out in [&stopped, &whole] {
        successful(&["sweep", "plan", &spec, "--out", out.to_str().unwrap()]);
    }
    successful(&["sweep", "task", whole.to_str().unwrap(), "--index", "0"]);
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
    // The same spec again: nothing to do.
    successful(&["sweep", "plan", &first, "--out", out]);
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
