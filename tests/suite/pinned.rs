//! Behaviour pinned bit for bit: the final state of 600 steps of `classic`, `gas1k` and
//! `billiards` under `discrete`, `substeps=4`, `swept`, `exact` and `soft` (and the pile and
//! the Galton board under `soft`), and the pair-collision counts
//! of the quick accuracy study. Restructuring the code must not change any of them; a deliberate
//! change of results updates the table here in the same commit and says why.
//!
//! Both go through the command line (`run --dump`, `accuracy --quick`), whose outputs are a
//! stable contract, so moving code inside the library never needs this file to change.

use crate::common::binary::{quick_study, scratch_dir, successful};
use std::path::Path;

/// FNV-1a over bytes: defined here, so the pinned values cannot move with a hasher's version.
fn fnv1a(hash: u64, bytes: &[u8]) -> u64 {
    bytes.iter().fold(hash, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// A hash of the exact bits of every circle's position and velocity in a particle-format dump,
/// in the dump's order (which is spawn order).
fn dump_hash(dump: &Path) -> u64 {
    let text = std::fs::read_to_string(dump).unwrap();
    let mut hash = 0xcbf2_9ce4_8422_2325;
    for line in text.lines().skip(1) {
        for word in line.split_whitespace().take(4) {
            let x: f64 = word.parse().unwrap();
            hash = fnv1a(hash, &x.to_bits().to_le_bytes());
        }
    }
    hash
}

/// `(scene, solver, hash of the state after 600 steps)`, measured on the code before the
/// restructuring of the module layout. Those of `swept`, `exact` and `soft` changed when the time
/// of impact came to take its discriminant by Lagrange's identity (`|dv|²σ² - (dp × dv)²`, which
/// does not cancel for pairs far apart; a last-bits change, chaos does the rest).
const PINNED_STATES: [(&str, &str, u64); 17] = [
    ("classic", "discrete", 0x70ec138773ba3976),
    ("classic", "substeps=4", 0x9b10061497aa709f),
    ("classic", "swept", 0xb2857781e71dfd7c),
    ("classic", "exact", 0x0606ed7adecc5695),
    ("gas1k", "discrete", 0x23cf5270c00747ab),
    ("gas1k", "substeps=4", 0x4fd76996d41ba8e5),
    ("gas1k", "swept", 0x66b0606c0291b727),
    ("gas1k", "exact", 0x5d1372630e101948),
    ("billiards", "discrete", 0x69534087135c38f7),
    ("billiards", "substeps=4", 0xe84ae06dacd1b120),
    ("billiards", "swept", 0x3ab6ee437c031ddf),
    ("billiards", "exact", 0xa46ca0377ac608ed),
    // `soft`, frictionless: measured when a step's bounces came to be solved together, with no
    // threshold without gravity and from the speed after the fall under it, and a contact whose
    // sides part (or, without gravity, still close) at the step's end came to be a new hit at its
    // next approach, and a bounce no longer warm starts the next step.
    ("classic", "soft", 0xe879e8d12fab8f10),
    ("gas1k", "soft", 0xfe17447ff446594e),
    ("billiards", "soft", 0xb25beb7a43ada38f),
    ("pile", "soft", 0x2d9ae850967e82d4),
    ("galton", "soft", 0x001da292af210fa3),
];

#[test]
fn the_final_states_of_600_steps_are_unchanged_bit_for_bit() {
    let dir = scratch_dir("pinned", "states");
    let mut differ = Vec::new();
    for (scene, solver, expected) in PINNED_STATES {
        let dump = dir.join(format!("{scene}-{solver}.txt"));
        let scene_path = format!("assets/scenes/{scene}.ron");
        successful(&[
            "run",
            "--scene",
            &scene_path,
            "--solver",
            solver,
            "--steps",
            "600",
            "--dump",
            dump.to_str().unwrap(),
        ]);
        let hash = dump_hash(&dump);
        println!("(\"{scene}\", \"{solver}\", {hash:#018x}),");
        if hash != expected {
            differ.push(format!(
                "{scene} under {solver}: {hash:#018x}, pinned {expected:#018x}"
            ));
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    assert!(
        differ.is_empty(),
        "final states changed:\n{}",
        differ.join("\n")
    );
}

/// `(scene, solver, pair collisions)` of `accuracy --quick` (60 Hz), measured on the code before
/// the restructuring of the module layout (`soft` and `soft=8` when they joined the study; `soft`, `swept`
/// and `exact` again when the time of impact took its discriminant by Lagrange's identity).
const PINNED_COLLISIONS: [(&str, &str, u64); 36] = [
    ("gas1k", "discrete", 6813),
    ("gas1k", "substeps=2", 7152),
    ("gas1k", "substeps=4", 7367),
    ("gas1k", "substeps=8", 7480),
    ("gas1k", "substeps=16", 7495),
    ("gas1k", "soft", 7327),
    ("gas1k", "soft=8", 7267),
    ("gas1k", "swept", 7484),
    ("gas1k", "exact", 7484),
    ("gas", "discrete", 33818),
    ("gas", "substeps=2", 35887),
    ("gas", "substeps=4", 36876),
    ("gas", "substeps=8", 37331),
    ("gas", "substeps=16", 37411),
    ("gas", "soft", 36437),
    ("gas", "soft=8", 36069),
    ("gas", "swept", 37505),
    ("gas", "exact", 37505),
    ("billiards", "discrete", 44),
    ("billiards", "substeps=2", 25),
    ("billiards", "substeps=4", 22),
    ("billiards", "substeps=8", 29),
    ("billiards", "substeps=16", 28),
    ("billiards", "soft", 64),
    ("billiards", "soft=8", 69),
    ("billiards", "swept", 30),
    ("billiards", "exact", 36),
    ("fast", "discrete", 651),
    ("fast", "substeps=2", 1210),
    ("fast", "substeps=4", 2278),
    ("fast", "substeps=8", 3285),
    ("fast", "substeps=16", 3606),
    ("fast", "soft", 3674),
    ("fast", "soft=8", 3640),
    ("fast", "swept", 3783),
    ("fast", "exact", 3741),
];

/// The same for the rough gas, measured when it joined the study: the time-stepped solvers
/// treat its circles as smooth (`soft` too, the study's rough gas having no friction), so
/// they count what they count on `gas1k` (the same circles);
/// `swept` and `exact` trade spin at every hit, and the circles, slower, meet less often.
const PINNED_ROUGH: [(&str, &str, u64); 9] = [
    ("rough_gas", "discrete", 6813),
    ("rough_gas", "substeps=2", 7152),
    ("rough_gas", "substeps=4", 7367),
    ("rough_gas", "substeps=8", 7480),
    ("rough_gas", "substeps=16", 7495),
    ("rough_gas", "soft", 7327),
    ("rough_gas", "soft=8", 7267),
    ("rough_gas", "swept", 6385),
    ("rough_gas", "exact", 6385),
];

#[test]
fn the_accuracy_studys_collision_counts_are_unchanged() {
    let csv = std::fs::read_to_string(quick_study().join("accuracy.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|&h| h == name).unwrap();
    let (scene, solver, count) = (column("scene"), column("solver"), column("pair_collisions"));
    let measured: Vec<(String, String, u64)> = lines
        .map(|line| {
            let fields: Vec<&str> = line.split(',').collect();
            (
                fields[scene].to_owned(),
                fields[solver].to_owned(),
                fields[count].parse().unwrap(),
            )
        })
        .collect();
    for (scene, solver, count) in &measured {
        println!("(\"{scene}\", \"{solver}\", {count}),");
    }
    let pinned = |list: &[(&str, &str, u64)]| -> Vec<(String, String, u64)> {
        let owned = list
            .iter()
            .map(|&(a, b, n)| (a.to_owned(), b.to_owned(), n));
        owned.collect()
    };
    // The smooth scenes as before rough hits came; the rough gas on its own.
    let (rough, smooth): (Vec<_>, Vec<_>) = measured.into_iter().partition(|m| m.0 == "rough_gas");
    assert_eq!(
        smooth,
        pinned(&PINNED_COLLISIONS),
        "the study's collision counts changed"
    );
    assert_eq!(
        rough,
        pinned(&PINNED_ROUGH),
        "the rough gas's collision counts changed"
    );
}
