//! The spatial queries against brute force: the index (`query::index`) on random scenes of
//! narrow and wide radii on walled, open and periodic arenas, and `SpatialQuery` in an app,
//! walls and segment walls included, with its filters and the moment it sees a change.

use bevy::ecs::system::RunSystemOnce;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::base::arena::{Arena, Boundary};
use moving_circles::game::query::index::CircleIndex;
use moving_circles::game::query::shapes::{ray_capsule, ray_disc};
use moving_circles::prelude::*;
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A 10 × 8 arena of `boundary`.
fn arena(boundary: Boundary) -> Arena {
    Arena::centered(DVec2::new(10.0, 8.0)).with_boundary(boundary)
}

fn boundary_of(k: u8) -> Boundary {
    [Boundary::Walls, Boundary::Open, Boundary::Periodic][k as usize % 3]
}

/// Random circles: centres over the arena (and beyond it on an open one), radii in
/// `[r_lo, r_hi]` log-uniform so that wide ranges get several size levels.
fn scene() -> impl Strategy<Value = (Vec<(DVec2, f64)>, u8)> {
    (
        0u8..3,
        prop_oneof![Just((0.05, 0.4)), Just((1e-3, 2.0))],
        0usize..150,
    )
        .prop_flat_map(|(b, (lo, hi), n): (u8, (f64, f64), usize)| {
            let spread = if boundary_of(b) == Boundary::Open {
                9.0
            } else {
                5.0
            };
            let circle = (-spread..spread, -spread..spread, 0.0f64..1.0)
                .prop_map(move |(x, y, u)| (DVec2::new(x, y * 0.8), lo * (hi / lo).powf(u)));
            (prop::collection::vec(circle, n), Just(b))
        })
}

/// Every image of a periodic arena within `reach` of the box, or the plain offset.
fn images(arena: &Arena, reach: f64) -> Vec<DVec2> {
    if !arena.is_periodic() {
        return vec![DVec2::ZERO];
    }
    let size = arena.size();
    let (nx, ny) = (
        (reach / size.x).ceil() as i64 + 1,
        (reach / size.y).ceil() as i64 + 1,
    );
    let mut out = Vec::new();
    for i in -nx..=nx {
        for j in -ny..=ny {
            out.push(DVec2::new(i as f64 * size.x, j as f64 * size.y));
        }
    }
    out
}

/// The first circle (lowest index on a tie) that a circle of `radius` moving from `o` along
/// `d` meets within `max`, by testing every circle's every image.
fn brute_cast(
    circles: &[(DVec2, f64)],
    arena: &Arena,
    o: DVec2,
    d: DVec2,
    radius: f64,
    max: f64,
) -> Option<(f64, u32)> {
    let shifts = images(arena, max + 10.0);
    let mut best: Option<(f64, u32)> = None;
    for (i, &(c, r)) in circles.iter().enumerate() {
        let c = if arena.is_periodic() {
            arena.wrap(c)
        } else {
            c
        };
        for s in &shifts {
            if let Some(t) = ray_disc(o, d, c + *s, r + radius)
                && t <= max
                && best.is_none_or(|b| (t, i as u32) < b)
            {
                best = Some((t, i as u32));
            }
        }
    }
    best
}

