//! Every link and image in the repository's Markdown resolves: a relative target must name a file
//! or folder of the repository (tracked by git, or not ignored by it; without git, any file
//! outside `target/`, `fuzz/target/` and `.git/`), and an anchor (`#heading`, `page.md#heading`)
//! a heading of its page under GitHub's slug rule. Web and mail targets are not followed. Fenced
//! code blocks and inline code spans are not Markdown, so what they hold is not read as links.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Component, Path, PathBuf};
use std::process::Command;

/// A link or image whose target is not there: the Markdown file (relative to the root), the line
/// (from 1), the target as written and what is wrong with it.
#[derive(Debug)]
struct Broken {
    file: PathBuf,
    line: usize,
    target: String,
    why: String,
}

/// What a check went through, and what it found broken.
#[derive(Debug, Default)]
struct Checked {
    files: usize,
    links: usize,
    broken: Vec<Broken>,
}

/// Runs git in `root`; its output, if it succeeds.
fn git(root: &Path, args: &[&str]) -> Option<Vec<u8>> {
    let out = Command::new("git")
        .arg("-C")
        .arg(root)
        .args(args)
        .output()
        .ok()?;
    out.status.success().then_some(out.stdout)
}

/// The files of the repository at `root`, relative to it: git's tracked and not-ignored files when
/// `root` is the top of a work tree, else every file found by walking it; only files that exist.
fn repository_files(root: &Path) -> BTreeSet<PathBuf> {
    let top = git(root, &["rev-parse", "--show-toplevel"])
        .map(|out| PathBuf::from(String::from_utf8_lossy(&out).trim()));
    let is_top = top.and_then(|top| top.canonicalize().ok()) == root.canonicalize().ok();
    let args = [
        "ls-files",
        "-z",
        "--cached",
        "--others",
        "--exclude-standard",
    ];
    let mut files = BTreeSet::new();
    match is_top.then(|| git(root, &args)).flatten() {
        Some(out) => files.extend(
            out.split(|&b| b == 0)
                .filter(|name| !name.is_empty())
                .map(|name| PathBuf::from(String::from_utf8_lossy(name).into_owned())),
        ),
        None => walk(root, Path::new(""), &mut files),
    }
    files.retain(|file| root.join(file).is_file());
    files
}

fn walk(root: &Path, dir: &Path, files: &mut BTreeSet<PathBuf>) {
    for entry in std::fs::read_dir(root.join(dir))
        .into_iter()
        .flatten()
        .flatten()
    {
        let path = dir.join(entry.file_name());
        if !entry.file_type().is_ok_and(|t| t.is_dir()) {
            files.insert(path);
        } else if entry.file_name() != ".git"
            && !["target", "fuzz/target"]
                .map(Path::new)
                .contains(&path.as_path())
        {
            walk(root, &path, files);
        }
    }
}

/// Checks every Markdown file of the repository at `root`.
fn check(root: &Path) -> Checked {
    let files = repository_files(root);
    let mut folders = BTreeSet::new();
    for file in &files {
        folders.extend(file.ancestors().skip(1).map(Path::to_path_buf));
    }
    let pages: Vec<&PathBuf> = files
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e.eq_ignore_ascii_case("md")))
        .collect();
    let mut anchors: BTreeMap<PathBuf, BTreeSet<String>> = BTreeMap::new();
    let mut texts = BTreeMap::new();
    for page in &pages {
        let text = without_fences(&std::fs::read_to_string(root.join(page)).unwrap_or_default());
        anchors.insert(page.to_path_buf(), heading_slugs(&text));
        texts.insert(page.to_path_buf(), without_code_spans(&text));
    }
    let mut checked = Checked {
        files: pages.len(),
        ..Checked::default()
    };
    for (page, prose) in &texts {
        for (line, target) in links(prose) {
            checked.links += 1;
            if let Some(why) = problem(page, &target, &files, &folders, &anchors) {
                let file = page.clone();
                checked.broken.push(Broken {
                    file,
                    line,
                    target,
                    why,
                });
            }
        }
    }
    checked
}

/// What is wrong with `target`, linked from `page`, if anything.
fn problem(
    page: &Path,
    target: &str,
    files: &BTreeSet<PathBuf>,
    folders: &BTreeSet<PathBuf>,
    anchors: &BTreeMap<PathBuf, BTreeSet<String>>,
) -> Option<String> {
    let lower = target.to_ascii_lowercase();
    if lower.contains("://") || lower.starts_with("mailto:") {
        return None;
    }
    let (path, anchor) = match target.split_once('#') {
        Some((path, anchor)) => (path, Some(anchor)),
        None => (target, None),
    };
    let path = path.split('?').next().unwrap_or_default();
    let resolved = if path.is_empty() {
        page.to_path_buf()
    } else {
        let base = if path.starts_with('/') {
            PathBuf::new()
        } else {
            page.parent().unwrap_or(Path::new("")).to_path_buf()
        };
        match normalise(&base.join(path.trim_start_matches('/').replace("%20", " "))) {
            Some(resolved) => resolved,
            None => return Some("points outside the repository".into()),
        }
    };
    if !files.contains(&resolved) && !folders.contains(&resolved) {
        return Some(format!("`{}` is not in the repository", resolved.display()));
    }
    let anchor = anchor.filter(|a| !a.is_empty())?;
    let slugs = anchors.get(&resolved)?;
    let anchor = anchor.to_lowercase();
    (!slugs.contains(&anchor))
        .then(|| format!("`{}` has no heading `#{anchor}`", resolved.display()))
}

