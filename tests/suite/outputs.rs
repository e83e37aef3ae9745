//! Outputs through the real binary: none replaces the run's own input (its scene, particle
//! file or the checkpoint it resumed, which only its own checkpoint may write over), a name
//! too long for its temporary file is refused before the run, and a checkpoint that cannot be
//! written loses none of the other outputs.
#![cfg(unix)]

use crate::common::binary::scratch_dir;

use crate::common::binary::{assert_refused, command, stderr, under_one_gib};

/// Two steps of `scene` with `flag` (an output) naming `path`, under the memory bound.
fn two_steps_writing(scene: &str, flag: &str, path: &str) -> std::process::Output {
    under_one_gib(&["run", "--scene", scene, "--steps", "2", flag, path])
}

#[test]
fn an_output_never_replaces_the_runs_own_input() {
    let dir = scratch_dir("outputs", "inputs");
    let scene = dir.join("scene.ron");
    let text = "(spawn: (count: 8))";
    std::fs::write(&scene, text).unwrap();
    let scene = scene.to_str().unwrap();
    for flag in ["--report", "--dump", "--checkpoint"] {
        let out = two_steps_writing(scene, flag, scene);
        assert_refused(&out, &[&format!("{flag} names the input of --scene")]);
    }
    assert_eq!(
        std::fs::read_to_string(scene).unwrap(),
        text,
        "the scene was replaced"
    );
    // A resumed run may write its checkpoint back over the one it resumed, nothing else.
    let checkpoint = dir.join("c.ckpt");
    let checkpoint = checkpoint.to_str().unwrap();
    let out = two_steps_writing(scene, "--checkpoint", checkpoint);
    assert!(out.status.success(), "{}", stderr(&out));
    let again = ["run", "--resume", checkpoint, "--steps", "2"];
    let out = under_one_gib(&[&again[..], &["--checkpoint", checkpoint]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    for flag in ["--report", "--dump"] {
        let out = under_one_gib(&[&again[..], &[flag, checkpoint]].concat());
        assert_refused(&out, &[&format!("{flag} names the input of --resume")]);
    }
    // A particle file, as a scene.
    let particles = dir.join("p.txt");
    let dump = ["run", "--scene", scene, "--steps", "1", "--dump"];
    let out = under_one_gib(&[&dump[..], &[particles.to_str().unwrap()]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let written = std::fs::read(&particles).unwrap();
    let particles = particles.to_str().unwrap();
    for flag in ["--report", "--dump", "--checkpoint"] {
        let args = [
            "run",
            "--particles",
            particles,
            "--steps",
            "1",
            flag,
            particles,
        ];
        assert_refused(
            &under_one_gib(&args),
            &[&format!("{flag} names the input of --particles")],
        );
    }
    assert_eq!(std::fs::read(particles).unwrap(), written);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_output_name_too_long_for_its_temporary_file_is_refused_before_the_run() {
    let dir = scratch_dir("outputs", "names");
    let scene = "assets/scenes/classic.ron";
    // 239 bytes is the longest name whose temporary file (16 bytes more) a file system takes.
    for (length, ok) in [(239, true), (240, false), (255, false)] {
        let report = dir.join("r".repeat(length));
        let out = two_steps_writing(scene, "--report", report.to_str().unwrap());
        let err = stderr(&out);
        assert_eq!(out.status.success(), ok, "{length} bytes: {err}");
        if !ok {
            assert!(err.contains("outputs take at most 239"), "{err}");
            assert!(!err.contains("steps of"), "refused after the run: {err}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A child process killed when dropped, so a failing test leaves no run behind.
struct Killed(std::process::Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

#[test]
fn a_checkpoint_that_cannot_be_written_ends_the_run_with_the_other_outputs_written() {
    let dir = scratch_dir("outputs", "full");
    let folder = dir.join("checkpoints");
    std::fs::create_dir(&folder).unwrap();
    let checkpoint = folder.join("c.ckpt");
    let (report, dump) = (dir.join("r.json"), dir.join("d.txt"));
    let mut run = Killed(
        command(&["run", "--scene", "assets/scenes/classic.ron"])
            .args(["--steps", "100000000", "--every", "1"])
            .args(["--checkpoint", checkpoint.to_str().unwrap()])
            .args(["--report", report.to_str().unwrap()])
            .args(["--dump", dump.to_str().unwrap()])
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap(),
    );
    // Once the first checkpoint is there its folder goes away (as a full or lost disk would
    // refuse it): the next one cannot be written.
    let start = std::time::Instant::now();
    while !checkpoint.exists() {
        assert!(start.elapsed().as_secs() < 60, "no checkpoint written");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    std::fs::rename(&folder, dir.join("moved")).unwrap();
    let start = std::time::Instant::now();
    let status = loop {
        if let Some(status) = run.0.try_wait().unwrap() {
            break status;
        }
        assert!(start.elapsed().as_secs() < 60, "the run went on");
        std::thread::sleep(std::time::Duration::from_millis(5));
    };
    let mut err = String::new();
    std::io::Read::read_to_string(run.0.stderr.as_mut().unwrap(), &mut err).unwrap();
    assert_eq!(status.code(), Some(1), "{err}");
    assert!(err.contains("writing the checkpoint"), "{err}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report written")).unwrap();
    assert_eq!(report["interrupted"], true, "{report}");
    assert!(
        std::fs::read_to_string(&dump)
            .expect("dump written")
            .starts_with("32\n")
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