/// Whether the index's cast and brute force agree: the same distance to rounding, and the
/// index's circle is one brute force meets at that distance.
fn same_cast(
    circles: &[(DVec2, f64)],
    arena: &Arena,
    (o, d, radius, max): (DVec2, DVec2, f64, f64),
    got: Option<(f64, u32)>,
    want: Option<(f64, u32)>,
) -> Result<(), TestCaseError> {
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * (1.0 + a.abs());
    match (got, want) {
        (None, None) => Ok(()),
        (Some(g), Some(w)) if g.1 == w.1 && close(g.0, w.0) => Ok(()),
        (Some(g), Some(w)) if close(g.0, w.0) => {
            // A tie to rounding: the index's circle must be met there too.
            let own = brute_cast(
                &circles[g.1 as usize..=g.1 as usize],
                arena,
                o,
                d,
                radius,
                max,
            );
            prop_assert!(own.is_some_and(|t| close(t.0, w.0)), "{g:?} vs {w:?}");
            Ok(())
        }
        // Grazing a rim within rounding of `max` may count on one side only.
        (Some(g), None) | (None, Some(g)) if close(g.0, max) => Ok(()),
        _ => Err(TestCaseError::fail(format!(
            "index {got:?}, brute force {want:?}"
        ))),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(10_000))]

    #[test]
    fn the_index_finds_what_brute_force_finds(
        (circles, b) in scene(),
        p in (-12.0f64..12.0, -10.0f64..10.0),
        angle in 0.0f64..std::f64::consts::TAU,
        radius in prop_oneof![Just(0.0), 0.0f64..1.5],
        max in prop_oneof![Just(f64::INFINITY), 0.0f64..30.0],
    ) {
        let arena = arena(boundary_of(b));
        let mut index = CircleIndex::default();
        index.build(&circles, &arena);
        let p = DVec2::new(p.0, p.1);
        let offset = |c: DVec2| arena.offset(p, c);

        // Circles within `radius` plus their own of the point (a point query at 0).
        let mut got = Vec::new();
        index.for_each_near(p, radius, |i, off, r| {
            if off.length() < r + radius {
                got.push(i);
            }
        });
        got.sort_unstable();
        let want: Vec<u32> = (0..circles.len() as u32)
            .filter(|&i| offset(circles[i as usize].0).length() < circles[i as usize].1 + radius)
            .collect();
        prop_assert_eq!(got, want);

        // The first circle a cast meets (the periodic ray stops within two boxes, so brute
        // force can list the images).
        let max = if arena.is_periodic() { max.min(20.0) } else { max };
        let d = DVec2::from_angle(angle);
        let accept_even = |i: u32| i % 3 != 1;
        let got = index.cast(p, d, radius, max, accept_even).map(|h| (h.distance, h.index));
        let kept: Vec<(DVec2, f64)> = circles
            .iter()
            .enumerate()
            .map(|(i, &c)| if accept_even(i as u32) { c } else { (DVec2::splat(f64::NAN), 0.0) })
            .collect();
        let want = brute_cast(&kept, &arena, p, d, radius, max);
        same_cast(&circles, &arena, (p, d, radius, max), got, want)?;
    }
}

