//! The two error types of bad input: [`FieldError`], a configuration value out of range (which
//! field, what is wrong), and [`InputError`], a problem in an input file located as precisely as
//! the file allows (its origin, then the line or the field); and [`printable`], which every
//! message quoting an input passes through.

use std::borrow::Cow;
use std::fmt;

/// A configuration value that cannot be used: the field (as a path like `spawn.radius`) and
/// what is wrong with it.
///
/// ```
/// use moving_circles::base::config::Effects;
///
/// let effects = Effects { restitution: 1.5, ..Effects::default() };
/// let err = effects.check().unwrap_err();
/// assert_eq!(err.field, "effects.restitution");
/// assert_eq!(err.to_string(), "effects.restitution: must be in [0, 1], got 1.5");
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldError {
    /// Where in the configuration, e.g. `spawn.radius` or `circles[2].position`.
    pub field: String,
    /// What is wrong.
    pub message: String,
}

impl FieldError {
    /// A problem with `field`.
    pub fn new(field: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            field: field.into(),
            message: message.into(),
        }
    }

    /// The same problem one level down: `spawn` + `radius` is `spawn.radius`.
    pub fn within(self, parent: &str) -> Self {
        Self {
            field: format!("{parent}.{}", self.field),
            ..self
        }
    }
}

impl fmt::Display for FieldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: {}",
            printable(&self.field),
            printable(&self.message)
        )
    }
}

impl std::error::Error for FieldError {}

/// A problem with an input file, located as precisely as the input allows.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputError {
    /// The file (or other origin) the input came from.
    pub origin: String,
    /// Where in it: `line 12`, `line 3, column 7` or `field circles[2].radius`.
    pub location: Option<String>,
    /// What is wrong.
    pub message: String,
}

impl InputError {
    /// An error at a named field of the input.
    pub fn field(origin: &str, field: impl fmt::Display, message: impl Into<String>) -> Self {
        Self {
            origin: origin.to_owned(),
            location: Some(format!("field `{field}`")),
            message: message.into(),
        }
    }

    /// An error at a line of the input.
    pub fn line(origin: &str, line: usize, message: impl Into<String>) -> Self {
        Self {
            origin: origin.to_owned(),
            location: Some(format!("line {line}")),
            message: message.into(),
        }
    }

    /// An error about the input as a whole.
    pub fn whole(origin: &str, message: impl Into<String>) -> Self {
        Self {
            origin: origin.to_owned(),
            location: None,
            message: message.into(),
        }
    }

    /// A [`FieldError`] found in the input from `origin`.
    pub fn from_field(origin: &str, error: FieldError) -> Self {
        Self::field(origin, error.field, error.message)
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Origins are file names and messages quote the file: neither reaches a terminal raw.
        let (origin, message) = (printable(&self.origin), printable(&self.message));
        match &self.location {
            Some(at) => write!(f, "{origin}: {}: {message}", printable(at)),
            None => write!(f, "{origin}: {message}"),
        }
    }
}

impl std::error::Error for InputError {}

/// `text` with every control character (ESC, BEL, CR, NUL, newline, …) written as a Rust escape
/// (`\u{1b}`, `\r`, …), so that a file name or a word quoted from a file cannot move the cursor,
/// retitle the terminal or forge a line of output. Other text, non-ASCII included, is kept.
///
/// ```
/// use moving_circles::base::error::printable;
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
