//! The structure rules of `src/`, checked on the source text: every import points down the
//! layers (`base`, `collision`, `step`, `solvers`, `game`, `tools`, `render`, `cli`, and
//! `lib.rs`, which declares them) or stays within its layer, no solver's folder imports
//! another's, no two files or folders import each other through any chain, no file is over
//! 450 lines, and only the config, the solvers' folders and the crate docs name a solver's
//! variant.
//!
//! An import is any `crate::…` or `super::…` path in code (comments are skipped), including
//! each branch of a `use` tree; it points at the deepest module file the path names.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            files.extend(rust_files(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            files.push(path);
        }
    }
    files
}

/// The module path of a file: `src/solvers/discrete/mod.rs` is `["solvers", "discrete"]`, `src/lib.rs` is `[]`.
fn module_of(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib")) {
        parts.pop();
    }
    parts
}

/// The code of a file without comments, string contents and its unit tests (the `#[cfg(test)]`
/// module at its end), so that doc links, messages and test helpers do not count as imports.
fn code_of(text: &str) -> String {
    let mut code = String::new();
    for line in text.lines().take_while(|l| l.trim() != "#[cfg(test)]") {
        let line = match line.find("//") {
            Some(at) => &line[..at],
            None => line,
        };
        let mut in_string = false;
        for c in line.chars() {
            if c == '"' {
                in_string = !in_string;
            } else if !in_string {
                code.push(c);
            }
        }
        code.push('\n');
    }
    code
}

/// Expands `use` trees and finds inline paths: every `crate::…` / `super::…` path, as segments.
fn paths_in(code: &str) -> Vec<Vec<String>> {
    let mut paths = Vec::new();
    let bytes: Vec<char> = code.chars().collect();
    let mut i = 0;
    while i < bytes.len() {
        let starts_word = i == 0 || !(bytes[i - 1].is_alphanumeric() || bytes[i - 1] == '_');
        let rest: String = bytes[i..bytes.len().min(i + 7)].iter().collect();
        if starts_word && (rest.starts_with("crate::") || rest.starts_with("super::")) {
            let (tree, end) = read_tree(&bytes, i);
            expand(&tree, &mut Vec::new(), &mut paths);
            i = end;
        } else {
            i += 1;
        }
    }
    paths
}

/// The path tree starting at `at` (`a::b::{c, d::{e}}`) as text, and where it ends.
fn read_tree(chars: &[char], at: usize) -> (String, usize) {
    let (mut depth, mut i, mut tree) = (0, at, String::new());
    while i < chars.len() {
        let c = chars[i];
        let part_of_path = c.is_alphanumeric() || c == '_' || c == ':' || c == '*';
        match c {
            '{' => depth += 1,
            '}' if depth == 0 => break,
            '}' => depth -= 1,
            _ if depth == 0 && !part_of_path => break,
            _ => {}
        }
        if !c.is_whitespace() {
            tree.push(c);
        }
        i += 1;
    }
    (tree, i)
}

/// Adds every path of a use tree (`a::{b, c::d}` is `a::b` and `a::c::d`) to `out`.
fn expand(tree: &str, prefix: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    let Some(open) = tree.find('{') else {
        let mut path = prefix.clone();
        path.extend(
            tree.split("::")
                .filter(|s| !s.is_empty())
                .map(str::to_owned),
        );
        out.push(path);
        return;
    };
    let head: Vec<String> = tree[..open]
        .split("::")
        .filter(|s| !s.is_empty())
        .map(str::to_owned)
        .collect();
    let inner = &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())];
    let mut depth = 0;
    let mut start = 0;
    let mut branches = Vec::new();
    for (k, c) in inner.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                branches.push(&inner[start..k]);
                start = k + 1;
            }
            _ => {}
        }
    }
    branches.push(&inner[start..]);
    let base = prefix.len();
    prefix.extend(head);
    for branch in branches.into_iter().filter(|b| !b.is_empty()) {
        expand(branch, prefix, out);
    }
    prefix.truncate(base);
}

/// The file-level import graph of `src/` (the library; the binary imports it from outside).
fn import_graph(src: &Path) -> BTreeMap<PathBuf, BTreeSet<PathBuf>> {
    let files: Vec<PathBuf> = rust_files(src)
        .into_iter()
        .filter(|f| f != &src.join("main.rs"))
        .collect();
    let modules: BTreeMap<Vec<String>, PathBuf> = files
        .iter()
        .map(|f| (module_of(src, f), f.clone()))
        .collect();
    let mut graph = BTreeMap::new();
    for file in &files {
        let here = module_of(src, file);
        let mut targets = BTreeSet::new();
        for path in paths_in(&code_of(&std::fs::read_to_string(file).unwrap())) {
            let mut module: Vec<String> = Vec::new();
            let mut segments = path.iter().peekable();
            match segments.next().map(String::as_str) {
                Some("crate") => {}
                Some("super") => {
                    // `super` of a/b.rs is a; of a/mod.rs, the parent of a.
                    module = here.clone();
                    module.pop();
                    while segments.peek().is_some_and(|s| s.as_str() == "super") {
                        segments.next();
                        module.pop();
                    }
                }
                _ => continue,
            }
            for segment in segments {
                module.push(segment.clone());
                if !modules.contains_key(&module) {
                    module.pop();
                    break;
                }
            }
            let target = &modules[&module];
            if target != file {
                targets.insert(target.clone());
            }
        }
        graph.insert(file.clone(), targets);
    }
    graph
}

