//! The work behind each `moving_circles` command, callable without the binary: `main.rs` only
//! turns arguments into these options and reports errors.
//!
//! - [`run`]: a headless run of a scene or particle file, with report and dump;
//! - [`accuracy`]: the accuracy study;
//! - [`eos`]: the hard-disk equation of state;
//! - [`systems`]: the systems a scene schedules;
//! - `app` (feature `render`): the windowed app.

use std::path::Path;

use anyhow::Context;

use crate::figure::{Figure, png, svg};
use crate::io::write_atomically;

pub mod accuracy;
#[cfg(feature = "render")]
pub mod app;
pub mod eos;
pub mod run;
pub mod systems;

/// Writes `figure` as `<stem>.svg` and `<stem>.png` inside `out`; the paths written.
pub fn write_figure(
    figure: &impl Figure,
    out: &Path,
    stem: &str,
) -> anyhow::Result<[std::path::PathBuf; 2]> {
    let (vector, picture) = (
        out.join(format!("{stem}.svg")),
        out.join(format!("{stem}.png")),
    );
    let text = svg(figure).map_err(|e| anyhow::anyhow!("drawing {}: {e}", vector.display()))?;
    write_atomically(&vector, text.as_bytes())
        .with_context(|| format!("writing {}", vector.display()))?;
    let bytes = png(figure).map_err(|e| anyhow::anyhow!("drawing {}: {e}", picture.display()))?;
    write_atomically(&picture, &bytes).with_context(|| format!("writing {}", picture.display()))?;
    Ok([vector, picture])
}
