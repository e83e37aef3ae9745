//! Files in and out: [`write_atomically`] is how every output file of the project (reports,
//! dumps, checkpoints, the accuracy CSV and plot, screenshots) reaches the disk,
//! [`read_limited`] and [`Lines`] how input files are read without trusting their size, [`say`]
//! how the commands print (through [`crate::base::error::printable`], which keeps
//! bytes from input files and names from reaching a terminal raw).

use std::io::{self, BufRead, Read, Write};
use std::path::Path;

use crate::base::error::printable;

/// Most bytes a scene file may have (a scene with more circles belongs in a particle file).
pub const MAX_SCENE_BYTES: u64 = 64 << 20;
/// Most bytes of one line of a line-based input (particle files, checkpoints).
pub const MAX_LINE_BYTES: usize = 4096;

/// What some editors put before the text of a UTF-8 file, invisible in most, and a syntax
/// error to RON and to the particle format.
pub const BYTE_ORDER_MARK: char = '\u{feff}';
/// What a file that begins with [`BYTE_ORDER_MARK`] is told.
pub const BYTE_ORDER_MARK_MESSAGE: &str = "begins with a byte-order mark (U+FEFF, invisible in most editors): save it as UTF-8 without one";

/// Reads all of `reader` as UTF-8 text, refusing it past `limit` bytes: a device or an endless
/// file costs at most `limit` bytes of memory before the error. The error says what is wrong,
/// without the file's name (the caller adds it).
pub fn read_limited(reader: impl Read, limit: u64) -> Result<String, String> {
    let bytes = read_bytes_limited(reader, limit)
        .map_err(|e| format!("cannot read: {e}"))?
        .ok_or_else(|| format!("larger than the {} MiB this input may have", limit >> 20))?;
    String::from_utf8(bytes).map_err(|e| {
        format!(
            "not UTF-8 text (byte {} is not valid)",
            e.utf8_error().valid_up_to()
        )
    })
}

/// All of `reader`'s bytes, or `None` if it has more than `limit` (having read at most one
/// byte past it).
pub fn read_bytes_limited(reader: impl Read, limit: u64) -> io::Result<Option<Vec<u8>>> {
    let mut bytes = Vec::new();
    reader.take(limit + 1).read_to_end(&mut bytes)?;
    Ok((bytes.len() as u64 <= limit).then_some(bytes))
}

/// Where a line could not be read and why: its number and the message.
pub type LineError = (usize, String);

/// The lines of a text input, numbered from 1 and trimmed, each at most [`MAX_LINE_BYTES`]: an
/// endless line (a device, a binary file) is an error after that many bytes, not a growing
/// buffer. Items are `(line number, line)` or the error's line number and message.
pub struct Lines<R> {
    reader: R,
    number: usize,
    buffer: Vec<u8>,
}

impl<R: BufRead> Lines<R> {
    /// Lines of `reader`.
    pub fn new(reader: R) -> Self {
        Self {
            reader,
            number: 0,
            buffer: Vec::new(),
        }
    }

    /// The reader the lines come from.
    pub fn get_ref(&self) -> &R {
        &self.reader
    }

    /// The next line, `None` at the end of the input.
    #[allow(clippy::should_implement_trait)]
    pub fn next(&mut self) -> Option<Result<(usize, &str), LineError>> {
        self.buffer.clear();
        self.number += 1;
        let limit = MAX_LINE_BYTES as u64 + 1;
        match (&mut self.reader)
            .take(limit)
            .read_until(b'\n', &mut self.buffer)
        {
            Ok(0) => return None,
            Ok(_) => {}
            Err(e) => return Some(Err((self.number, format!("cannot read: {e}")))),
        }
        if self.buffer.len() > MAX_LINE_BYTES {
            return Some(Err((
                self.number,
                format!("longer than {MAX_LINE_BYTES} bytes"),
            )));
        }
        Some(match std::str::from_utf8(&self.buffer) {
            Ok(line) => Ok((self.number, line.trim())),
            Err(_) => Err((self.number, "not UTF-8 text".to_owned())),
        })
    }
}

/// Writes `bytes` to `path` atomically: to a temporary file beside it with an unpredictable
/// name, created exclusively (no other writer, no planted link, can share it), synced, then
/// renamed over `path`. A reader never sees half a file; a failed write leaves the old file
/// intact and removes the temporary one. `path` must pass [`check_output_path`].
///
/// ```
/// let path = std::env::temp_dir().join(format!("mc-doc-{}.txt", std::process::id()));
/// moving_circles::tools::io::write_atomically(&path, b"whole").unwrap();
/// assert_eq!(std::fs::read(&path).unwrap(), b"whole");
/// # std::fs::remove_file(&path).unwrap();
/// ```
pub fn write_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
    stage(path, bytes)?.commit()
}

