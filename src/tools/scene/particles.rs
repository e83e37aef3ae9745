//! The plain-text particle format of the Princeton event-driven collision demo: first line `N`,
//! then one line per circle `rx ry vx vy radius mass r g b` (colour bytes 0-255), in the unit
//! square `[0, 1]²`. Read exactly — every problem names its line — and written back exactly
//! (shortest round-trip decimal for each number). A mass of `inf` is a static circle (it must
//! then be at rest).

use std::io::BufRead;
use std::path::Path;

use bevy::math::DVec2;

use super::check::{check_circle, first_overlap};
use crate::base::arena::{Arena, Boundary};
use crate::base::circle::CircleState;
use crate::base::config::{CirclesConfig, MAX_CIRCLES, SpawnConfig};
use crate::base::error::InputError;
use crate::tools::io::{BYTE_ORDER_MARK, BYTE_ORDER_MARK_MESSAGE, Lines};

/// Most bytes a particle file may have: a dump of the most circles an input may ask for, with
/// every number written to full precision, fits.
pub const MAX_PARTICLE_BYTES: u64 = 4 << 30;

/// Reads a particle file's text. `origin` names it in errors. Circles must lie inside the unit
/// square (with walls: entirely; periodic: their centres) and must not overlap beyond rounding.
pub fn parse(text: &str, origin: &str, boundary: Boundary) -> Result<Vec<CircleState>, InputError> {
    parse_from(text.as_bytes(), origin, boundary, || false)
}

/// [`parse`] reading line by line from `reader`, at most [`MAX_PARTICLE_BYTES`] and lines of at
/// most [`MAX_LINE_BYTES`](crate::tools::io::MAX_LINE_BYTES): memory grows with the circles read,
/// never with what the header claims or with a line that never ends. Before each line it asks
/// `stop` whether to give up (a signal: an endless stream of blank lines must not keep it).
pub fn parse_from(
    reader: impl BufRead,
    origin: &str,
    boundary: Boundary,
    stop: impl Fn() -> bool,
) -> Result<Vec<CircleState>, InputError> {
    parse_limited(reader, origin, boundary, stop, MAX_PARTICLE_BYTES)
}

