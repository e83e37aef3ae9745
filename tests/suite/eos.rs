//! `moving_circles eos`: the measured hard-disk pressure agrees with Liu's equation of state
//! and the speeds with the Rayleigh law on a small box, the command writes its CSV and figure,
//! and bad options are refused with the option named.

use std::process::Command;

use moving_circles::tools::eos::theory::ks_critical_5_percent;
use moving_circles::tools::eos::{EosOptions, measure};

fn small(area_fractions: Vec<f64>) -> EosOptions {
    EosOptions {
        n: 400,
        area_fractions,
        equilibrate: 30.0,
        blocks: 5,
        block: 40.0,
        seed: 3,
    }
}

#[test]
fn a_small_box_gives_liu_s_pressure_and_rayleigh_speeds() {
    let options = small(vec![0.3]);
    options.check().unwrap();
    let point = measure(&options, 0.3).unwrap();
    assert_eq!(point.n, 400);
    // 400 disks and 200 collisions each: a few tenths of a per cent of statistical error.
    assert!(point.vs_liu.abs() < 0.01, "{point:?}");
    assert!(
        point.z_error > 0.0 && point.z_error < 0.01 * point.z,
        "{point:?}"
    );
    assert!(
        (point.vs_liu * point.liu).abs() < 4.0 * point.z_error + 0.005 * point.liu,
        "the deviation is within the error bars: {point:?}"
    );
    // Every disk started at speed 1; the collisions made the speeds Rayleigh.
    assert!(point.speed_ks < ks_critical_5_percent(400), "{point:?}");
    let measured_pairs = (200.0 * 400.0 / 2.0) as u64;
    assert!(point.collisions >= measured_pairs, "{point:?}");
}

#[test]
fn the_command_measures_each_point_as_a_task_and_goes_on_from_where_it_stopped() {
    let out = std::env::temp_dir().join(format!("mc-eos-tasks-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let run = |fractions: &str| {
        Command::new(env!("CARGO_BIN_EXE_moving_circles"))
            .args(["eos", "--out", out.to_str().unwrap(), "--n", "100"])
            .args(["--area-fractions", fractions, "--equilibrate", "10"])
            .args([
                "--blocks", "3", "--block", "10", "--seed", "7", "--jobs", "2",
            ])
            .output()
            .unwrap()
    };
    let first = run("0.2,0.5");
    assert!(
        first.status.success(),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    // Each task measured what `measure` measures in this process, to the bit.
    let options = EosOptions {
        n: 100,
        area_fractions: vec![0.2, 0.5],
        equilibrate: 10.0,
        blocks: 3,
        block: 10.0,
        seed: 7,
    };
    let csv = std::fs::read_to_string(out.join("eos.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let z_column = header.iter().position(|&h| h == "z").unwrap();
    for (line, phi) in csv.lines().skip(1).zip([0.2, 0.5]) {
        let z: f64 = line.split(',').nth(z_column).unwrap().parse().unwrap();
        assert_eq!(z, measure(&options, phi).unwrap().z, "at {phi}");
    }
    // Stopped with one point left (its result gone), run again: only that point is measured.
    let result = out.join("eos-tasks/results/1.json");
    std::fs::remove_file(&result).unwrap();
    let again = run("0.2,0.5");
    let said = String::from_utf8_lossy(&again.stdout);
    assert!(
        again.status.success() && said.contains("1 of 1 tasks done here (1 done before)"),
        "{said}"
    );
    let z_of = |csv: &str| -> Vec<String> {
        csv.lines()
            .map(|l| l.split(',').nth(z_column).unwrap().to_owned())
            .collect()
    };
    let csv_again = std::fs::read_to_string(out.join("eos.csv")).unwrap();
    assert_eq!(z_of(&csv_again), z_of(&csv));
    // Other options into an unfinished run would mix two measurements: refused, nothing
    // overwritten.
    std::fs::remove_file(&result).unwrap();
    let other = run("0.2,0.6");
    let stderr = String::from_utf8_lossy(&other.stderr);
    assert!(
        !other.status.success() && stderr.contains("holds another sweep's plan"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("eos.csv")).unwrap(),
        csv_again
    );
    // A finished run is measured again whole.
    assert!(run("0.2,0.5").status.success());
    let fresh = run("0.2,0.5");
    let said = String::from_utf8_lossy(&fresh.stdout);
    assert!(
        said.contains("2 of 2 tasks done here (0 done before)"),
        "{said}"
    );
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn the_command_writes_a_csv_and_the_figure_and_refuses_bad_options() {
    let out = std::env::temp_dir().join(format!("mc-eos-{}", std::process::id()));
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_moving_circles"))
            .arg("eos")
            .args(args)
            .output()
            .unwrap()
    };
    let out_arg = out.to_str().unwrap();
    // At 0.001 a mean free time is longer than the longest step a scene may have.
    let done = run(&[
        "--out",
        out_arg,
        "--n",
        "64",
        "--area-fractions",
        "0.001,0.6",
        "--equilibrate",
        "5",
        "--blocks",
        "2",
        "--block",
        "5",
    ]);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let csv = std::fs::read_to_string(out.join("eos.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    for column in [
        "area_fraction",
        "z",
        "z_error",
        "henderson",
        "liu",
        "speed_ks",
    ] {
        assert!(header.contains(&column), "{column} missing: {header:?}");
    }
    assert_eq!(lines.count(), 2, "one row per area fraction");
    let svg = std::fs::read_to_string(out.join("eos.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("Liu"));
    let png = std::fs::read(out.join("eos.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG"));

    // The range the help gives, said as it gives it (0 and 1 were refused with what they made
    // of the box and the step, 0.86 was run).
    for phi in ["0", "0.86", "0.9", "1.0"] {
        let refused = run(&["--out", out_arg, "--area-fractions", phi]);
        let stderr = String::from_utf8_lossy(&refused.stderr);
        assert!(!refused.status.success(), "{phi} accepted");
        assert!(
            stderr.contains("area-fractions") && stderr.contains("must be in (0, 0.85]"),
            "{phi}: {stderr}"
        );
    }
    for (args, field) in [
        (vec!["--blocks", "1"], "--blocks: must be 2 to"),
        (vec!["--n", "1"], "--n: needs 2 to"),
        (
            vec!["--block", "NaN"],
            "--block: collisions per disk must be in",
        ),
        (
            vec!["--equilibrate", "1e300"],
            "--equilibrate: collisions per disk must be in",
        ),
    ] {
        let mut all = vec!["--out", out_arg];
        all.extend(args.iter());
        let refused = run(&all);
        let stderr = String::from_utf8_lossy(&refused.stderr);
        assert!(!refused.status.success(), "{args:?} accepted");
        assert!(stderr.contains(field), "{args:?}: {stderr}");
    }
    std::fs::remove_dir_all(&out).unwrap();
}