/// A file written whole beside where it goes, not yet in place: [`write_atomically`] in two
/// halves, so that several outputs are all written before any replaces what was there, and then
/// go in place one rename after another. Dropped uncommitted, it is removed and `path` is left as
/// it was.
#[derive(Debug)]
pub struct Staged {
    /// `None` once committed.
    file: Option<tempfile::NamedTempFile>,
    path: std::path::PathBuf,
}

impl Staged {
    /// Puts the file in place of `path` (a rename).
    pub fn commit(mut self) -> io::Result<()> {
        let mut staged = staged_files();
        let file = self.file.take().expect("a staged file is committed once");
        let temporary = file.path().to_owned();
        staged.retain(|p| *p != temporary);
        file.persist(&self.path).map_err(|e| e.error)?;
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if let Some(file) = self.file.take() {
            let mut staged = staged_files();
            let temporary = file.path().to_owned();
            staged.retain(|p| *p != temporary);
            // Removed (by the temporary file's own drop) while the list is held.
            drop(file);
        }
    }
}

/// The temporary files [`stage`] has made and not yet put in place or removed: what
/// [`exit_removing_staged`] removes.
static STAGED: std::sync::Mutex<Vec<std::path::PathBuf>> = std::sync::Mutex::new(Vec::new());

/// [`STAGED`], held: a panic elsewhere while it was held leaves a list still worth reading.
fn staged_files() -> std::sync::MutexGuard<'static, Vec<std::path::PathBuf>> {
    STAGED.lock().unwrap_or_else(|e| e.into_inner())
}

/// Ends the process with `code` at once, from any thread, first removing every temporary file
/// of an output being written: what is in place stays as it was, and nothing half-written is
/// left beside it. The list stays held until the end, so no output is put in place meanwhile.
pub fn exit_removing_staged(code: i32) -> ! {
    let staged = staged_files();
    for temporary in staged.iter() {
        let _ = std::fs::remove_file(temporary);
    }
    std::process::exit(code)
}

/// Writes `bytes` to a temporary file beside `path`, as [`write_atomically`] does, and leaves it
/// there until [`Staged::commit`].
pub fn stage(path: &Path, bytes: &[u8]) -> io::Result<Staged> {
    check_output_path(path)?;
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    let prefix = format!(".{name}.");
    let mut builder = tempfile::Builder::new();
    builder
        .prefix(&prefix)
        .suffix(TEMPORARY_SUFFIX)
        .rand_bytes(TEMPORARY_RANDOM);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // What a plain `File::create` would give: 0666 less the umask.
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    // Made and listed while the list is held: a forced exit finds every temporary file.
    let mut staged = {
        let mut list = staged_files();
        let file = builder.tempfile_in(directory_of(path))?;
        list.push(file.path().to_owned());
        Staged {
            file: Some(file),
            path: path.to_owned(),
        }
    };
    let file = staged.file.as_mut().expect("just made");
    file.write_all(bytes)?;
    file.as_file().sync_all()?;
    // On a failure to commit, the temporary file comes back inside the error and is removed as
    // it drops.
    Ok(staged)
}

/// The end of [`write_atomically`]'s temporary file's name.
const TEMPORARY_SUFFIX: &str = ".partial";
/// Random characters in that name.
const TEMPORARY_RANDOM: usize = 6;
/// The longest file name most file systems take, in bytes.
pub const MAX_NAME_BYTES: usize = 255;

/// Whether `path` can take an output: its folder exists, the path is free or a regular file,
/// and its name is short enough that the temporary file beside it ([`write_atomically`]) can
/// be made. Directories, devices, pipes, sockets and symbolic links are refused, so that an
/// output never replaces a device node or writes through a link somewhere else.
pub fn check_output_path(path: &Path) -> io::Result<()> {
    let refuse = |what: &str| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{} is {what}; outputs are written to regular files only",
                path.display()
            ),
        )
    };
    let Some(name) = path.file_name() else {
        return Err(refuse("not a file name"));
    };
    // `.NAME.` + random + suffix: what the temporary file's name adds.
    let longest = MAX_NAME_BYTES - 2 - TEMPORARY_RANDOM - TEMPORARY_SUFFIX.len();
    if name.len() > longest {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{}: the file name is {} bytes; outputs take at most {longest} (the temporary \
                 file written first adds {})",
                path.display(),
                name.len(),
                MAX_NAME_BYTES - longest
            ),
        ));
    }
    match std::fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_file() => {}
        Ok(meta) => return Err(refuse(kind_of(&meta.file_type()))),
        Err(e) if e.kind() == io::ErrorKind::NotFound => {}
        Err(e) => return Err(e),
    }
    let dir = directory_of(path);
    if !dir.is_dir() {
        return Err(io::Error::new(
            io::ErrorKind::NotFound,
            format!("{}: no such folder", dir.display()),
        ));
    }
    Ok(())
}

