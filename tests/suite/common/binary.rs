//! Helpers for the tests that run the real binary: run it (under a 1 GiB address-space limit
//! where memory is the promise), a scratch folder per test, and the refusal every bad input
//! must get.

use std::path::PathBuf;
use std::process::{Command, Output, Stdio};

/// `moving_circles` with `args`, from the crate's folder, with no display and no input, to be
/// spawned or run.
pub fn command(args: &[&str]) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_moving_circles"));
    command
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("DISPLAY", "")
        .args(args)
        .stdin(Stdio::null());
    command
}

/// [`command`] run to its end.
pub fn moving_circles(args: &[&str]) -> Output {
    command(args).output().expect("runs")
}

/// [`moving_circles`], asserting the run succeeded.
pub fn successful(args: &[&str]) -> Output {
    let out = moving_circles(args);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    out
}

/// `moving_circles` under a 1 GiB address-space limit: what "no more than 1 GB before refusing"
/// means, enforced by the kernel instead of measured.
pub fn under_one_gib(args: &[&str]) -> Output {
    let binary = env!("CARGO_BIN_EXE_moving_circles");
    Command::new("sh")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("DISPLAY", "")
        .arg("-c")
        .arg(r#"ulimit -v 1048576 && exec "$0" "$@""#)
        .arg(binary)
        .args(args)
        .output()
        .expect("runs")
}

/// A fresh folder for the test `name` of the test file `file`, in the system's temporary
/// folder.
pub fn scratch_dir(file: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mc-{file}-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `moving_circles run` with `args` and `--report` into a scratch folder of the test
/// `name` of the test file `file`, asserting it succeeded; the report.
pub fn run_report(file: &str, name: &str, args: &[&str]) -> serde_json::Value {
    let dir = scratch_dir(file, name);
    let path = dir.join("r.json");
    let mut args = args.to_vec();
    args.extend(["--report", path.to_str().unwrap()]);
    successful(&args);
    let json = read_report(&path);
    std::fs::remove_dir_all(dir).unwrap();
    json
}

/// The JSON report at `path`.
pub fn read_report(path: &std::path::Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).expect("report written");
    serde_json::from_str(&text).expect("a JSON report")
}

/// The folder of the quick accuracy study (`accuracy --quick`: accuracy.csv, .svg and .png,
/// piles.csv), run once for the whole suite by the first test that asks (the others wait for
/// it), and left in the system's temporary folder.
pub fn quick_study() -> &'static std::path::Path {
    static OUT: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    OUT.get_or_init(|| {
        let dir = scratch_dir("study", "quick");
        successful(&["accuracy", "--quick", "--out", dir.to_str().unwrap()]);
        dir
    })
}

/// What the run wrote to stdout.
pub fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// What the run wrote to stderr.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Asserts the run was refused with exit code 1 and one line on stderr that contains every
/// `expected` piece, and that nothing panicked or aborted.
pub fn assert_refused(out: &Output, expected: &[&str]) {
    let stderr = stderr(out);
    assert_eq!(out.status.code(), Some(1), "exit status, stderr:\n{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "one line:\n{stderr}");
    for piece in expected {
        assert!(stderr.contains(piece), "expected `{piece}` in:\n{stderr}");
    }
}