/// A tiny deterministic random source for the app-level checks.
fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// `SpatialQuery` in an app with walls and segment walls, against brute force over the same
/// circles and walls: 20 scenes × 500 queries of each kind.
#[test]
fn spatial_query_matches_brute_force_with_walls_and_segments() {
    let mut queries = 0;
    for seed in 0..20u64 {
        let mut r = rng(seed);
        let boundary = if seed % 2 == 0 {
            Boundary::Walls
        } else {
            Boundary::Open
        };
        let point =
            |r: &mut ChaCha8Rng| DVec2::new(r.random_range(-5.0..5.0), r.random_range(-4.0..4.0));
        let segments: Vec<Segment> = (0..4)
            .map(|_| Segment::new(point(&mut r), point(&mut r)))
            .collect();
        let config = CirclesConfig {
            arena: arena(boundary),
            segments: Segments(segments.clone()),
            ..default()
        };
        let mut app = crate::common::create_app(config);
        let circles: Vec<(DVec2, f64)> = (0..120)
            .map(|_| {
                let c = DVec2::new(r.random_range(-5.0..5.0), r.random_range(-4.0..4.0));
                (c, r.random_range(0.02..0.4))
            })
            .collect();
        let entities: Vec<Entity> = circles
            .iter()
            .map(|&(c, radius)| {
                app.world_mut()
                    .spawn((
                        Position(c),
                        Radius(radius),
                        Sleep {
                            asleep: true,
                            ..default()
                        },
                    ))
                    .id()
            })
            .collect();
        let arena = arena(boundary);
        let mut walls: Vec<(Wall, Segment)> = Vec::new();
        if arena.has_walls() {
            let (lo, hi) = (arena.min, arena.max);
            walls.push((
                Wall::Arena(ArenaWall::Bottom),
                Segment::new(lo, DVec2::new(hi.x, lo.y)),
            ));
            walls.push((
                Wall::Arena(ArenaWall::Right),
                Segment::new(DVec2::new(hi.x, lo.y), hi),
            ));
            walls.push((
                Wall::Arena(ArenaWall::Top),
                Segment::new(hi, DVec2::new(lo.x, hi.y)),
            ));
            walls.push((
                Wall::Arena(ArenaWall::Left),
                Segment::new(DVec2::new(lo.x, hi.y), lo),
            ));
        }
        walls.extend(
            segments
                .iter()
                .enumerate()
                .map(|(k, s)| (Wall::Segment(k as u32), *s)),
        );
        let asks: Vec<(DVec2, DVec2, f64, f64)> = (0..500)
            .map(|_| {
                let p = DVec2::new(r.random_range(-7.0..7.0), r.random_range(-6.0..6.0));
                let d = DVec2::from_angle(r.random_range(0.0..std::f64::consts::TAU));
                let radius = if r.random_bool(0.3) {
                    0.0
                } else {
                    r.random_range(0.0..1.0)
                };
                (
                    p,
                    d * r.random_range(0.5..3.0),
                    radius,
                    r.random_range(0.0..15.0),
                )
            })
            .collect();
        let excluded = entities[0];
        let answers = app
            .world_mut()
            .run_system_once_with(
                move |asks: In<Vec<(DVec2, DVec2, f64, f64)>>, query: SpatialQuery| {
                    let filter = QueryFilter::default().excluding([excluded]);
                    asks.iter()
                        .map(|&(p, d, radius, max)| {
                            (
                                query.point(p, &filter),
                                query.overlap_circle(p, radius, &filter),
                                query.circle_cast(p, radius, d, max, &filter),
                            )
                        })
                        .collect::<Vec<_>>()
                },
                asks.clone(),
            )
            .unwrap();
        for ((p, d, radius, max), (points, overlaps, cast)) in asks.into_iter().zip(answers) {
            let d = d.normalize();
            let taken = |i: &usize| entities[*i] != excluded;
            let want_points: Vec<Entity> = (0..circles.len())
                .filter(taken)
                .filter(|&i| (circles[i].0 - p).length() <= circles[i].1)
                .map(|i| entities[i])
                .collect();
            assert_eq!(points, want_points, "point {p}");
            let mut want: Vec<Target> = (0..circles.len())
                .filter(taken)
                .filter(|&i| (circles[i].0 - p).length() < circles[i].1 + radius)
                .map(|i| Target::Circle(entities[i]))
                .collect();
            want.extend(
                walls
                    .iter()
                    .filter(|(_, s)| s.distance(p) < radius)
                    .map(|w| Target::Wall(w.0)),
            );
            assert_eq!(overlaps, want, "overlap {p} {radius}");
            // The first of every circle and wall, circles first on a tie.
            let circle = (0..circles.len())
                .filter(taken)
                .filter_map(|i| {
                    Some((
                        ray_disc(p, d, circles[i].0, circles[i].1 + radius)?,
                        Target::Circle(entities[i]),
                    ))
                })
                .filter(|h| h.0 <= max)
                .min_by(|a, b| a.0.total_cmp(&b.0));
            let wall = walls
                .iter()
                .filter_map(|(w, s)| Some((ray_capsule(p, d, s, radius)?, Target::Wall(*w))))
                .filter(|h| h.0 <= max)
                .min_by(|a, b| a.0.total_cmp(&b.0));
            let want = match (circle, wall) {
                (Some(c), Some(w)) => Some(if c.0 <= w.0 { c } else { w }),
                (c, w) => c.or(w),
            };
            let got = cast.map(|h| (h.distance, h.target));
            match (got, want) {
                (Some(g), Some(w)) => {
                    assert!((g.0 - w.0).abs() < 1e-9, "cast {p} {d}: {g:?} vs {w:?}");
                    assert_eq!(g.1, w.1, "cast {p} {d} r {radius}");
                    let h = cast.unwrap();
                    assert!((h.normal.length() - 1.0).abs() < 1e-9);
                    // Met after moving, the caster touches the target at the point, along the
                    // normal.
                    let centre = p + d * h.distance;
                    assert!(
                        h.distance == 0.0 || (centre - h.point - h.normal * radius).length() < 1e-6,
                        "{h:?}"
                    );
                }
                (g, w) => assert_eq!(g, w, "cast {p} {d} r {radius} max {max}"),
            }
            queries += 1;
        }
    }
    assert_eq!(queries, 10_000);
}

