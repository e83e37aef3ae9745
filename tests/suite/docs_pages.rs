//! The guide stays a reference: every page of `docs/` but its history at most 300 lines and
//! free of commit hashes, and the pages together (without the history) at most 20,000 words,
//! counted as `wc -w` counts them. History goes to `docs/history.md`.

use std::path::PathBuf;

/// Longest a guide page may be, in lines.
const MAX_LINES: usize = 300;
/// Most words the guide may hold without its history.
const MAX_WORDS: usize = 20_000;

/// The guide's pages but its history, `docs/*.md` in name order: what holds the reference.
pub(crate) fn reference_pages() -> Vec<PathBuf> {
    let mut pages: Vec<PathBuf> = std::fs::read_dir("docs")
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .filter(|p| p.file_name().is_none_or(|n| n != "history.md"))
        .collect();
    pages.sort();
    pages
}

/// [`reference_pages`] with their text.
fn reference_texts() -> Vec<(PathBuf, String)> {
    let text = |p: PathBuf| {
        let text = std::fs::read_to_string(&p).unwrap();
        (p, text)
    };
    reference_pages().into_iter().map(text).collect()
}

/// The words of `text` that look like a commit: 7 to 40 hexadecimal digits with at least one
/// letter and one digit among them.
fn commit_like(text: &str) -> Vec<&str> {
    text.split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|w| (7..=40).contains(&w.len()))
        .filter(|w| {
            w.chars()
                .all(|c| c.is_ascii_digit() || ('a'..='f').contains(&c))
        })
        .filter(|w| w.chars().any(|c| c.is_ascii_digit()) && w.chars().any(char::is_alphabetic))
        .collect()
}

#[test]
fn commit_like_words_are_found_and_ordinary_words_are_not() {
    assert_eq!(
        commit_like("fixed in b6c0e69e, see 53e3767."),
        ["b6c0e69e", "53e3767"]
    );
    assert!(commit_like("deadbeefcafe 1048576 decade faded 0x1f2e3d4c 3.14159265").is_empty());
}

#[test]
fn every_guide_page_is_short_and_names_no_commit() {
    let mut problems = Vec::new();
    for (path, text) in reference_texts() {
        let lines = text.lines().count();
        if lines > MAX_LINES {
            problems.push(format!(
                "{}: {lines} lines (at most {MAX_LINES})",
                path.display()
            ));
        }
        let commits = commit_like(&text);
        if !commits.is_empty() {
            problems.push(format!("{}: names commits {commits:?}", path.display()));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn the_guide_without_its_history_is_at_most_twenty_thousand_words() {
    let pages = reference_texts();
    let words: usize = pages
        .iter()
        .map(|(_, t)| t.split_whitespace().count())
        .sum();
    let each: Vec<String> = pages
        .iter()
        .map(|(p, t)| format!("{} {}", t.split_whitespace().count(), p.display()))
        .collect();
    assert!(
        words <= MAX_WORDS,
        "{words} words (at most {MAX_WORDS}):\n{}",
        each.join("\n")
    );
}
