//! `field` axes: a task's scene is the sweep's scene with the fields its axes set, each
//! distinct one checked at plan time and written once into the folder as `scenes/K.ron`, a
//! scene file `run --scene` reads as it is.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use anyhow::{Context, bail};
use serde_json::Value;

use super::spec::Task;
use crate::tools::io::write_atomically;
use crate::tools::scene::Scene;

/// `base` with each of `fields` (path to value) set, checked as a scene file is.
pub(super) fn scene_with(
    base: &Scene,
    fields: &BTreeMap<String, Value>,
    origin: &str,
) -> Result<Scene, String> {
    let mut tree = serde_json::to_value(base).map_err(|e| e.to_string())?;
    for (path, value) in fields {
        *field_mut(&mut tree, path)? = value.clone();
    }
    let scene: Scene = serde_json::from_value(tree).map_err(|e| {
        let paths: Vec<&str> = fields.keys().map(String::as_str).collect();
        format!("setting {}: {e}", paths.join(", "))
    })?;
    scene.to_config(origin).map_err(|e| e.to_string())?;
    Ok(scene)
}

/// The place of `path` (`effects.restitution`, `circles.0.radius`) in a scene as JSON.
fn field_mut<'a>(tree: &'a mut Value, path: &str) -> Result<&'a mut Value, String> {
    let mut here = tree;
    let mut walked = String::new();
    for name in path.split('.') {
        let within = if walked.is_empty() {
            "the scene".to_owned()
        } else {
            format!("`{walked}`")
        };
        here = match here {
            Value::Object(fields) => {
                if !fields.contains_key(name) {
                    let known: Vec<&str> = fields.keys().map(String::as_str).collect();
                    return Err(format!(
                        "field {path:?}: {within} has no field `{name}` (it has {})",
                        known.join(", ")
                    ));
                }
                fields.get_mut(name).expect("just found")
            }
            Value::Array(items) => {
                let len = items.len();
                name.parse::<usize>()
                    .ok()
                    .and_then(|k| items.get_mut(k))
                    .ok_or_else(|| {
                        format!("field {path:?}: {within} is a list of {len}; `{name}` is not one of its positions")
                    })?
            }
            Value::Null => {
                return Err(format!(
                    "field {path:?}: {within} is not set in the scene; give it there, then sweep \
                     its fields"
                ));
            }
            _ => return Err(format!("field {path:?}: {within} has no fields")),
        };
        if !walked.is_empty() {
            walked.push('.');
        }
        walked.push_str(name);
    }
    Ok(here)
}

/// Names each task's own scene, `scenes/K.ron`, the distinct field settings numbered in the
/// order the tasks first need them; the index of the first task of each.
pub(super) fn name_scenes(tasks: &mut [Task]) -> Vec<usize> {
    let mut numbers: HashMap<String, usize> = HashMap::new();
    let mut firsts = Vec::new();
    for task in tasks.iter_mut().filter(|t| !t.fields.is_empty()) {
        let key = serde_json::Value::from_iter(task.fields.clone()).to_string();
        let k = *numbers.entry(key).or_insert_with(|| {
            firsts.push(task.index);
            firsts.len() - 1
        });
        task.scene = Some(format!("scenes/{k}.ron"));
    }
    firsts
}

/// Names each task's own scene ([`name_scenes`]) and writes each into `dir`, checked.
pub(super) fn write_scenes(base: &Scene, tasks: &mut [Task], dir: &Path) -> anyhow::Result<()> {
    for first in name_scenes(tasks) {
        let task = &tasks[first];
        let name = task.scene.as_deref().expect("named");
        let scene = scene_with(base, &task.fields, name)
            .map_err(|e| anyhow::anyhow!("task {}: {e}", task.index))?;
        let text = ron::ser::to_string_pretty(&scene, ron::ser::PrettyConfig::default())
            .context("a scene as RON")?;
        // What is written is what runs: the file must read back as this very scene.
        if Scene::parse(&text, name).ok().as_ref() != Some(&scene) {
            bail!("task {}: its scene does not read back from RON", task.index);
        }
        let path = dir.join(name);
        write_atomically(&path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every scene that ships reads back from the RON a task's scene file is written in, and
    /// through the JSON a field is set in, as the same scene.
    #[test]
    fn every_shipped_scene_survives_the_trips_a_field_axis_takes_it_on() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes");
        let mut seen = 0;
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let text = std::fs::read_to_string(&path).unwrap();
            let scene = Scene::parse(&text, "s.ron").unwrap();
            let ron = ron::ser::to_string_pretty(&scene, ron::ser::PrettyConfig::default());
            assert_eq!(
                Scene::parse(&ron.unwrap(), "s.ron").unwrap(),
                scene,
                "{path:?}"
            );
            let same = scene_with(&scene, &BTreeMap::new(), "s.ron").unwrap();
            assert_eq!(same, scene, "{path:?}");
            seen += 1;
        }
        assert!(seen > 10);
    }
}
