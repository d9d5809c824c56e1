//! Peek-and-pass in a hallway (issue 20): one plan with 20 tracked people and 64 Ψ samples,
//! and the visibility scan behind it.
//!
//! Target: one plan ≤ 1 ms median, with constant-velocity predictions (`pnp`), with
//! predictions that react to each candidate (`pnp-react`), with the first segment's speed
//! in sixths (`pnp-fine`), with a 1.5 s horizon and twelfths (`pnp-agile`), and with a
//! holonomic base's candidates (`pnp-omni`).
//!
//! The planner scores the last plan's choice first, so planning one scene over and over
//! would time its best case. Each iteration plans the next of 10 moments of the scene,
//! 0.1 s apart as on a robot (and after the tenth, the first again: a 0.9 s jump back).
//!
//!     cargo bench -p agent --bench pnp

use agent::map::{LocalMap, Obstacle, StaticMap};
use agent::math::{Real, vec2};
use agent::model::{AgentKind, EgoState, Neighbour};
use agent::pnp::{Pnp, PnpParams};
use agent::visibility::{DEFAULT_RAYS, Visibility};
use criterion::{Criterion, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;

/// A 3 m wide hallway from x = −30 to 30, the robot at the origin driving +x at 2 m/s, and
/// 20 people walking both ways within 12 m of it (seeded), none within 1 m.
fn scene() -> (StaticMap, EgoState, Vec<Neighbour>) {
    let map = StaticMap::new(vec![
        Obstacle::Wall(vec2(-30.0, -1.5), vec2(30.0, -1.5)),
        Obstacle::Wall(vec2(-30.0, 1.5), vec2(30.0, 1.5)),
    ])
    .expect("valid walls");
    let ego = EgoState {
        position: vec2(0.0, 0.0),
        heading: 0.0,
        velocity: vec2(2.0, 0.0),
        yaw_rate: 0.0,
        radius: 0.3,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(20);
    let mut people: Vec<Neighbour> = Vec::new();
    while people.len() < 20 {
        let p = vec2(rng.random_range(-12.0..12.0), rng.random_range(-1.1..1.1));
        let clear = p.norm() > 1.0 && people.iter().all(|o| (o.position - p).norm() > 0.6);
        if clear {
            let way: Real = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            let v = vec2(way * rng.random_range(0.5..1.5), 0.0);
            people.push(Neighbour::new(
                people.len() as u64,
                p,
                v,
                0.3,
                AgentKind::Human,
            ));
        }
    }
    (map, ego, people)
}

/// The scene `t` seconds on: the robot and the people moved on at their velocities.
fn moment(ego: &EgoState, people: &[Neighbour], t: Real) -> (EgoState, Vec<Neighbour>) {
    let ego = EgoState {
        position: ego.position + ego.velocity * t,
        ..*ego
    };
    let people = people
        .iter()
        .map(|b| Neighbour {
            position: b.position + b.velocity * t,
            ..b.clone()
        })
        .collect();
    (ego, people)
}

fn pnp(c: &mut Criterion) {
    let (map, ego, people) = scene();
    let mut local = LocalMap::default();
    let moments: Vec<_> = (0..10)
        .map(|i| {
            let (ego, people) = moment(&ego, &people, 0.1 * Real::from(i));
            let bodies = people.iter().map(|b| (b.position, b.radius));
            let seen = Visibility::scan(ego.position, 12.0, DEFAULT_RAYS, &map, bodies, &mut local);
            (ego, people, seen)
        })
        .collect();
    let goal = vec2(25.0, 0.0);
    let mut g = c.benchmark_group("pnp");
    // `pnp`; the same plan with predictions that react to each candidate (`pnp-react`); and
    // with the first segment's speed in sixths (`pnp-fine`); and with a 1.5 s horizon and the
    // first segment's speed in twelfths (`pnp-agile`); and with velocities in ten directions
    // (`pnp-omni`), and samples spread across people's way half as far (`pnp-omni-across`),
    // and keeping to the side (`pnp-side`), scoring hidden people against braking once they
    // step out (`pnp-side-brake`), keeping to the wall on its right (`pnp-right`).
    for (name, params) in [
        ("plan", PnpParams::default()),
        ("plan-reactive", PnpParams::reactive(true)),
        ("plan-fine", PnpParams::fine(true)),
        ("plan-agile", PnpParams::agile(true)),
        ("plan-omni", PnpParams::omni(true)),
        ("plan-omni-across", PnpParams::omni_across(true)),
        ("plan-side", PnpParams::side(true)),
        ("plan-side-brake", PnpParams::side_brake(true)),
        ("plan-right", PnpParams::right(true)),
    ] {
        let mut planner = Pnp::new(PnpParams {
            v_max: 3.0,
            a_max: 2.0,
            psi_samples: 64,
            ..params
        });
        for (ego, people, seen) in &moments {
            let d = planner.plan(ego, people, &map, goal, Some(seen));
            assert!(d.edges > 0, "the people cast shadows");
        }
        let mut next = moments.iter().cycle();
        g.bench_function(
            format!(
                "{name}-20-people-64-psi-{}-candidates",
                planner.candidates()
            ),
            |b| {
                b.iter(|| {
                    let (ego, people, seen) = next.next().expect("an endless cycle");
                    black_box(planner.plan(ego, black_box(people), &map, goal, Some(seen)))
                })
            },
        );
    }
    let (ego, people, _) = &moments[0];
    let bodies = || people.iter().map(|b| (b.position, b.radius));
    g.bench_function("visibility-scan-360-rays-20-people", |b| {
        b.iter(|| {
            black_box(Visibility::scan(
                ego.position,
                12.0,
                DEFAULT_RAYS,
                &map,
                bodies(),
                &mut local,
            ))
        })
    });
    g.finish();
}

criterion_group!(benches, pnp);
criterion_main!(benches);
