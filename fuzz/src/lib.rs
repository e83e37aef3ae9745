//! What the fuzz targets check, one function per target, so that the targets in `fuzz_targets/`
//! are one line each and a crash found by one replays with the same checks. A check that fails
//! panics, which libFuzzer reports as a crash and saves the input under `artifacts/`.
//!
//! - [`particles`]: any bytes as a particle file, under both boundaries.
//! - [`scene`]: any bytes as a scene file (read with the scene limit, RON, every value checked).
//! - [`simulate`]: what either reader accepts, run for a few steps under every solver; an
//!   elastic run of the event solvers keeps its energy to rounding.
//! - [`checkpoint`]: any bytes as a checkpoint (the kept corpus holds true checkpoints of small
//!   runs, which libFuzzer mutates); what is accepted is resumed and run a few steps.

use bevy::math::DVec2;
use bevy::prelude::Entity;
use moving_circles::base::arena::{Arena, Boundary};
use moving_circles::base::circle::{CircleState, inverse_inertia, snapshot_with_entities};
use moving_circles::base::components::Inertia;
use moving_circles::base::config::{CirclesConfig, Effects, MAX_CIRCLES, Solver};
use moving_circles::base::error::InputError;
use moving_circles::base::segment::{SegmentCells, Segments};
use moving_circles::solvers::exact::{
    EXACT_EVENTS_PER_CIRCLE, EventBudget, SWEPT_EVENTS_PER_CIRCLE,
};
use moving_circles::step::schedule::StepTotals;
use moving_circles::tools::checkpoint::Checkpoint;
use moving_circles::tools::io::{MAX_SCENE_BYTES, read_limited};
use moving_circles::tools::run::{Report, advance, headless_app_with, out_of_range, run_steps};
use moving_circles::tools::scene::check::{check_circle, first_overlap};
use moving_circles::tools::scene::{Scene, particles as particle_file};

/// Most circles [`simulate`] runs: inputs asking for more are only read and checked. With
/// [`SIMULATED_STEPS`] and [`FUZZ_BUDGET`] this bounds an execution: the slowest input costs
/// about 7 k events, milliseconds in the instrumented build, as most inputs do.
pub const MAX_SIMULATED_CIRCLES: usize = 16;

/// The event budget of [`simulate`]'s runs: `exact`'s a thousandth of its default (100 events
/// per circle and step, far more than a step of a few circles at any ordinary speed needs).
/// Only inelastic collapse and speeds that cross the arena millions of times a step reach the
/// default; they reach this one too and take the same path a thousand times sooner (a tenth of
/// the kept corpus did, at up to 20 s each with the default).
pub const FUZZ_BUDGET: EventBudget = EventBudget {
    swept: SWEPT_EVENTS_PER_CIRCLE,
    exact: EXACT_EVENTS_PER_CIRCLE / 1000,
};

/// The event budget of [`checkpoint`]'s runs, a tenth of [`FUZZ_BUDGET`] for `exact` and an
/// eighth for `swept` (10 and 8 events per circle and step). Mutated checkpoints are mostly
/// hostile (tiny periodic boxes, collapse, speeds the clock cannot resolve) and spend their
/// time at the budget, where nothing is checked but what holds at any budget. On the kept
/// corpus the runs whose overlap is checked are the same 30 `exact` and 32 `swept` runs at
/// this budget as at [`FUZZ_BUDGET`], and the target runs twice as many inputs a second;
/// [`simulate`]'s checked runs would drop from 101 to 89 and 85, so it keeps its own.
pub const CHECKPOINT_BUDGET: EventBudget = EventBudget {
    swept: SWEPT_EVENTS_PER_CIRCLE / 8,
    exact: EXACT_EVENTS_PER_CIRCLE / 10_000,
};

/// Steps [`simulate`] runs under each solver.
pub const SIMULATED_STEPS: u64 = 4;

/// Overlap, in smaller radii, that is rounding and not penetration (as in the hard cases).
const ROUNDING: f64 = 1e-9;

/// How far below [`ROUNDING`] the rounding of a position by its clock must stay for the
/// overlap bound to be promised (see [`resolvable`]): room for speeds that collisions raise past
/// the bound [`resolvable`] takes.
const RESOLUTION_MARGIN: f64 = 1e3;

/// The solvers [`simulate`] runs, one of each kind.
const SOLVERS: [Solver; 5] = [
    Solver::Exact,
    Solver::Swept,
    Solver::Substeps(3),
    Solver::Discrete,
    Solver::Soft(2),
];

/// Energy change, relative to the energy the run began with plus what drops brought, that an
/// elastic run of the event solvers may show ([`elastic`]): rounding over a few steps, far
/// below what one wrong event costs (a snap out of a segment wall once gained 1e-3).
const ELASTIC_DRIFT: f64 = 1e-9;