/// A cycle of files, if the graph has one.
fn find_cycle(graph: &BTreeMap<PathBuf, BTreeSet<PathBuf>>) -> Option<Vec<PathBuf>> {
    fn visit(
        node: &PathBuf,
        graph: &BTreeMap<PathBuf, BTreeSet<PathBuf>>,
        done: &mut BTreeSet<PathBuf>,
        stack: &mut Vec<PathBuf>,
    ) -> Option<Vec<PathBuf>> {
        if let Some(at) = stack.iter().position(|n| n == node) {
            let mut cycle = stack[at..].to_vec();
            cycle.push(node.clone());
            return Some(cycle);
        }
        if done.contains(node) {
            return None;
        }
        stack.push(node.clone());
        for next in &graph[node] {
            if let Some(cycle) = visit(next, graph, done, stack) {
                return Some(cycle);
            }
        }
        stack.pop();
        done.insert(node.clone());
        None
    }
    let mut done = BTreeSet::new();
    graph
        .keys()
        .find_map(|node| visit(node, graph, &mut done, &mut Vec::new()))
}

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

#[test]
fn no_file_imports_itself_through_other_files() {
    let graph = import_graph(&src());
    let edges: usize = graph.values().map(BTreeSet::len).sum();
    // The reader really reads: a tree this size has well over a hundred imports between files,
    // among them these.
    assert!(edges > 100, "only {edges} imports found");
    for (from, to) in [
        ("solvers/discrete/pass.rs", "collision/contact.rs"),
        (
            "solvers/exact/engine/predict.rs",
            "solvers/exact/engine/mod.rs",
        ),
        ("solvers/exact/engine/predict.rs", "collision/toi.rs"),
        ("tools/scene/check.rs", "tools/scene/schema.rs"),
        ("tools/run/mod.rs", "game/plugins.rs"),
    ] {
        assert!(
            graph[&src().join(from)].contains(&src().join(to)),
            "{from} should import {to}: {:?}",
            graph[&src().join(from)]
        );
    }
    if let Some(cycle) = find_cycle(&graph) {
        let names: Vec<String> = cycle
            .iter()
            .map(|f| f.strip_prefix(src()).unwrap().display().to_string())
            .collect();
        panic!("import cycle: {}", names.join(" → "));
    }
}

/// The layers of `src/`, bottom first: a file may import its own layer and those below.
const LAYERS: [&str; 9] = [
    "base",
    "collision",
    "step",
    "solvers",
    "game",
    "tools",
    "render",
    "cli",
    "lib.rs",
];

/// The layer of a file (its top folder under `src/`, or `lib.rs`) and, for a solver, its folder.
fn place_of(file: &Path) -> (usize, Option<String>) {
    let parts: Vec<String> = file
        .strip_prefix(src())
        .unwrap()
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    let layer = LAYERS
        .iter()
        .position(|l| *l == parts[0])
        .unwrap_or_else(|| panic!("{} is in no layer of {LAYERS:?}", file.display()));
    let solver = (parts[0] == "solvers" && parts.len() > 2).then(|| parts[1].clone());
    (layer, solver)
}

/// Every import that points up the layers or from one solver's folder into another's.
fn imports_against_the_layers(graph: &BTreeMap<PathBuf, BTreeSet<PathBuf>>) -> Vec<String> {
    let mut wrong = Vec::new();
    for (from, targets) in graph {
        let (layer, solver) = place_of(from);
        for to in targets {
            let (to_layer, to_solver) = place_of(to);
            let sideways = solver.is_some() && to_solver.is_some() && solver != to_solver;
            if to_layer > layer || sideways {
                wrong.push(format!(
                    "{} -> {}",
                    from.strip_prefix(src()).unwrap().display(),
                    to.strip_prefix(src()).unwrap().display()
                ));
            }
        }
    }
    wrong
}

#[test]
fn every_import_points_down_the_layers_and_no_solver_imports_another() {
    let src = src();
    let tops: BTreeSet<String> = std::fs::read_dir(&src)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    let expected: BTreeSet<String> = LAYERS
        .iter()
        .map(|l| l.to_string())
        .chain(["main.rs".to_owned()])
        .collect();
    assert_eq!(tops, expected, "src/ holds the layers and the binary alone");
    let graph = import_graph(&src);
    let wrong = imports_against_the_layers(&graph);
    assert!(wrong.is_empty(), "imports against the layers: {wrong:#?}");
}

