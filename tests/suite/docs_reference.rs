//! The guide's reference tables against the code they describe: the configuration reference
//! in `docs/cli.md` against the scene schema (every field a scene takes is documented, every
//! documented field is one a scene takes), and `docs/cli-reference.md` against the command
//! line's own help (it is that help; `MC_BLESS=1` writes it anew), with every `moving_circles`
//! command line in the guide using only flags its command takes; and the crate's front page
//! (`src/lib.rs`) naming every guide page and linking every public module.

use std::collections::{BTreeMap, BTreeSet};
use std::process::Command;

use bevy::math::DVec2;
use moving_circles::base::config::{DropConfig, SpawnConfig};
use moving_circles::tools::scene::{CircleSpec, Scene};
use serde_json::{Map, Value};

/// The rows of the markdown table under `heading` in `page`: each row's cells, trimmed.
fn table_under(page: &str, heading: &str) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(page).unwrap();
    let start = text
        .find(heading)
        .unwrap_or_else(|| panic!("{page} has no `{heading}`"));
    text[start..]
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .skip(2) // the header and its rule
        .map(|l| {
            l.trim_matches('|')
                .split(" | ")
                .map(|c| c.trim().to_owned())
                .collect()
        })
        .collect()
}

/// The `code` spans of a cell.
fn code_spans(cell: &str) -> Vec<String> {
    cell.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_owned)
        .collect()
}

/// The configuration reference: each documented field (`arena.size`, ...) with the text that
/// explains it.
fn documented_fields() -> BTreeMap<String, String> {
    let rows = table_under("docs/cli.md", "### Configuration reference");
    assert!(rows.len() > 20, "the table was not found whole: {rows:?}");
    let mut fields = BTreeMap::new();
    for row in rows {
        for field in code_spans(&row[0]) {
            fields.insert(field, row[2].clone());
        }
    }
    fields
}

/// A scene with every optional part given, as JSON: the shape of every field a scene takes.
fn full_scene() -> Value {
    let mut scene = Scene {
        spawn: Some(SpawnConfig {
            area_fraction: Some(0.3),
            ..SpawnConfig::default()
        }),
        drop: Some(DropConfig::default()),
        circles: vec![CircleSpec {
            position: DVec2::ZERO,
            velocity: DVec2::X,
            angular_velocity: 1.0,
            radius: 0.5,
            mass: Some(1.0),
            color: Some([1, 2, 3]),
            immovable: false,
        }],
        segments: vec![vec![DVec2::ZERO, DVec2::X]],
        ..Scene::default()
    };
    scene.effects.gravity = Some(DVec2::NEG_Y);
    scene.effects.drag = Some(0.1);
    serde_json::to_value(&scene).unwrap()
}

/// A struct's fields as JSON gives them (an enum's variant is capitalised: a value, not a
/// field).
fn fields_of(value: &Value) -> Option<&Map<String, Value>> {
    let object = value.as_object()?;
    object
        .keys()
        .all(|k| k.starts_with(|c: char| c.is_ascii_lowercase()))
        .then_some(object)
}

/// Every field path of `value` under `prefix`, down to the values (lists of structs, such as
/// `circles`, give their items' fields).
fn field_paths(value: &Value, prefix: &str, out: &mut BTreeSet<String>) {
    let Some(fields) = fields_of(value) else {
        out.insert(prefix.to_owned());
        return;
    };
    for (name, inner) in fields {
        let path = match prefix {
            "" => name.clone(),
            _ => format!("{prefix}.{name}"),
        };
        let item = inner.as_array().and_then(|items| items.first());
        match item.filter(|item| fields_of(item).is_some()) {
            Some(item) => field_paths(item, &path, out),
            None => field_paths(inner, &path, out),
        }
    }
}

/// The value at `path` in `value`, if it has one.
fn at<'a>(value: &'a Value, path: &str) -> Option<&'a Value> {
    path.split('.').try_fold(value, |v, name| {
        let v = v.as_array().and_then(|a| a.first()).unwrap_or(v);
        v.get(name)
    })
}

