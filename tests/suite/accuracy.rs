//! The accuracy study and `--solver auto`: the study writes its CSV (every solver present) and
//! its figure as SVG and PNG (every scene and measure), and its pile scenes' CSV (what holds a
//! stack and what does not); tunnelling is told apart from bouncing; `auto` picks cheap solvers for loose
//! tolerances and an exact one for tight tolerances.

use std::process::Command;

use bevy::math::DVec2;
use moving_circles::prelude::*;
use moving_circles::tools::accuracy::auto::choose_solver;
use moving_circles::tools::accuracy::front::MEASURES;
use moving_circles::tools::accuracy::passed_through;
use moving_circles::tools::accuracy::plot::AccuracyFigure;

fn circle(x: f64, vx: f64) -> CircleState {
    CircleState::new(DVec2::new(x, 0.0), DVec2::new(vx, 0.0), 0.1)
}

#[test]
fn passing_through_is_counted_and_bouncing_is_not() {
    let before = [circle(-0.3, 6.0), circle(0.3, -6.0)];
    // One step of 0.1 s later, unchanged velocities, on the far sides: tunnelled.
    let tunnelled = [circle(0.3, 6.0), circle(-0.3, -6.0)];
    assert_eq!(passed_through(&before, &tunnelled, &Arena::default()), 1);
    // Bounced back: velocities changed, same sides.
    let bounced = [circle(-0.3, -6.0), circle(0.3, 6.0)];
    assert_eq!(passed_through(&before, &bounced, &Arena::default()), 0);
    // Missed each other sideways: no overlap on the way.
    let wide = [
        CircleState {
            position: DVec2::new(-0.3, 0.5),
            ..circle(0.0, 6.0)
        },
        circle(0.3, -6.0),
    ];
    let wide_after = [
        CircleState {
            position: DVec2::new(0.3, 0.5),
            ..circle(0.0, 6.0)
        },
        circle(-0.3, -6.0),
    ];
    assert_eq!(passed_through(&wide, &wide_after, &Arena::default()), 0);
}

fn fast_scene() -> CirclesConfig {
    Scene::load(std::path::Path::new("assets/scenes/fast.ron")).unwrap()
}

#[test]
fn auto_picks_a_continuous_solver_for_a_tight_tolerance_and_a_cheap_one_for_a_loose_one() {
    let (tight, measured) = choose_solver(&fast_scene(), 1e-6);
    assert!(
        tight.is_continuous(),
        "1e-6 of a radius needs swept or exact, got {tight}: {measured:?}"
    );
    assert_eq!(
        measured.len(),
        9,
        "eight candidates (soft among them) and exact"
    );
    // With any error allowed, the choice is the cheapest of that calibration's measurements.
    let (loose, measured) = choose_solver(&fast_scene(), 1e6);
    let cheapest = measured
        .iter()
        .min_by(|a, b| a.ms_per_step.total_cmp(&b.ms_per_step))
        .unwrap();
    assert_eq!(loose, cheapest.solver, "{measured:?}");
}