/// Any bytes as a particle file: refused with a clear one-line error, or accepted as circles
/// that pass every check and that the writer writes back to the same circles.
pub fn particles(data: &[u8]) {
    for boundary in [Boundary::Walls, Boundary::Periodic] {
        let _ = read_particles(data, boundary);
    }
}

/// Any bytes as a scene file: refused with a clear one-line error, or accepted as a
/// configuration whose every value passes the checks again.
pub fn scene(data: &[u8]) {
    let _ = read_scene(data);
}

/// The first byte chooses the reader (even: scene; odd: particle file, bit 1 the boundary), the
/// rest is the file. What the reader accepts, if small enough, runs for [`SIMULATED_STEPS`]
/// under every solver: no panic, no circle non-finite or outside the arena, every report
/// number finite, and under `exact` and `swept` no overlap beyond rounding unless the step's
/// event budget ran out (which the report counts). `substeps=N` and `discrete` promise no bound
/// on overlap for arbitrary inputs: tunnelling and overlap are what they trade for speed.
pub fn simulate(data: &[u8]) {
    let Some((&selector, file)) = data.split_first() else {
        return;
    };
    let config = if selector % 2 == 0 {
        read_scene(file)
    } else {
        let boundary = if selector & 2 == 0 {
            Boundary::Walls
        } else {
            Boundary::Periodic
        };
        read_particles(file, boundary).map(|circles| particle_file::to_config(circles, boundary))
    };
    let Some(config) = config else {
        return;
    };
    if config.circles.len() + config.spawn.target_count(&config.arena) > MAX_SIMULATED_CIRCLES {
        return;
    }
    for solver in SOLVERS {
        let (report, resolved) = run(&config, solver);
        check_report(&report, solver, resolved);
        if resolved && solver.is_continuous() && report.budget_exhausted == 0 && elastic(&config) {
            let expected = report.energy_initial + report.energy_added;
            let change = (report.energy_final - expected).abs();
            assert!(
                change <= ELASTIC_DRIFT * expected.abs(),
                "{solver}: an elastic run changed its energy by {change:e} of {expected:e}: {report:?}"
            );
        }
    }
}

/// Whether the event solvers must keep `config`'s energy to rounding: every hit elastic and
/// smooth, no drag, walls around it (potential energy is measured from the arena's lowest
/// corner; across a periodic edge a falling circle's height jumps), and no immovable circle
/// that moves (a paddle does work).
fn elastic(config: &CirclesConfig) -> bool {
    let e = &config.effects;
    e.restitution == 1.0
        && e.wall_restitution == 1.0
        && e.drag.is_none()
        && !e.is_rough()
        && !e.has_friction()
        && config.arena.boundary == Boundary::Walls
        && config
            .circles
            .iter()
            .all(|c| c.mass.is_finite() || (c.velocity == DVec2::ZERO && c.angular_velocity == 0.0))
}

/// Any bytes as a checkpoint, their checksum first made to match the rest
/// ([`Checkpoint::reseal`]: a mutation would otherwise almost never get past it): refused with
/// a clear one-line error, or accepted as one that is written back to bytes that are read back
/// the same. An accepted checkpoint of at most
/// [`MAX_SIMULATED_CIRCLES`] resumes or is refused the same way, and then runs
/// [`SIMULATED_STEPS`] under its own solver with the promises of [`simulate`] (overlap only
/// if it began with none, of circles or of segment walls: a checkpoint of a time-stepped run
/// may hold overlaps, and an edit of the solver or a wall is not a damage the reader can see);
/// the checkpoint of where it ends is read back.
pub fn checkpoint(data: &[u8]) {
    let mut data = data.to_vec();
    Checkpoint::reseal(&mut data);
    let checkpoint = match Checkpoint::from_bytes(&data, ORIGIN) {
        Ok(checkpoint) => checkpoint,
        Err(error) => {
            refused::<()>(&error);
            return;
        }
    };
    let written = checkpoint.to_bytes();
    read_back(&written, "an accepted checkpoint");
    if checkpoint.circles().len() > MAX_SIMULATED_CIRCLES {
        return;
    }
    let (solver, source, dt) = (
        checkpoint.solver(),
        checkpoint.source.clone(),
        checkpoint.dt(),
    );
    let began_apart = apart(
        checkpoint.circles(),
        checkpoint.arena(),
        checkpoint.segments(),
    );
    let (mut app, mut progress) = match checkpoint.resume(ORIGIN) {
        Ok(resumed) => resumed,
        Err(error) => {
            refused::<()>(&error);
            return;
        }
    };
    app.insert_resource(CHECKPOINT_BUDGET);
    let resolved = resolvable(&mut app, dt);
    // The overlaps the checkpoint says the run saw are its own: judge the steps run here.
    progress.overlaps = Default::default();
    let until = app.world().resource::<StepTotals>().steps + SIMULATED_STEPS;
    advance(&mut app, &mut progress, until, 1, || false, |_| {});
    let report = Report::new(app.world_mut(), ORIGIN, &progress);
    check_report(&report, solver, began_apart && resolved);
    // A state past the range of values (inputs at its edge can drive it there) is written
    // nowhere: `moving_circles run` refuses it, as a non-finite one.
    if out_of_range(app.world_mut()).is_some() {
        return;
    }
    let end = Checkpoint::take(app.world_mut(), &source, &progress).to_bytes();
    read_back(&end, "the checkpoint of a resumed run");
}