/// A scene giving `path` alone, set to `value`.
fn scene_with(full: &Value, path: &str, value: Value) -> Value {
    let (head, rest) = path.split_once('.').unwrap_or((path, ""));
    let inner = match rest {
        "" => value,
        _ => scene_with(&full[head], rest, value),
    };
    Value::Object(Map::from_iter([(head.to_owned(), inner)]))
}

#[test]
fn every_field_a_scene_takes_is_in_the_configuration_reference() {
    let documented = documented_fields();
    let mut paths = BTreeSet::new();
    let full = full_scene();
    field_paths(&full, "", &mut paths);
    assert!(paths.contains("effects.sleep.time"), "{paths:?}");
    // An optional part left out would hide its fields: `full_scene` gives every one.
    let absent: Vec<&String> = paths
        .iter()
        .filter(|p| at(&full, p) == Some(&Value::Null))
        .collect();
    assert!(absent.is_empty(), "give these in full_scene: {absent:?}");
    // A field is documented in a row of its own, or named in its parent's row (`circles`:
    // `position`, `radius`, ...).
    let missing: Vec<&String> = paths
        .iter()
        .filter(|path| {
            if documented.contains_key(*path) {
                return false;
            }
            let (parent, name) = path.rsplit_once('.').unwrap_or(("", path));
            let in_parent = documented.get(parent);
            !in_parent.is_some_and(|text| code_spans(text).iter().any(|s| s == name))
        })
        .collect();
    assert!(
        missing.is_empty(),
        "scene fields missing from docs/cli.md's configuration reference: {missing:?}"
    );
}

#[test]
fn every_field_the_configuration_reference_names_is_taken_by_a_scene() {
    let full = full_scene();
    for field in documented_fields().keys() {
        let value = at(&full, field)
            .unwrap_or_else(|| panic!("docs/cli.md documents `{field}`, which a scene lacks"));
        let scene = scene_with(&full, field, value.clone());
        if let Err(e) = serde_json::from_value::<Scene>(scene.clone()) {
            panic!("a scene giving only the documented `{field}` is refused: {e} ({scene})");
        }
    }
}

/// The commands whose help the command-line reference holds, as typed after `moving_circles`.
const COMMANDS: [&str; 11] = [
    "",
    "run",
    "systems",
    "accuracy",
    "eos",
    "sweep",
    "sweep plan",
    "sweep task",
    "sweep run",
    "sweep status",
    "sweep merge",
];

/// `moving_circles COMMAND --help`.
fn help_of(command: &str) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_moving_circles"))
        .args(command.split_whitespace())
        .arg("--help")
        .output()
        .unwrap();
    assert!(out.status.success(), "{command} --help failed");
    String::from_utf8(out.stdout).unwrap()
}

/// The command-line reference as the parser's help makes it.
fn cli_reference() -> String {
    let mut page = String::from(
        "# Command-line reference\n\n\
         Every command's `--help`, as the parser prints it; `tests/suite/docs_reference.rs` \
         fails when\nthis page and the parser differ, and `MC_BLESS=1 cargo test --all-features \
         --test suite\ncli_reference` writes it anew. How the commands are used: [cli.md](cli.md) \
         and\n[sweeps.md](sweeps.md).\n",
    );
    for command in COMMANDS {
        let name = format!("moving_circles {command}");
        page.push_str(&format!(
            "\n## `{}`\n\n```text\n{}```\n",
            name.trim_end(),
            help_of(command)
        ));
    }
    page
}

#[test]
fn the_cli_reference_is_the_parsers_help() {
    let path = "docs/cli-reference.md";
    let made = cli_reference();
    if std::env::var_os("MC_BLESS").is_some() {
        std::fs::write(path, &made).unwrap();
    }
    let kept = std::fs::read_to_string(path).unwrap_or_default();
    assert!(
        kept == made,
        "{path} is not the parser's help: run `MC_BLESS=1 cargo test --all-features --test suite \
         cli_reference` and read the diff"
    );
}

/// The long flags a help text's option lines give (not those its descriptions mention).
fn flags_in(help: &str) -> BTreeSet<String> {
    help.lines()
        .map(str::trim_start)
        .filter(|line| line.starts_with('-'))
        .flat_map(|line| line.split("  ").next().unwrap_or("").split([' ', ',', '=']))
        .filter(|w| w.starts_with("--") && w.len() > 2)
        .map(str::to_owned)
        .collect()
}

