//! The event-driven solvers under gravity: circles fly parabolas between events, so an elastic
//! gas in a box keeps its mechanical energy (kinetic plus potential) to rounding over ten
//! thousand collisions, at the Earth's gravity and at a thousand times it.

use crate::common::*;
use bevy::prelude::*;
use moving_circles::prelude::*;

fn elastic_box(solver: &str, g: f64) -> App {
    let scene = format!(
        "(solver: \"{solver}\", arena: (size: (4.0, 4.0)), effects: (gravity: (0.0, {g})),
          mass: Equal(1.0), spawn: (count: 30, radius: (0.1, 0.2), speed: (2.0, 6.0), seed: 9))"
    );
    let config = Scene::parse(&scene, "box.ron")
        .and_then(|s| s.to_config("box.ron"))
        .unwrap();
    create_app(config)
}

#[test]
fn an_elastic_gas_under_gravity_keeps_its_energy_to_rounding_over_ten_thousand_collisions() {
    for solver in ["exact", "swept"] {
        for g in [-9.81, -1e4] {
            let mut app = elastic_box(solver, g);
            let e0 = app.world().resource::<CircleDiagnostics>().energy;
            let mut steps = 0;
            let hits = |app: &App| {
                app.world().resource::<PairCollisions>().count
                    + app.world().resource::<WallCollisions>().count
            };
            while hits(&app) < 10_000 && steps < 20_000 {
                step(&mut app, 1);
                steps += 1;
            }
            let d = *app.world().resource::<CircleDiagnostics>();
            let drift = (d.energy - e0).abs() / e0;
            eprintln!(
                "{solver}, g = {g}: {} hits in {steps} steps, drift {drift:e}",
                hits(&app)
            );
            assert!(
                hits(&app) >= 10_000,
                "{solver}, g = {g}: only {} hits",
                hits(&app)
            );
            assert!(
                drift <= 1e-12,
                "{solver}, g = {g}: energy drifted by {drift:e}"
            );
            let budget = app.world().resource::<moving_circles::exact::EngineState>();
            assert_eq!(budget.budget_exhausted, 0);
            assert_eq!(
                app.world().resource::<Sleeping>().count,
                0,
                "nothing rests at e = 1"
            );
        }
    }
}