/// `path` without `.` and `..`, or `None` if it climbs above the root.
fn normalise(path: &Path) -> Option<PathBuf> {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            Component::Normal(name) => out.push(name),
            Component::ParentDir if out.pop() => {}
            Component::CurDir => {}
            _ => return None,
        }
    }
    Some(out)
}

/// Every byte of `bytes` but a newline turned into a space: what is blanked out keeps the
/// offsets and line numbers of the file.
fn blank(bytes: &mut [u8]) {
    for b in bytes.iter_mut().filter(|b| **b != b'\n') {
        *b = b' ';
    }
}

/// `text` with its fenced code blocks blanked out.
fn without_fences(text: &str) -> String {
    let mut out = Vec::with_capacity(text.len());
    let mut fence: Option<(u8, usize)> = None;
    for line in text.split_inclusive('\n') {
        let trimmed = line.trim_start();
        let run = |c: u8| trimmed.bytes().take_while(|&b| b == c).count();
        let opens = [b'`', b'~'].into_iter().find(|&c| run(c) >= 3);
        let code = match (fence, opens) {
            (None, Some(c)) => {
                fence = Some((c, run(c)));
                true
            }
            (Some((c, n)), _) => {
                if run(c) >= n && trimmed[run(c)..].trim().is_empty() {
                    fence = None;
                }
                true
            }
            (None, None) => false,
        };
        let start = out.len();
        out.extend_from_slice(line.as_bytes());
        if code {
            blank(&mut out[start..]);
        }
    }
    String::from_utf8(out).expect("blanking keeps UTF-8")
}

fn backticks(bytes: &[u8]) -> usize {
    bytes.iter().take_while(|&&b| b == b'`').count()
}

/// `text` (without fences) with its inline code spans blanked out too.
fn without_code_spans(text: &str) -> String {
    let mut out = text.as_bytes().to_vec();
    // Code spans live within a paragraph: a backtick run opens one only if a run of the same
    // length closes it before the next blank line.
    let mut i = 0;
    while i < out.len() {
        if out[i] != b'`' {
            i += 1;
            continue;
        }
        let n = backticks(&out[i..]);
        let mut j = i + n;
        let mut close = None;
        while j < out.len() {
            let line = out[j + 1..].split(|&b| b == b'\n').next();
            if out[j] == b'\n' && line.is_some_and(|l| l.trim_ascii().is_empty()) {
                break;
            }
            if out[j] == b'`' {
                let m = backticks(&out[j..]);
                if m == n {
                    close = Some(j + m);
                    break;
                }
                j += m;
            } else {
                j += 1;
            }
        }
        match close {
            Some(end) => {
                blank(&mut out[i..end]);
                i = end;
            }
            None => i += n,
        }
    }
    String::from_utf8(out).expect("blanking keeps UTF-8")
}

/// The targets of the links and images in `prose` (inline `[text](target)`, `![alt](target)`
/// and reference definitions `[label]: target`), each with its line.
fn links(prose: &str) -> Vec<(usize, String)> {
    let bytes = prose.as_bytes();
    let line_of = |at: usize| 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count();
    let mut found = Vec::new();
    let mut from = 0;
    while let Some(at) = prose[from..].find("](").map(|k| from + k) {
        let start = at + 2;
        let mut depth = 0usize;
        let mut end = prose.len();
        for (k, c) in prose[start..].char_indices() {
            match c {
                '(' => depth += 1,
                ')' | '\n' if depth == 0 || c == '\n' => {
                    end = start + k;
                    break;
                }
                ')' => depth -= 1,
                _ => {}
            }
        }
        let inner = prose[start..end].trim();
        let target = match inner.strip_prefix('<') {
            Some(rest) => rest.split('>').next().unwrap_or_default(),
            None => inner.split_whitespace().next().unwrap_or_default(),
        };
        if !target.is_empty() {
            found.push((line_of(at), target.to_string()));
        }
        from = start;
    }
    let mut offset = 0;
    for line in prose.split_inclusive('\n') {
        let trimmed = line.trim_start();
        if line.len() - trimmed.len() <= 3
            && trimmed.starts_with('[')
            && let Some((label, rest)) = trimmed[1..].split_once("]:")
            && !label.is_empty()
            && !label.starts_with('^')
            && !label.contains(['[', ']'])
            && let Some(target) = rest.split_whitespace().next()
        {
            let target = target.trim_start_matches('<').trim_end_matches('>');
            found.push((line_of(offset), target.to_string()));
        }
        offset += line.len();
    }
    found
}

