//! The guide's reference tables against the code they describe: the configuration reference
//! in `docs/cli.md` against the scene schema (every field a scene takes is documented, every
//! documented field is one a scene takes).

use std::collections::{BTreeMap, BTreeSet};

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

/// A scene giving `path` alone, set to `value` (a list's field in a one-item list).
fn scene_with(full: &Value, path: &str, value: Value) -> Value {
    let (head, rest) = path.split_once('.').unwrap_or((path, ""));
    if rest.is_empty() {
        return Value::Object(Map::from_iter([(head.to_owned(), value)]));
    }
    let inner = &full[head];
    match inner.as_array() {
        Some(items) => {
            // An item of a list needs its required fields: start from the full one.
            let mut item = items[0].clone();
            let (first, _) = rest.split_once('.').unwrap_or((rest, ""));
            item[first] = scene_with(&items[0], rest, value)[first].clone();
            Value::Object(Map::from_iter([(
                head.to_owned(),
                Value::Array(vec![item]),
            )]))
        }
        None => Value::Object(Map::from_iter([(
            head.to_owned(),
            scene_with(inner, rest, value),
        )])),
    }
}

#[test]
fn every_field_a_scene_takes_is_in_the_configuration_reference() {
    let documented = documented_fields();
    let mut paths = BTreeSet::new();
    field_paths(&full_scene(), "", &mut paths);
    assert!(paths.contains("effects.sleep.time"), "{paths:?}");
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