/// The index is built from the circles as the first query after a step finds them: a circle
/// moved by game code is seen where it was until the next step or a refresh.
#[test]
fn queries_see_a_moved_circle_after_the_next_step_or_a_refresh() {
    let mut app = crate::common::create_app(CirclesConfig::default());
    let ball = app
        .world_mut()
        .spawn((Position(DVec2::ZERO), Radius(0.5)))
        .id();
    app.update();
    let at = |app: &mut App, p: DVec2| {
        app.world_mut()
            .run_system_cached_with(
                |p: In<DVec2>, q: SpatialQuery| q.point(*p, &QueryFilter::default()),
                p,
            )
            .unwrap()
    };
    assert_eq!(at(&mut app, DVec2::ZERO), [ball]);
    app.world_mut().get_mut::<Position>(ball).unwrap().0 = DVec2::new(3.0, 0.0);
    assert_eq!(
        at(&mut app, DVec2::ZERO),
        [ball],
        "seen where the last build found it"
    );
    app.world_mut()
        .run_system_cached(|q: SpatialQuery| q.refresh())
        .unwrap();
    assert!(at(&mut app, DVec2::ZERO).is_empty());
    assert_eq!(at(&mut app, DVec2::new(3.0, 0.0)), [ball]);
    app.world_mut().get_mut::<Position>(ball).unwrap().0 = DVec2::new(-3.0, 0.0);
    app.update();
    assert_eq!(
        at(&mut app, DVec2::new(-3.0, 0.0)),
        [ball],
        "rebuilt after a step"
    );
}

/// Filters: circles only, walls only, and a caster that leaves itself out.
#[test]
fn filters_choose_circles_walls_and_leave_out_the_caster() {
    let mut app = crate::common::create_app(CirclesConfig {
        arena: arena(Boundary::Walls),
        ..default()
    });
    let me = app
        .world_mut()
        .spawn((Position(DVec2::ZERO), Radius(0.5)))
        .id();
    let other = app
        .world_mut()
        .spawn((Position(DVec2::new(3.0, 0.0)), Radius(0.5)))
        .id();
    app.update();
    let hits = app
        .world_mut()
        .run_system_once(move |q: SpatialQuery| {
            let cast = |f: &QueryFilter| {
                q.ray_cast(DVec2::ZERO, DVec2::X, f64::INFINITY, f)
                    .map(|h| h.target)
            };
            [
                cast(&QueryFilter::default()),
                cast(&QueryFilter::default().excluding([me])),
                cast(&QueryFilter::walls_only()),
                cast(&QueryFilter::circles_only().excluding([me, other])),
            ]
        })
        .unwrap();
    assert_eq!(
        hits,
        [
            Some(Target::Circle(me)),
            Some(Target::Circle(other)),
            Some(Target::Wall(Wall::Arena(ArenaWall::Right))),
            None,
        ]
    );
}