/// The anchors GitHub gives the headings of `prose` (ATX `#` headings and setext underlines).
fn heading_slugs(prose: &str) -> BTreeSet<String> {
    let lines: Vec<&str> = prose.lines().collect();
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    let mut slugs = BTreeSet::new();
    for (k, line) in lines.iter().enumerate() {
        let trimmed = line.trim_start();
        let hashes = trimmed.bytes().take_while(|&b| b == b'#').count();
        let atx = line.len() - trimmed.len() <= 3
            && (1..=6).contains(&hashes)
            && trimmed[hashes..]
                .chars()
                .next()
                .is_none_or(char::is_whitespace);
        let underline = |l: &&str| {
            let l = l.trim();
            !l.is_empty() && (l.bytes().all(|b| b == b'=') || l.bytes().all(|b| b == b'-'))
        };
        let text = if atx {
            trimmed[hashes..].trim().trim_end_matches('#').trim()
        } else if !line.trim().is_empty() && lines.get(k + 1).is_some_and(underline) {
            line.trim()
        } else {
            continue;
        };
        let base = slug(text);
        let count = seen.entry(base.clone()).or_insert(0);
        let suffix = if *count == 0 {
            String::new()
        } else {
            format!("-{count}")
        };
        slugs.insert(base + &suffix);
        *count += 1;
    }
    slugs
}

/// GitHub's anchor for a heading: link syntax reduced to its text, lower case, only letters,
/// digits, `-`, `_` and spaces kept, spaces turned into `-`.
fn slug(heading: &str) -> String {
    let mut text = String::new();
    let mut rest = heading;
    while let Some(at) = rest.find("](") {
        let close = rest[at..].find(')').map_or(rest.len(), |k| at + k + 1);
        text.push_str(&rest[..at]);
        rest = &rest[close..];
    }
    text.push_str(rest);
    text.to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, '-' | '_' | ' '))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

fn report(broken: &[Broken]) -> String {
    broken
        .iter()
        .map(|b| format!("{}:{}: `{}`: {}", b.file.display(), b.line, b.target, b.why))
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn every_link_and_image_in_the_repository_resolves() {
    let checked = check(Path::new(env!("CARGO_MANIFEST_DIR")));
    let broken = report(&checked.broken);
    assert!(broken.is_empty(), "broken links and images:\n{broken}");
    // Not a pass by finding nothing: the README, the guide and their links were read.
    assert!(checked.files >= 10 && checked.links >= 50, "{checked:?}");
}

/// Checks `root` and asserts that the report holds each of `parts`, and no more lines.
fn assert_broken(root: &Path, parts: &[&str]) {
    let message = report(&check(root).broken);
    assert_eq!(message.lines().count(), parts.len(), "{message}");
    for part in parts {
        assert!(message.contains(part), "no `{part}` in:\n{message}");
    }
}

#[test]
fn a_deleted_image_is_found_and_code_is_not_read_as_links() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let root = dir.path();
    std::fs::create_dir_all(root.join("docs/figures")).unwrap();
    std::fs::write(root.join("docs/figures/plot.svg"), "<svg/>").unwrap();
    let other = "# Other\n\n## The `kernels` bench: sizes\n";
    std::fs::write(root.join("docs/other.md"), other).unwrap();
    let page = "# Page\n\n![a plot](figures/plot.svg)\n\n\
                See [the sizes](other.md#the-kernels-bench-sizes), [above](#page),\n\
                [the folder](figures/) and [the web](https://example.com/x.png).\n\n\
                ```text\n[not a link](missing.png)\n```\n\n\
                And `[nor](this.png)` or ``a `[span](x.png)` ``.\n";
    std::fs::write(root.join("docs/page.md"), page).unwrap();
    let checked = check(root);
    assert!(checked.broken.is_empty(), "{}", report(&checked.broken));
    assert_eq!((checked.files, checked.links), (2, 5));

    std::fs::remove_file(root.join("docs/figures/plot.svg")).unwrap();
    assert_broken(
        root,
        &[
            "docs/page.md:3: `figures/plot.svg`: `docs/figures/plot.svg` is not in the repository",
            "docs/page.md:6: `figures/`: `docs/figures` is not in the repository",
        ],
    );
}

#[test]
fn missing_headings_and_paths_outside_the_repository_are_broken() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let page = "# Top\n\n[a](#nowhere) [b](../outside.md) [c](other.md) [d](README.md#top)\n\
                [ref]: gone.txt\n";
    std::fs::write(dir.path().join("README.md"), page).unwrap();
    assert_broken(
        dir.path(),
        &[
            "README.md:3: `#nowhere`: `README.md` has no heading `#nowhere`",
            "README.md:3: `../outside.md`: points outside the repository",
            "README.md:3: `other.md`: `other.md` is not in the repository",
            "README.md:4: `gone.txt`: `gone.txt` is not in the repository",
        ],
    );
}

#[test]
fn slugs_follow_githubs_rule() {
    let text = "# Scenes: simulate only what a scene calls for\n## `exact_events`, 2×\n\
                ## Twice\n## Twice\nSetext\n---\n";
    let expected = [
        "scenes-simulate-only-what-a-scene-calls-for",
        "exact_events-2",
        "twice",
        "twice-1",
        "setext",
    ];
    assert_eq!(heading_slugs(text), expected.map(String::from).into());
}