/// Whether two output paths name the same file (the same path written two ways, or two links
/// to one file), so that one output would silently replace the other.
pub fn same_output(a: &Path, b: &Path) -> bool {
    let absolute = |p: &Path| std::path::absolute(p).ok();
    if absolute(a).is_some() && absolute(a) == absolute(b) {
        return true;
    }
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

fn directory_of(path: &Path) -> &Path {
    path.parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

fn kind_of(file_type: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file_type.is_char_device() || file_type.is_block_device() {
            return "a device";
        }
        if file_type.is_fifo() {
            return "a pipe";
        }
        if file_type.is_socket() {
            return "a socket";
        }
    }
    if file_type.is_dir() {
        "a directory"
    } else if file_type.is_symlink() {
        "a symbolic link"
    } else {
        "not a regular file"
    }
}

/// `rows` as CSV text, a header line then one line per row, the columns being the fields
/// (through serde).
pub fn csv_text<T: serde::Serialize>(rows: &[T]) -> Result<String, csv::Error> {
    let mut writer = csv::Writer::from_writer(Vec::new());
    for row in rows {
        writer.serialize(row)?;
    }
    let bytes = writer.into_inner().map_err(|e| e.into_error())?;
    Ok(String::from_utf8(bytes).expect("csv writes the UTF-8 it is given"))
}

/// Writes `rows` as CSV to `path`, atomically, and says so.
pub fn write_csv<T: serde::Serialize>(rows: &[T], path: &Path) -> anyhow::Result<()> {
    use anyhow::Context;
    let text = csv_text(rows).context("formatting the CSV")?;
    write_atomically(path, text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    say(format_args!("wrote {}", path.display()));
    Ok(())
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
    fn a_staged_file_is_listed_for_a_forced_exit_until_it_is_in_place_or_removed() {
        let dir = std::env::temp_dir().join(format!("mc-staged-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let listed = |staged: &Staged| {
            let temporary = staged.file.as_ref().unwrap().path().to_owned();
            (staged_files().contains(&temporary), temporary)
        };
        let kept = stage(&dir.join("kept.txt"), b"kept").unwrap();
        let (is_listed, kept_temporary) = listed(&kept);
        assert!(is_listed);
        kept.commit().unwrap();
        assert!(!staged_files().contains(&kept_temporary));
        let dropped = stage(&dir.join("dropped.txt"), b"dropped").unwrap();
        let (is_listed, dropped_temporary) = listed(&dropped);
        assert!(is_listed);
        drop(dropped);
        assert!(!staged_files().contains(&dropped_temporary));
        assert!(!dropped_temporary.exists());
        let mut left: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        left.sort();
        assert_eq!(left, ["kept.txt"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

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
        // A directory or a link is never replaced, and nothing is left behind.
        let blocked = dir.join("blocked");
        std::fs::create_dir(&blocked).unwrap();
        let err = write_atomically(&blocked, b"x").unwrap_err();
        assert!(err.to_string().contains("is a directory"), "{err}");
        #[cfg(unix)]
        {
            let link = dir.join("link");
            std::os::unix::fs::symlink(&path, &link).unwrap();
            let err = write_atomically(&link, b"through the link").unwrap_err();
            assert!(err.to_string().contains("is a symbolic link"), "{err}");
            assert_eq!(std::fs::read_to_string(&path).unwrap(), "second");
        }
        let err = write_atomically(&dir.join("no/such/out.txt"), b"x").unwrap_err();
        assert!(err.to_string().contains("no such folder"), "{err}");
        let left: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .filter(|n| n.to_string_lossy().ends_with(".partial"))
            .collect();
        assert!(left.is_empty(), "{left:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn staged_files_replace_nothing_until_committed() {
        let dir = std::env::temp_dir().join(format!("mc-staged-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (a, b) = (dir.join("a.json"), dir.join("b.txt"));
        std::fs::write(&a, "old a").unwrap();
        std::fs::write(&b, "old b").unwrap();
        let (new_a, new_b) = (stage(&a, b"new a").unwrap(), stage(&b, b"new b").unwrap());
        // Both written, neither in place yet.
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "old b");
        new_a.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "new a");
        // Dropped uncommitted: the old file stays and the staged one is gone.
        drop(new_b);
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "old b");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 2);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_same_file_named_two_ways_is_the_same_output() {
        let here = std::env::current_dir().unwrap();
        assert!(same_output(Path::new("r.json"), &here.join("r.json")));
        assert!(same_output(
            Path::new("a/../r.json"),
            Path::new("a/../r.json")
        ));
        assert!(!same_output(Path::new("r.json"), Path::new("d.txt")));
    }
}