/// [`parse_from`] with at most `limit` bytes.
fn parse_limited(
    reader: impl BufRead,
    origin: &str,
    boundary: Boundary,
    stop: impl Fn() -> bool,
    limit: u64,
) -> Result<Vec<CircleState>, InputError> {
    let mut lines = Lines::new(reader.take(limit + 1));
    let mut next_line = || -> Result<Option<(usize, String)>, InputError> {
        loop {
            if stop() {
                return Err(InputError::whole(origin, "reading interrupted"));
            }
            let line = lines
                .next()
                .map(|read| read.map(|(n, line)| (n, line.to_owned())));
            // The bytes allowed and one more were read: the file is past the limit (its last
            // line may be cut there, so this is said before that line is looked at).
            if lines.get_ref().limit() == 0 {
                let size = match limit % (1 << 30) {
                    0 => format!("{} GiB", limit >> 30),
                    _ => format!("{limit} bytes"),
                };
                return Err(InputError::whole(
                    origin,
                    format!("larger than the {size} a particle file may have"),
                ));
            }
            match line {
                None => return Ok(None),
                Some(Err((number, message))) => {
                    return Err(InputError::line(origin, number, message));
                }
                Some(Ok((_, line))) if line.is_empty() => continue,
                Some(Ok(numbered)) => return Ok(Some(numbered)),
            }
        }
    };
    let (header_line, header) = next_line()?.ok_or_else(|| {
        InputError::whole(
            origin,
            "empty file: expected the number of circles on the first line",
        )
    })?;
    if header.starts_with(BYTE_ORDER_MARK) {
        return Err(InputError::line(
            origin,
            header_line,
            BYTE_ORDER_MARK_MESSAGE,
        ));
    }
    let n: usize = header.parse().map_err(|_| {
        InputError::line(
            origin,
            header_line,
            format!("expected the number of circles, got `{header}`"),
        )
    })?;
    if n > MAX_CIRCLES {
        return Err(InputError::line(
            origin,
            header_line,
            format!("declares {n} circles; at most {MAX_CIRCLES} are supported"),
        ));
    }
    let arena = Arena::unit_square(boundary);
    // Capacity grows with what is actually read, not with what the header claims.
    let mut circles = Vec::with_capacity(n.min(1 << 16));
    let mut line_of: Vec<usize> = Vec::with_capacity(n.min(1 << 16));
    while let Some((number, line)) = next_line()? {
        if circles.len() == n {
            return Err(InputError::line(
                origin,
                number,
                format!("more circles than the {n} the first line declares"),
            ));
        }
        let circle = parse_circle(&line).map_err(|m| InputError::line(origin, number, m))?;
        check_circle(&circle, &arena)
            .map_err(|e| InputError::line(origin, number, format!("{} {}", e.field, e.message)))?;
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
    if let Some((i, j, depth)) = first_overlap(&circles, &arena) {
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

fn parse_circle(line: &str) -> Result<CircleState, String> {
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
        // A mass of +∞ is a static circle (what a dump of immovable circles writes).
        let immovable = k == 5 && value == f64::INFINITY;
        if !value.is_finite() && !immovable {
            let what = if k == 5 { "finite or `inf`" } else { "finite" };
            return Err(format!("{} must be {what}, got `{}`", FIELDS[k], words[k]));
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
    Ok(CircleState {
        position: DVec2::new(x[0], x[1]),
        velocity: DVec2::new(x[2], x[3]),
        radius: x[4],
        mass: x[5],
        tint: rgb,
        angular_velocity: 0.0,
        rotation: 0.0,
    })
}

/// Reads a particle file.
pub fn read(path: &Path, boundary: Boundary) -> Result<Vec<CircleState>, InputError> {
    read_until(path, boundary, || false)
}

/// [`read`], asking `stop` before each line whether to give up ([`parse_from`]).
pub fn read_until(
    path: &Path,
    boundary: Boundary,
    stop: impl Fn() -> bool,
) -> Result<Vec<CircleState>, InputError> {
    let origin = path.display().to_string();
    let file = std::fs::File::open(path)
        .map_err(|e| InputError::whole(&origin, format!("cannot read: {e}")))?;
    parse_from(std::io::BufReader::new(file), &origin, boundary, stop)
}

/// The particle-format text of `circles`.
pub fn format(circles: &[CircleState]) -> String {
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

/// What a particle file runs as: its circles in the unit square with this `boundary`, no
/// random circles, the default effects, solver and step.
pub fn to_config(circles: Vec<CircleState>, boundary: Boundary) -> CirclesConfig {
    CirclesConfig {
        arena: Arena::unit_square(boundary),
        spawn: SpawnConfig {
            count: 0,
            ..SpawnConfig::default()
        },
        circles,
        ..CirclesConfig::default()
    }
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

    #[test]
    fn a_file_past_the_size_limit_says_so_whatever_its_last_line() {
        // Blank lines, a cut circle line, a whole one: past the limit the error is the limit.
        let limit = 64;
        for text in [
            "\n".repeat(100),
            format!("1\n{}0.5 0.5 0 0 0.01 1 0 0 0\n", " ".repeat(60)),
            format!("1\n0.5 0.5 0 0 0.01 1 0 0 0\n{}", "\n".repeat(60)),
        ] {
            let error = parse_limited(text.as_bytes(), "f", Boundary::Walls, || false, limit)
                .unwrap_err()
                .to_string();
            assert_eq!(
                error,
                "f: larger than the 64 bytes a particle file may have"
            );
        }
        // At the limit exactly, it is read.
        let whole = "1\n0.5 0.5 0 0 0.01 1 0 0 0\n";
        let limit = whole.len() as u64;
        assert!(parse_limited(whole.as_bytes(), "f", Boundary::Walls, || false, limit).is_ok());
    }

    #[test]
    fn a_stop_request_ends_the_reading() {
        let text = format!("2\n{}", "\n".repeat(1000));
        let asked = std::cell::Cell::new(0);
        let stop = || {
            asked.set(asked.get() + 1);
            asked.get() > 10
        };
        let error = parse_from(text.as_bytes(), "f", Boundary::Walls, stop).unwrap_err();
        assert_eq!(error.to_string(), "f: reading interrupted");
        assert_eq!(asked.get(), 11, "asked before each line");
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
                "\u{feff}1\n0.5 0.5 0 0 0.1 1 0 0 0\n",
                "f.txt: line 1: begins with a byte-order mark (U+FEFF",
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
                "f.txt: line 2: mass must be between",
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
}