/// Whether no two circles overlap, none touches a segment wall and none reaches past an arena
/// wall by more than [`ROUNDING`] of its radius: what the continuous solvers keep from there on.
/// (A circle across a wall, which a checkpoint may hold, is put back inside at its first hit,
/// into whatever is there: the `checkpoint` target's find, a circle of radius 0.76 reaching
/// 0.52 past the wall put back into its neighbour.)
fn apart(circles: &[CircleState], arena: &Arena, segments: &Segments) -> bool {
    let walls = SegmentCells::over_arena(&segments.0, arena);
    let within_walls = |c: &CircleState| {
        let reach = DVec2::splat(c.radius * (1.0 - ROUNDING));
        !arena.has_walls()
            || (c.position - reach).cmpge(arena.min).all()
                && (c.position + reach).cmple(arena.max).all()
    };
    first_overlap(circles, arena).is_none()
        && circles.iter().all(|c| {
            within_walls(c)
                && walls
                    .first_touched(&segments.0, c.position, c.radius)
                    .is_none()
        })
}

/// A checkpoint we wrote must be read back, and written again to the same bytes.
fn read_back(bytes: &[u8], what: &str) {
    match Checkpoint::from_bytes(bytes, ORIGIN) {
        Ok(again) => assert!(
            again.to_bytes() == bytes,
            "{what} is written back otherwise"
        ),
        Err(error) => panic!("{what} is refused when read back: {error}"),
    }
}

/// Reads `data` as a particle file and checks what came of it.
fn read_particles(data: &[u8], boundary: Boundary) -> Option<Vec<CircleState>> {
    let circles = match particle_file::parse_from(data, ORIGIN, boundary, || false) {
        Ok(circles) => circles,
        Err(error) => return refused(&error),
    };
    let arena = Arena::unit_square(boundary);
    assert!(circles.len() <= MAX_CIRCLES);
    check_circles(&circles, &arena);
    let written = particle_file::format(&circles);
    let again = particle_file::parse(&written, ORIGIN, boundary)
        .unwrap_or_else(|e| panic!("the writer's own text is refused: {e}\n{written}"));
    assert_eq!(again, circles, "written and read back differently");
    Some(circles)
}

/// Reads `data` as a scene file and checks what came of it.
fn read_scene(data: &[u8]) -> Option<CirclesConfig> {
    let read = read_limited(data, MAX_SCENE_BYTES)
        .map_err(|message| InputError::whole(ORIGIN, message))
        .and_then(|text| Scene::parse(&text, ORIGIN)?.to_config(ORIGIN));
    let config = match read {
        Ok(config) => config,
        Err(error) => return refused(&error),
    };
    if let Err(e) = config.check() {
        panic!("an accepted scene fails its own check: {e}");
    }
    check_circles(&config.circles, &config.arena);
    Some(config)
}

/// The name inputs are read under; errors must start with it.
const ORIGIN: &str = "fuzz.in";

/// A refusal must be one line, name the input, and carry no raw control byte.
fn refused<T>(error: &InputError) -> Option<T> {
    let text = error.to_string();
    assert!(
        text.starts_with(ORIGIN),
        "error does not name the input: {text}"
    );
    assert!(
        !text.chars().any(char::is_control),
        "raw control byte in: {text:?}"
    );
    None
}

/// Accepted circles are each valid and do not overlap.
fn check_circles(circles: &[CircleState], arena: &Arena) {
    for (i, circle) in circles.iter().enumerate() {
        if let Err(e) = check_circle(circle, arena) {
            panic!("accepted circle {i} fails its check: {e}");
        }
    }
    if let Some((i, j, depth)) = first_overlap(circles, arena) {
        panic!("accepted circles {i} and {j} overlap by {depth:e}");
    }
}

