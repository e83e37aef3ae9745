//! The work behind each `moving_circles` command, callable without the binary: `main.rs` only
//! turns arguments into these options and reports errors.
//!
//! - [`run`]: a headless run of a scene or particle file, with report and dump;
//! - [`accuracy`]: the accuracy study;
//! - [`eos`]: the hard-disk equation of state;
//! - [`sweep`]: grids of runs, planned for Slurm or run on this machine's cores, merged;
//! - [`systems`]: the systems a scene schedules;
//! - `app` (feature `render`): the windowed app.

use std::path::Path;

use anyhow::Context;

use crate::tools::figure::{Figure, png, svg};
use crate::tools::io::{check_output_path, csv_text, say, write_atomically};

pub mod accuracy;
#[cfg(feature = "render")]
pub mod app;
pub mod eos;
pub mod run;
pub mod sweep;
pub mod systems;

/// Makes the folder `out` (`--out`) if it is missing and checks that each of `names` can be
/// written in it, before any work whose results would go there.
pub fn prepare_out(out: &Path, names: &[&str]) -> anyhow::Result<()> {
    std::fs::create_dir_all(out)
        .with_context(|| format!("--out: creating the folder {}", out.display()))?;
    for name in names {
        let file = out.join(name);
        check_output_path(&file).with_context(|| format!("cannot write {}", file.display()))?;
    }
    Ok(())
}

/// Writes `rows` as `<stem>.csv` and `figure` as `<stem>.svg` and `<stem>.png` inside `out`,
/// each atomically, and says what it wrote.
pub fn write_results<T: serde::Serialize>(
    rows: &[T],
    figure: &impl Figure,
    out: &Path,
    stem: &str,
) -> anyhow::Result<()> {
    let [csv, vector, picture] = ["csv", "svg", "png"].map(|ext| out.join(format!("{stem}.{ext}")));
    let text = csv_text(rows).context("formatting the CSV")?;
    write_atomically(&csv, text.as_bytes())
        .with_context(|| format!("writing {}", csv.display()))?;
    let drawing = svg(figure).map_err(|e| anyhow::anyhow!("drawing {}: {e}", vector.display()))?;
    write_atomically(&vector, drawing.as_bytes())
        .with_context(|| format!("writing {}", vector.display()))?;
    let bytes = png(figure).map_err(|e| anyhow::anyhow!("drawing {}: {e}", picture.display()))?;
    write_atomically(&picture, &bytes).with_context(|| format!("writing {}", picture.display()))?;
    say(format_args!(
        "wrote {}, {} and {}",
        csv.display(),
        vector.display(),
        picture.display()
    ));
    Ok(())
}