#[test]
fn the_study_writes_a_csv_with_every_solver_and_its_figure_as_svg_and_png() {
    let out = crate::common::binary::quick_study();
    let csv = std::fs::read_to_string(out.join("accuracy.csv")).unwrap();
    for solver in [
        "discrete",
        "substeps=16",
        "soft",
        "soft=8",
        "swept",
        "exact",
    ] {
        for scene in ["gas1k", "gas", "billiards", "fast", "rough_gas"] {
            assert!(
                csv.lines()
                    .any(|l| l.starts_with(&format!("{scene},"))
                        && l.contains(&format!(",{solver},"))),
                "{scene}/{solver} missing:\n{csv}"
            );
        }
    }
    // The rotation measure: where rough hits turn the circles, a solver that treats them as
    // smooth misses all of the reference's turning, and `swept` (the same hits, events bounded
    // per step) little of it; smooth scenes have none to compare.
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|&h| h == name).unwrap();
    let turning_error = |scene: &str, solver: &str| -> Option<f64> {
        let row: Vec<&str> = csv
            .lines()
            .map(|l| l.split(',').collect::<Vec<_>>())
            .find(|f| f[column("scene")] == scene && f[column("solver")] == solver)
            .unwrap();
        row[column("turning_error")].parse().ok()
    };
    assert_eq!(turning_error("rough_gas", "discrete"), Some(-1.0));
    let swept = turning_error("rough_gas", "swept").unwrap();
    assert!(swept.abs() < 0.05, "swept misses {swept} of the turning");
    assert_eq!(turning_error("gas1k", "discrete"), None);
    let svg = std::fs::read_to_string(out.join("accuracy.svg")).unwrap();
    assert!(svg.starts_with("<svg"), "not an SVG");
    for scene in ["gas1k", "gas", "billiards", "fast", "rough_gas"] {
        for measure in &MEASURES {
            assert!(
                svg.contains(&format!("{scene} (n = ")) && svg.contains(measure.title),
                "no panel for {scene}: {}",
                measure.title
            );
        }
    }
    // The PNG is the same figure: its size, and drawn in the colours of the front and of the
    // reference line (a blank or text-only image would fail).
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(out.join("accuracy.png")).unwrap(),
    ));
    let mut reader = decoder.read_info().unwrap();
    let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut pixels).unwrap();
    assert_eq!((info.width, info.height), AccuracyFigure::size_for(5));
    let count = |rgb: [u8; 3]| pixels.chunks(3).filter(|p| *p == rgb).count();
    assert!(count([255, 200, 60]) > 1000, "no Pareto front drawn");
    assert!(count([117, 80, 170]) > 1000, "no reference drawn");
    assert!(
        count([255, 255, 255]) > pixels.len() / 6,
        "mostly not background"
    );
    // The pile part: every pile solver on the pyramid, measured on its own terms. The
    // event-driven solvers hold it at rounding and it settles at once; `soft` within a
    // fiftieth, settled and asleep; the course's one contact pass lets it sink and never rest.
    let piles = std::fs::read_to_string(out.join("piles.csv")).unwrap();
    let header: Vec<&str> = piles.lines().next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<&str>> = piles
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    let row = |solver: &str| {
        rows.iter()
            .find(|r| r[column("scene")] == "pyramid" && r[column("solver")] == solver)
            .unwrap_or_else(|| panic!("pyramid/{solver} missing:\n{piles}"))
    };
    let number = |r: &Vec<&str>, name: &str| r[column(name)].parse::<f64>().unwrap();
    for solver in ["swept", "exact", "soft", "soft=8"] {
        let r = row(solver);
        let bound = if solver.starts_with("soft") {
            0.02
        } else {
            1e-9
        };
        assert!(number(r, "rest_penetration") <= bound, "{solver}: {r:?}");
        assert!(
            !r[column("settled_at")].is_empty(),
            "{solver} never settled"
        );
        assert_eq!(r[column("asleep")], "210", "{solver}");
    }
    for solver in ["discrete", "substeps=4"] {
        let r = row(solver);
        assert!(
            number(r, "rest_penetration") > 0.1,
            "{solver} held the stack: {r:?}"
        );
        assert!(
            r[column("settled_at")].is_empty(),
            "{solver} settled: {r:?}"
        );
    }
}

#[test]
fn a_bad_pile_scene_or_output_is_refused_before_any_run() {
    // The last two were found only after the gases had run and been written (a black-box try).
    let dir = std::env::temp_dir().join(format!("mc-accuracy-bad-{}", std::process::id()));
    let (scenes, out) = (dir.join("scenes"), dir.join("out"));
    std::fs::create_dir_all(&scenes).unwrap();
    for entry in std::fs::read_dir("assets/scenes").unwrap() {
        let path = entry.unwrap().path();
        std::fs::copy(&path, scenes.join(path.file_name().unwrap())).unwrap();
    }
    // The study refused, its error naming each of `named`, and nothing of it written.
    let refused_naming = |named: &[&str]| {
        let refused = Command::new(env!("CARGO_BIN_EXE_moving_circles"))
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .args(["accuracy", "--quick", "--scenes", scenes.to_str().unwrap()])
            .args(["--out", out.to_str().unwrap()])
            .output()
            .unwrap();
        let said = String::from_utf8_lossy(&refused.stderr);
        assert!(!refused.status.success(), "accepted: {said}");
        assert!(named.iter().all(|n| said.contains(n)), "{named:?}: {said}");
        assert!(!out.join("accuracy.csv").exists(), "the gases ran first");
    };
    // A scene with no circle would put 0/0 in every column.
    let gas1k = scenes.join("gas1k.ron");
    let good = std::fs::read_to_string(&gas1k).unwrap();
    std::fs::write(&gas1k, "(spawn: (count: 0))").unwrap();
    refused_naming(&["gas1k.ron", "no circles"]);
    std::fs::write(&gas1k, good).unwrap();
    let pyramid = scenes.join("pyramid.ron");
    let good = std::fs::read_to_string(&pyramid).unwrap();
    std::fs::write(&pyramid, "(dt: 1e-10)").unwrap();
    refused_naming(&["pyramid.ron", "dt"]);
    std::fs::write(&pyramid, good).unwrap();
    std::fs::create_dir_all(out.join("piles.csv")).unwrap();
    refused_naming(&["piles.csv"]);
    std::fs::remove_dir_all(&dir).unwrap();
}