/// The folder-level graph: an edge from a folder to another when a file directly in the first
/// imports a file directly in the second.
fn folder_graph(
    graph: &BTreeMap<PathBuf, BTreeSet<PathBuf>>,
) -> BTreeMap<PathBuf, BTreeSet<PathBuf>> {
    let folder = |f: &Path| f.parent().unwrap().to_path_buf();
    let mut folders: BTreeMap<PathBuf, BTreeSet<PathBuf>> = BTreeMap::new();
    for (from, targets) in graph {
        folders.entry(folder(from)).or_default();
        for to in targets {
            folders.entry(folder(to)).or_default();
            if folder(from) != folder(to) {
                folders.get_mut(&folder(from)).unwrap().insert(folder(to));
            }
        }
    }
    folders
}

#[test]
fn no_folder_imports_itself_through_other_folders() {
    let graph = import_graph(&src());
    let folders = folder_graph(&graph);
    // The reader sees the folders: the solvers' folders import the collision layer's.
    assert!(folders[&src().join("solvers/soft")].contains(&src().join("collision")));
    if let Some(cycle) = find_cycle(&folders) {
        let names: Vec<String> = cycle
            .iter()
            .map(|f| f.strip_prefix(src()).unwrap().display().to_string())
            .collect();
        panic!("folder cycle: {}", names.join(" → "));
    }
}

#[test]
fn an_import_up_the_layers_or_between_solvers_is_found() {
    let file = |p: &str| src().join(p);
    let graph = BTreeMap::from([
        (
            file("collision/toi.rs"),
            BTreeSet::from([file("base/segment.rs"), file("step/schedule.rs")]),
        ),
        (
            file("solvers/soft/solve.rs"),
            BTreeSet::from([file("solvers/soft/rules.rs"), file("solvers/exact/keep.rs")]),
        ),
        (
            file("tools/run/mod.rs"),
            BTreeSet::from([file("game/plugins.rs")]),
        ),
    ]);
    assert_eq!(
        imports_against_the_layers(&graph),
        [
            "collision/toi.rs -> step/schedule.rs",
            "solvers/soft/solve.rs -> solvers/exact/keep.rs"
        ]
    );
}

#[test]
fn a_cycle_is_found_where_there_is_one() {
    let (a, b, c) = (PathBuf::from("a"), PathBuf::from("b"), PathBuf::from("c"));
    let mut graph = BTreeMap::from([
        (a.clone(), BTreeSet::from([b.clone()])),
        (b.clone(), BTreeSet::from([c.clone()])),
        (c.clone(), BTreeSet::new()),
    ]);
    assert_eq!(find_cycle(&graph), None);
    graph.get_mut(&c).unwrap().insert(a.clone());
    assert_eq!(find_cycle(&graph), Some(vec![a.clone(), b, c, a]));
}

#[test]
fn use_trees_are_read_branch_by_branch() {
    let paths = paths_in(&code_of(
        "use crate::a::{b, c::{d, e}};\n// use crate::comment;\nlet x = super::f::g(\"crate::in_string\");",
    ));
    let joined: Vec<String> = paths.iter().map(|p| p.join("::")).collect();
    assert_eq!(
        joined,
        [
            "crate::a::b",
            "crate::a::c::d",
            "crate::a::c::e",
            "super::f::g"
        ]
    );
}

#[test]
fn no_source_file_is_over_450_lines() {
    let long: Vec<String> = rust_files(&src())
        .into_iter()
        .filter_map(|f| {
            let lines = std::fs::read_to_string(&f).unwrap().lines().count();
            (lines > 450).then(|| format!("{} ({lines} lines)", f.display()))
        })
        .collect();
    assert!(long.is_empty(), "split along their seams: {long:?}");
}

/// The files under `src/` that name a variant of `Solver` (in code, docs or tests), relative
/// to `src/`.
fn files_naming_solver_variants() -> BTreeSet<String> {
    let variant = ["Discrete", "Substeps", "Swept", "Exact", "Soft"];
    rust_files(&src())
        .into_iter()
        .filter(|f| {
            let text = std::fs::read_to_string(f).unwrap();
            text.match_indices("Solver::").any(|(at, _)| {
                let rest = &text[at + "Solver::".len()..];
                let name: String = rest
                    .chars()
                    .take_while(char::is_ascii_alphanumeric)
                    .collect();
                variant.contains(&name.as_str())
            })
        })
        .map(|f| f.strip_prefix(src()).unwrap().display().to_string())
        .collect()
}

#[test]
fn solver_variants_are_named_only_by_the_config_the_solvers_and_the_crate_docs() {
    // Adding a solver is its variant in the config, its folder and a line in the plugin group:
    // whatever else must tell solvers apart asks `Solver`'s methods and lists.
    let named = files_naming_solver_variants();
    let elsewhere: Vec<&String> = named
        .iter()
        .filter(|f| !f.starts_with("solvers/") && *f != "base/config/mod.rs" && *f != "lib.rs")
        .collect();
    assert!(
        elsewhere.is_empty(),
        "ask Solver's methods or lists instead: {elsewhere:?}"
    );
    assert!(named.len() <= 6, "{named:?}");
    assert!(named.contains("base/config/mod.rs"), "{named:?}");
}