/// The pages whose command lines are checked: the README, the guide but its history, the
/// benchmarks' README.
fn guide_pages() -> Vec<std::path::PathBuf> {
    let mut pages = vec!["README.md".into(), "benches/README.md".into()];
    pages.extend(crate::docs_pages::reference_pages());
    pages
}

/// The command lines of our binary in `line` (with its continuations joined): what follows
/// `moving_circles` (not where it is a path handed to another program's flag) or `cargo run
/// [--release] --`, to the end of the line or of its code span, comment or pipe.
fn command_lines(line: &str) -> Vec<Vec<&str>> {
    let mut found = Vec::new();
    for marker in [
        "moving_circles ",
        "cargo run --release -- ",
        "cargo run -- ",
    ] {
        for (at, _) in line.match_indices(marker) {
            let token_start = line[..at].rfind(char::is_whitespace).map_or(0, |k| k + 1);
            let before = line[..token_start].split_whitespace().next_back();
            if before.is_some_and(|w| w.starts_with("--")) {
                continue;
            }
            let rest = &line[at + marker.len()..];
            let end = rest.find(['`', '#', '|', ';', ')']).unwrap_or(rest.len());
            found.push(rest[..end].split_whitespace().collect());
        }
    }
    found
}

#[test]
fn every_command_line_in_the_guide_uses_flags_its_command_takes() {
    let flags: BTreeMap<&str, BTreeSet<String>> = COMMANDS
        .iter()
        .map(|&c| (c, flags_in(&help_of(c))))
        .collect();
    assert!(flags["run"].contains("--scene") && !flags["sweep"].contains("--index"));
    let mut wrong = Vec::new();
    let mut checked = 0;
    for page in guide_pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        // A line ending in `\` goes on in the next: each logical line with its first line's
        // number.
        let mut logical: Vec<(usize, String)> = Vec::new();
        let mut open = false;
        for (n, line) in text.lines().enumerate() {
            match logical.last_mut() {
                Some((_, joined)) if open => joined.push_str(line),
                _ => logical.push((n, line.to_owned())),
            }
            open = line.ends_with('\\');
        }
        for (n, line) in &logical {
            for words in command_lines(line) {
                // The longest command the words start with (`sweep run` before `sweep`).
                let command = COMMANDS
                    .iter()
                    .rev()
                    .find(|c| {
                        let names: Vec<&str> = c.split(' ').collect();
                        words.starts_with(&names) || c.is_empty()
                    })
                    .copied()
                    .unwrap_or("");
                for flag in words.iter().filter(|w| w.starts_with("--")) {
                    let flag = flag.split('=').next().unwrap();
                    checked += 1;
                    if !flags[command].contains(flag) {
                        let at = format!("{}:{}", page.display(), *n + 1);
                        wrong.push(format!("{at}: `moving_circles {command}` takes no {flag}"));
                    }
                }
            }
        }
    }
    assert!(
        checked > 50,
        "only {checked} flags found: is the guide read?"
    );
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// The crate documentation's front page: the `//!` lines of `lib`, the text of `src/lib.rs`.
fn front_page(lib: &str) -> String {
    let lines = lib.lines().filter_map(|l| l.strip_prefix("//!"));
    lines.collect::<Vec<_>>().join("\n")
}

#[test]
fn the_crate_front_page_names_every_guide_page_and_links_every_public_module() {
    let lib = std::fs::read_to_string("src/lib.rs").unwrap();
    let page = front_page(&lib);
    let mut missing = Vec::new();
    for entry in std::fs::read_dir("docs").unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        if name.ends_with(".md") && name != "README.md" && !page.contains(&format!("`docs/{name}`"))
        {
            missing.push(format!("docs/{name}"));
        }
    }
    let modules = lib
        .lines()
        .filter_map(|l| l.trim().strip_prefix("pub mod "));
    for module in modules.map(|m| m.trim_end_matches([';', ' ', '{'])) {
        if !page.contains(&format!("[`{module}`]")) {
            missing.push(format!("module {module}"));
        }
    }
    assert!(
        missing.is_empty(),
        "src/lib.rs's front page lacks {missing:?}"
    );
}
