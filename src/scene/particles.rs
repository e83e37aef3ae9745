//! The plain-text particle format of the Princeton event-driven collision demo: first line `N`,
//! then one line per circle `rx ry vx vy radius mass r g b` (colour bytes 0-255), in the unit
//! square `[0, 1]²`. Read exactly — every problem names its line — and written back exactly
//! (shortest round-trip decimal for each number), atomically.

use std::io::Write;
use std::path::Path;

use bevy::math::DVec2;
use bevy::prelude::*;

use super::{InputError, check_circle, first_overlap};
use crate::config::{Arena, Boundary};
use crate::spawn::CircleInit;

/// The arena of the particle format.
pub fn unit_square() -> Arena {
    Arena {
        min: DVec2::ZERO,
        max: DVec2::ONE,
    }
}

/// Most circles a particle file may declare (bounds memory before anything is read).
pub const MAX_PARTICLES: usize = 20_000_000;

/// Reads a particle file's text. `origin` names it in errors. Circles must lie inside the unit
/// square (with walls: entirely; periodic: their centres) and must not overlap beyond rounding.
pub fn parse(text: &str, origin: &str, boundary: Boundary) -> Result<Vec<CircleInit>, InputError> {
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim()));
    let (header_line, header) = lines.by_ref().find(|(_, l)| !l.is_empty()).ok_or_else(|| {
        InputError::whole(
            origin,
            "empty file: expected the number of circles on the first line",
        )
    })?;
    let n: usize = header.parse().map_err(|_| {
        InputError::line(
            origin,
            header_line,
            format!("expected the number of circles, got `{header}`"),
        )
    })?;
    if n > MAX_PARTICLES {
        return Err(InputError::line(
            origin,
            header_line,
            format!("declares {n} circles; at most {MAX_PARTICLES} are supported"),
        ));
    }
    let arena = unit_square();
    // Capacity grows with what is actually read, not with what the header claims.
    let mut circles = Vec::with_capacity(n.min(1 << 16));
    let mut line_of = Vec::with_capacity(n.min(1 << 16));
    for (number, line) in lines {
        if line.is_empty() {
            continue;
        }
        if circles.len() == n {
            return Err(InputError::line(
                origin,
                number,
                format!("more circles than the {n} the first line declares"),
            ));
        }
        let circle = parse_circle(line).map_err(|m| InputError::line(origin, number, m))?;
        check_circle(&circle, &arena, boundary).map_err(|(field, message)| {
            InputError::line(origin, number, format!("{field} {message}"))
        })?;
        circles.push(circle);
        line_of.push(number);
    }
    if circles.len() < n {
        return Err(InputError::whole(
            origin,
            format!(
                "the first line declares {n} circles but the file has {}",
                circles.len()
            ),
        ));
    }
    if let Some((i, j, depth)) = first_overlap(&circles, boundary, &arena) {
        return Err(InputError::line(
            origin,
            line_of[j],
            format!(
                "circle overlaps the one on line {} by {depth:.3e}",
                line_of[i]
            ),
        ));
    }
    Ok(circles)
}

const FIELDS: [&str; 9] = ["rx", "ry", "vx", "vy", "radius", "mass", "r", "g", "b"];

fn parse_circle(line: &str) -> Result<CircleInit, String> {
    let words: Vec<&str> = line.split_whitespace().collect();
    if words.len() != FIELDS.len() {
        return Err(format!(
            "expected 9 numbers `rx ry vx vy radius mass r g b`, got {}",
            words.len()
        ));
    }
    let mut x = [0.0f64; 6];
    for (k, slot) in x.iter_mut().enumerate() {
        let value: f64 = words[k]
            .parse()
            .map_err(|_| format!("{} is not a number: `{}`", FIELDS[k], words[k]))?;
        if !value.is_finite() {
            return Err(format!("{} must be finite, got `{}`", FIELDS[k], words[k]));
        }
        *slot = value;
    }
    let mut rgb = [0u8; 3];
    for (k, slot) in rgb.iter_mut().enumerate() {
        let word = words[6 + k];
        *slot = word
            .parse()
            .map_err(|_| format!("{} must be an integer 0-255, got `{word}`", FIELDS[6 + k]))?;
    }
    Ok(CircleInit {
        position: DVec2::new(x[0], x[1]),
        velocity: DVec2::new(x[2], x[3]),
        radius: x[4],
        mass: x[5],
        tint: rgb,
    })
}

/// Reads a particle file.
pub fn read(path: &Path, boundary: Boundary) -> Result<Vec<CircleInit>, InputError> {
    let origin = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| InputError::whole(&origin, format!("cannot read: {e}")))?;
    parse(&text, &origin, boundary)
}

