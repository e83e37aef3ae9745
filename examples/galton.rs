//! A Galton board in a window: `assets/scenes/galton.ron` (pegs are static circles, the funnel,
//! guides and bins are segment walls, balls are dropped one by one) with a histogram of the bins
//! drawn over it, counted from the balls' positions every frame.
//!
//! `cargo run --example galton` opens the window. For a picture without a person:
//! `cargo run --example galton -- --screenshot galton.png --frames 150 --steps-per-frame 20`
//! renders 150 frames, each advancing exactly 20 fixed steps (50 simulated seconds: every ball
//! has landed), saves the window and exits.

use std::path::PathBuf;

use bevy::math::DVec2;
use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use moving_circles::prelude::*;
use moving_circles::render::{AppOptions, app};

const SCENE: &str = "assets/scenes/galton.ron";

fn main() -> AppExit {
    let options = match Options::parse(std::env::args().skip(1)) {
        Ok(options) => options,
        Err(message) => {
            eprintln!(
                "galton: {message}\nusage: galton [--screenshot PATH --frames N] [--steps-per-frame K]"
            );
            return AppExit::error();
        }
    };
    let config = Scene::parse(include_str!("../assets/scenes/galton.ron"), SCENE)
        .and_then(|scene| scene.to_config(SCENE))
        .expect("the Galton scene is valid (tested)");
    let mut app = app(
        config,
        AppOptions {
            scene_file: None,
            screenshot: options.screenshot,
            panel: false,
        },
    );
    if let Some(k) = options.steps_per_frame {
        app.insert_resource(TimeUpdateStrategy::FixedTimesteps(k));
    }
    app.add_systems(Startup, spawn_histogram)
        .add_systems(Update, update_histogram)
        .run()
}

/// The command line: where to save a screenshot and after how many frames, and a fixed number
/// of steps per frame instead of real time.
struct Options {
    screenshot: Option<(PathBuf, u32)>,
    steps_per_frame: Option<u32>,
}

impl Options {
    fn parse(mut args: impl Iterator<Item = String>) -> Result<Self, String> {
        let (mut path, mut frames, mut steps_per_frame) = (None, 60, None);
        while let Some(arg) = args.next() {
            let mut value = |name: &str| args.next().ok_or(format!("{name} needs a value"));
            match arg.as_str() {
                "--screenshot" => path = Some(PathBuf::from(value("--screenshot")?)),
                "--frames" => frames = number(&value("--frames")?, "--frames")?,
                "--steps-per-frame" => {
                    steps_per_frame =
                        Some(number(&value("--steps-per-frame")?, "--steps-per-frame")?)
                }
                other => return Err(format!("unknown argument `{other}`")),
            }
        }
        Ok(Self {
            screenshot: path.map(|p| (p, frames)),
            steps_per_frame,
        })
    }
}

fn number(text: &str, name: &str) -> Result<u32, String> {
    match text.parse() {
        Ok(n) if (1..=100_000).contains(&n) => Ok(n),
        _ => Err(format!(
            "{name} must be a whole number from 1 to 100000, got `{text}`"
        )),
    }
}

/// The bins: the x of the bin walls (vertical segments standing on the floor), left to right,
/// and the height below which a ball counts as landed.
fn bins(segments: &Segments, arena: &Arena) -> (Vec<f64>, f64) {
    let standing = segments
        .0
        .iter()
        .filter(|s| s.a.x == s.b.x && s.a.y.min(s.b.y) == arena.min.y);
    let mut edges: Vec<f64> = standing.clone().map(|s| s.a.x).collect();
    edges.sort_by(f64::total_cmp);
    edges.dedup();
    let top = standing
        .map(|s| s.a.y.max(s.b.y))
        .fold(f64::INFINITY, f64::min);
    (edges, top)
}

/// Landed balls per bin: between two neighbouring walls, below their top.
fn count(edges: &[f64], top: f64, balls: impl Iterator<Item = DVec2>) -> Vec<usize> {
    let mut counts = vec![0; edges.len().saturating_sub(1)];
    for p in balls.filter(|p| p.y < top) {
        let k = edges.partition_point(|&x| x < p.x);
        if (1..edges.len()).contains(&k) {
            counts[k - 1] += 1;
        }
    }
    counts
}

/// One bar of the histogram.
#[derive(Component)]
struct Bar(usize);

/// The line of counts under the bars.
#[derive(Component)]
struct Counts;

fn spawn_histogram(mut commands: Commands, segments: Res<Segments>, arena: Res<Arena>) {
    let (edges, _) = bins(&segments, &arena);
    commands
        .spawn((
            Node {
                position_type: PositionType::Absolute,
                right: px(12),
                top: px(48),
                width: px(300),
                flex_direction: FlexDirection::Column,
                row_gap: px(6),
                padding: UiRect::all(px(8)),
                ..default()
            },
            BackgroundColor(Color::srgba(0.0, 0.0, 0.0, 0.6)),
        ))
        .with_children(|panel| {
            panel.spawn((Text::new("balls per bin"), TextFont::from_font_size(15.0)));
            panel
                .spawn(Node {
                    height: px(110),
                    flex_direction: FlexDirection::Row,
                    align_items: AlignItems::FlexEnd,
                    column_gap: px(4),
                    ..default()
                })
                .with_children(|row| {
                    for k in 0..edges.len().saturating_sub(1) {
                        row.spawn((
                            Bar(k),
                            Node {
                                width: px(16),
                                height: percent(0),
                                ..default()
                            },
                            BackgroundColor(Color::srgb(0.95, 0.7, 0.25)),
                        ));
                    }
                });
            panel.spawn((Counts, Text::new(""), TextFont::from_font_size(13.0)));
        });
}

fn update_histogram(
    segments: Res<Segments>,
    arena: Res<Arena>,
    balls: Query<(&Position, &Mass)>,
    mut bars: Query<(&Bar, &mut Node)>,
    mut counts_text: Single<&mut Text, With<Counts>>,
) {
    let (edges, top) = bins(&segments, &arena);
    let landed = balls
        .iter()
        .filter(|(_, m)| !m.is_immovable())
        .map(|(p, _)| p.0);
    let counts = count(&edges, top, landed);
    let most = counts.iter().copied().max().unwrap_or(0).max(1);
    for (bar, mut node) in &mut bars {
        let n = counts.get(bar.0).copied().unwrap_or(0);
        node.height = percent(100.0 * n as f32 / most as f32);
    }
    let line: Vec<String> = counts.iter().map(usize::to_string).collect();
    let total: usize = counts.iter().sum();
    counts_text.0 = format!("{} landed: {}", total, line.join(" "));
}
