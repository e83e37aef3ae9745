//! What `moving_circles run` is asked to do ([`RunOptions`]: the input, the solver, the
//! length, the outputs) and how it ended ([`Finished`]), with the command line's limits.

use std::path::PathBuf;
use std::str::FromStr;

use crate::base::arena::Boundary;
use crate::base::config::{ParseSolverError, Placement, Solver};

/// Most threads `--threads` may ask for: far more than any machine this runs on has cores, and
/// few enough that starting them cannot exhaust the process.
pub const MAX_THREADS: u16 = 1024;
/// Most steps one run may ask for: about three hours at a microsecond per step, the cost of a
/// handful of circles; a request for more is a typo for a shorter `--dt` or `--seconds`.
pub const MAX_STEPS: u64 = 10_000_000_000;
/// Where the circles come from.
#[derive(Clone, Debug, PartialEq)]
pub enum Input {
    /// A scene file (RON).
    Scene(PathBuf),
    /// A particle file, in the unit square with this boundary (walls by default).
    Particles(PathBuf, Option<Boundary>),
    /// A checkpoint, to go on from.
    Resume(PathBuf),
}

/// How long to run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Length {
    /// Simulated seconds, rounded up to whole steps.
    Seconds(f64),
    /// Fixed steps.
    Steps(u64),
}

/// A fixed solver, or `auto`: the cheapest that meets a tolerance on a short calibration run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SolverChoice {
    /// This solver.
    Fixed(Solver),
    /// Chosen by measurement.
    Auto,
}

impl FromStr for SolverChoice {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        if s == "auto" {
            return Ok(Self::Auto);
        }
        s.parse()
            .map(Self::Fixed)
            .map_err(|e: ParseSolverError| format!("{e}, or `auto`"))
    }
}

/// Everything `run` is asked to do.
#[derive(Clone, Debug, PartialEq)]
pub struct RunOptions {
    /// The circles.
    pub input: Input,
    /// Overrides the scene's solver.
    pub solver: Option<SolverChoice>,
    /// With `auto`: the largest acceptable error in radii.
    pub tolerance: Option<f64>,
    /// Overrides the fixed step.
    pub dt: Option<f64>,
    /// How long.
    pub length: Length,
    /// Overrides the placement seed.
    pub seed: Option<u64>,
    /// Overrides where the scene's circles are spawned.
    pub placement: Option<Placement>,
    /// Overrides the scene's count with an area fraction to fill.
    pub area_fraction: Option<f64>,
    /// Where the JSON report goes.
    pub report: Option<PathBuf>,
    /// Where the final state goes (particle format).
    pub dump: Option<PathBuf>,
    /// Threads of the parallel parts of a step (results do not depend on it).
    pub threads: Option<u16>,
    /// Whether the kernels may use the processor's vector instructions (results do not depend
    /// on it).
    pub vector: bool,
    /// Where checkpoints go: at the end, when interrupted, and every `every` steps.
    pub checkpoint: Option<PathBuf>,
    /// Steps between checkpoints (counted from the start of the whole run).
    pub every: Option<u64>,
}

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Finished {
    /// It ran its length.
    Completed,
    /// A signal stopped it: after a step, with everything asked for written; while its input
    /// was read or its circles placed, with nothing written; or after its last step, while its
    /// outputs were written (all of them).
    Interrupted {
        /// The signal's number (2 for SIGINT, 15 for SIGTERM).
        signal: i32,
    },
}

impl Finished {
    /// The process's exit status: 0, or 128 + the signal as shells report it (130, 143).
    pub fn exit_code(self) -> u8 {
        match self {
            Self::Completed => 0,
            Self::Interrupted { signal } => 128u8.saturating_add(signal as u8),
        }
    }
}