/// The particle-format text of `circles`.
pub fn format(circles: &[CircleInit]) -> String {
    let mut out = format!("{}\n", circles.len());
    for c in circles {
        let [r, g, b] = c.tint;
        out.push_str(&format!(
            "{} {} {} {} {} {} {r} {g} {b}\n",
            c.position.x, c.position.y, c.velocity.x, c.velocity.y, c.radius, c.mass
        ));
    }
    out
}

/// Writes `text` to `path` atomically: to a temporary file beside it, then renamed over it, so a
/// reader never sees half a file and a failed write leaves the old one intact.
pub fn write_atomically(path: &Path, text: &str) -> std::io::Result<()> {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy())
        .unwrap_or_default();
    let tmp = dir.join(format!(".{name}.{}.partial", std::process::id()));
    let result = (|| {
        let mut file = std::fs::File::create(&tmp)?;
        file.write_all(text.as_bytes())?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_and_writes_back_exactly() {
        let text = "2\n0.25 0.5 0.01 -0.02 0.05 1 255 0 10\n0.75 0.5 0 0 0.1 2.5 0 128 255\n";
        let circles = parse(text, "t", Boundary::Walls).unwrap();
        assert_eq!(circles[1].mass, 2.5);
        assert_eq!(circles[0].tint, [255, 0, 10]);
        assert_eq!(format(&circles), text);
    }

    fn error_of(text: &str) -> String {
        parse(text, "f.txt", Boundary::Walls)
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn each_kind_of_bad_line_names_its_line_and_problem() {
        let cases = [
            ("", "f.txt: empty file"),
            (
                "x\n",
                "f.txt: line 1: expected the number of circles, got `x`",
            ),
            (
                "99999999999\n",
                "f.txt: line 1: declares 99999999999 circles",
            ),
            (
                "2\n0.5 0.5 0 0 0.1 1 0 0 0\n",
                "f.txt: the first line declares 2 circles but the file has 1",
            ),
            (
                "1\n0.5 0.5 0 0 0.1 1 0 0\n",
                "f.txt: line 2: expected 9 numbers",
            ),
            (
                "1\n0.5 abc 0 0 0.1 1 0 0 0\n",
                "f.txt: line 2: ry is not a number: `abc`",
            ),
            (
                "1\n0.5 0.5 NaN 0 0.1 1 0 0 0\n",
                "f.txt: line 2: vx must be finite",
            ),
            (
                "1\n0.5 0.5 0 0 -0.1 1 0 0 0\n",
                "f.txt: line 2: radius must be positive",
            ),
            (
                "1\n0.5 0.5 0 0 0.1 0 0 0 0\n",
                "f.txt: line 2: mass must be positive",
            ),
            (
                "1\n0.5 0.5 0 0 0.1 1 0 256 0\n",
                "f.txt: line 2: g must be an integer 0-255",
            ),
            ("1\n0.95 0.5 0 0 0.1 1 0 0 0\n", "f.txt: line 2: position"),
            (
                "1\n0.5 0.5 0 0 0.6 1 0 0 0\n",
                "f.txt: line 2: radius 0.6 is larger than the arena",
            ),
            (
                "1\n0.5 0.5 0 0 0.1 1 0 0 0\n0.5 0.5 0 0 0.1 1 0 0 0\n",
                "f.txt: line 3: more circles",
            ),
            (
                "2\n0.3 0.5 0 0 0.1 1 0 0 0\n0.45 0.5 0 0 0.1 1 0 0 0\n",
                "f.txt: line 3: circle overlaps the one on line 2",
            ),
        ];
        for (text, expected) in cases {
            let message = error_of(text);
            assert!(
                message.starts_with(expected),
                "for {text:?}\n expected: {expected}\n      got: {message}"
            );
        }
    }

    #[test]
    fn touching_within_rounding_is_not_overlapping() {
        // 0.1 + 0.2 is not exactly representable: the centres are 2r apart up to rounding.
        let text = "2\n0.1 0.5 0 0 0.1 1 0 0 0\n0.3 0.5 0 0 0.1 1 0 0 0\n";
        assert_eq!(parse(text, "t", Boundary::Walls).unwrap().len(), 2);
    }

    #[test]
    fn atomic_write_replaces_the_file_whole() {
        let dir = std::env::temp_dir().join(format!("mc-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("out.txt");
        write_atomically(&path, "first").unwrap();
        write_atomically(&path, "second").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "second");
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            1,
            "no temporary file left behind"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