/// Runs `config` under `solver` for [`SIMULATED_STEPS`], sampling every step; with the report,
/// whether its circles were [`resolvable`] at the start.
fn run(config: &CirclesConfig, solver: Solver) -> (Report, bool) {
    let mut app = headless_app_with(
        CirclesConfig {
            solver,
            ..config.clone()
        },
        |app| {
            app.insert_resource(FUZZ_BUDGET);
        },
    );
    let resolved = resolvable(&mut app, config.dt);
    (
        run_steps(&mut app, ORIGIN, SIMULATED_STEPS, 1, |_| {}),
        resolved,
    )
}

/// Whether the circles in `world` move slowly enough for their positions to be known to within
/// [`ROUNDING`] of the smallest radius over the next [`SIMULATED_STEPS`]: a circle at speed `v`
/// is placed to within `v · ε · t` at a clock of `t` (`swept` counts from the step's start,
/// `exact` from the run's), which inputs may make larger than any circle (speeds up to 10³⁰, a
/// circle crossing a 4 × 4 box 10²⁷ times a step). Speeds are bounded by the fastest circle's
/// and the speed the kinetic energy and a fall across the arena could give the lightest one,
/// with [`RESOLUTION_MARGIN`] to spare; a run of ordinary speeds is a million times inside it.
/// Where hits are rough or have friction, spin turns into motion, so the fastest surface and
/// the energy of turning count too, through each circle's own moment of inertia (a circle
/// spinning at 10³⁰ per second sent its neighbour across the box at 10²⁸ in one rough hit: the
/// campaign's `exact` find); a spinning circle that never turns back (no inertia of its own to
/// spend) drives its neighbours like a paddle without bound, so it is never resolvable.
fn resolvable(app: &mut bevy::app::App, dt: f64) -> bool {
    let with_entities = snapshot_with_entities(app.world_mut());
    let world = app.world();
    let arena = world.resource::<Arena>();
    let effects = world.resource::<Effects>();
    let gravity = effects.gravity.map_or(0.0, |g| g.length());
    let spin_moves = effects.is_rough() || effects.has_friction();
    let turning = |c: &CircleState| if spin_moves { c.angular_velocity } else { 0.0 };
    let horizon = world.resource::<StepTotals>().sim_seconds + dt * SIMULATED_STEPS as f64;
    // ½ m v² + ½ I ω², with I the circle's own or a uniform disc's.
    let energy = |(e, c): &(Entity, CircleState)| {
        let w = turning(c);
        let own = world.get::<Inertia>(*e).map(|i| i.0);
        let inv_inertia = inverse_inertia(own, c.inv_mass(), c.radius);
        let turning = match (w, inv_inertia) {
            (0.0, _) => 0.0,
            (_, 0.0) => f64::INFINITY,
            (w, k) => 0.5 * w * w / k,
        };
        0.5 * c.velocity.length_squared() / c.inv_mass() + turning
    };
    let circles: Vec<CircleState> = with_entities.iter().map(|&(_, c)| c).collect();
    let movable = circles.iter().filter(|c| c.inv_mass() > 0.0);
    let kinetic: f64 = with_entities
        .iter()
        .filter(|(_, c)| c.inv_mass() > 0.0)
        .map(energy)
        .sum();
    let lightest = movable.map(|c| c.inv_mass()).fold(0.0, f64::max);
    let fall = 2.0 * gravity * arena.size().max_element();
    let fastest = circles
        .iter()
        .map(|c| c.velocity.length() + (turning(c) * c.radius).abs())
        .fold(0.0, f64::max);
    let speed = fastest.max((2.0 * kinetic * lightest + fall).sqrt());
    let smallest = circles
        .iter()
        .map(|c| c.radius)
        .fold(f64::INFINITY, f64::min);
    circles.is_empty() || speed * f64::EPSILON * horizon * RESOLUTION_MARGIN <= ROUNDING * smallest
}

/// The promises every run keeps, and the overlap bound of the continuous solvers where it is
/// `promised` (circles that began apart and are [`resolvable`]).
fn check_report(report: &Report, solver: Solver, promised: bool) {
    assert_eq!(
        report.non_finite, 0,
        "{solver}: non-finite circles: {report:?}"
    );
    assert!(
        report.is_finite(),
        "{solver}: non-finite report: {report:?}"
    );
    assert_eq!(
        report.escaped, 0,
        "{solver}: circles left the arena: {report:?}"
    );
    if promised && solver.is_continuous() && report.budget_exhausted == 0 {
        assert!(
            report.max_penetration <= ROUNDING,
            "{solver}: overlap {:e} beyond rounding: {report:?}",
            report.max_penetration
        );
    }
}
