//! Output: [`write_atomically`] is how every output file of the project (reports, dumps, the
//! accuracy CSV and plot, screenshots) reaches the disk, [`say`] how the commands print, and
//! [`printable`] what keeps bytes from input files and names from reaching a terminal raw.

use std::borrow::Cow;

use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

/// Writes `bytes` to `path` atomically: to a new temporary file beside it (created exclusively,
/// so no other writer shares it), synced, then renamed over `path`. A reader never sees half a
/// file, and a failed write leaves the old file intact and no temporary file behind.
///
/// ```
/// let path = std::env::temp_dir().join(format!("mc-doc-{}.txt", std::process::id()));
/// moving_circles::io::write_atomically(&path, b"whole").unwrap();
/// assert_eq!(std::fs::read(&path).unwrap(), b"whole");
/// # std::fs::remove_file(&path).unwrap();
/// ```
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    static WRITES: AtomicU64 = AtomicU64::new(0);
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy())
        .unwrap_or_default();
    let tmp = dir.join(format!(
        ".{name}.{}.{}.partial",
        std::process::id(),
        WRITES.fetch_add(1, Ordering::Relaxed)
    ));
    let result = (|| {
        let mut file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)?;
        file.write_all(bytes)?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// `text` with every control character (ESC, BEL, CR, NUL, newline, …) written as a Rust escape
/// (`\u{1b}`, `\r`, …), so that a file name or a word quoted from a file cannot move the cursor,
/// retitle the terminal or forge a line of output. Other text, non-ASCII included, is kept.
///
/// ```
/// use moving_circles::io::printable;
///
/// assert_eq!(printable("ok × 2"), "ok × 2");
/// assert_eq!(printable("a\u{1b}]0;pwned\u{7}b\n"), "a\\u{1b}]0;pwned\\u{7}b\\n");
/// ```
pub fn printable(text: &str) -> Cow<'_, str> {
    if !text.chars().any(char::is_control) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

/// Writes a line to stdout. A closed pipe (`moving_circles run … | head -1`) ends the reader's
/// interest, not the work: the files asked for are still written, so a failed write to stdout
/// is ignored instead of panicking as `println!` does.
pub fn say(line: impl std::fmt::Display) {
    let _ = writeln!(std::io::stdout().lock(), "{}", printable(&line.to_string()));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_the_file_whole_and_leaves_nothing_behind() {
        let dir = std::env::temp_dir().join(format!("mc-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("out.txt");
        write_atomically(&path, b"first").unwrap();
        write_atomically(&path, b"second").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "second");
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            1,
            "no temporary file left behind"
        );
        // A directory cannot be replaced by a file: the write fails and cleans up after itself.
        let blocked = dir.join("blocked");
        std::fs::create_dir(blocked.join("")).unwrap();
        assert!(write_atomically(&blocked, b"x").is_err());
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            2,
            "out.txt and blocked/"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
