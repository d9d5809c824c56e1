//! Anticipatory Social Force (issue 21): one estimate-and-optimise update (the long cycle)
//! with 10 and 20 tracked people (the paper's parameters, and `asfm-crowd`'s with 20), and
//! one control step (the short cycle: filters, estimates and the control law of Eq. 11).
//!
//! Targets: one update ≤ 2 ms median, one control step ≤ 20 µs median.
//!
//!     cargo bench -p agent --bench asfm

use agent::asfm::{Asfm, AsfmParams};
use agent::map::{Obstacle, StaticMap};
use agent::math::{Real, Vec2, vec2};
use agent::model::{AgentKind, EgoState, Neighbour};
use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;

/// A 6 m wide hall, the robot at the origin driving +x at 1 m/s toward (12, 0), and `n`
/// people within 5 m of it walking both ways (seeded), none within 1 m; `k` steps of 0.1 s
/// into the scene.
fn scene(n: usize, k: usize) -> (StaticMap, EgoState, Vec<Neighbour>) {
    let map = StaticMap::new(vec![
        Obstacle::Wall(vec2(-20.0, -3.0), vec2(20.0, -3.0)),
        Obstacle::Wall(vec2(-20.0, 3.0), vec2(20.0, 3.0)),
    ])
    .expect("valid walls");
    let t = k as Real * 0.1;
    let ego = EgoState {
        position: vec2(t, 0.0),
        heading: 0.0,
        velocity: vec2(1.0, 0.0),
        yaw_rate: 0.0,
        radius: 0.3,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let mut people: Vec<(Vec2, Vec2)> = Vec::new();
    while people.len() < n {
        let p = vec2(rng.random_range(-5.0..5.0), rng.random_range(-2.5..2.5));
        let clear = p.norm() > 1.0 && people.iter().all(|o| (o.0 - p).norm() > 0.7);
        if clear {
            let way: Real = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            people.push((p, vec2(way * rng.random_range(0.5..1.5), 0.0)));
        }
    }
    let people = people
        .iter()
        .enumerate()
        .map(|(i, &(p, v))| Neighbour::new(i as u64, p + v * t, v, 0.3, AgentKind::Human))
        .collect();
    (map, ego, people)
}

/// The planner with `params` after `steps` steps of the scene with `n` people.
fn warmed(params: &AsfmParams, n: usize, steps: usize) -> Asfm {
    let mut planner = Asfm::new(params.clone());
    for k in 0..steps {
        let (map, ego, people) = scene(n, k);
        planner.step(&ego, &people, &map, vec2(12.0, 0.0), 0.1);
    }
    planner
}

fn asfm(c: &mut Criterion) {
    let goal = vec2(12.0, 0.0);
    let mut g = c.benchmark_group("asfm");
    for (name, params, n) in [
        ("", AsfmParams::default(), 10),
        ("", AsfmParams::default(), 20),
        ("crowd-", AsfmParams::crowd(), 20),
    ] {
        // Steps 0, 2, 4, … run the long cycle (update period 0.2 s).
        let (map, ego, people) = scene(n, 4);
        let before_update = warmed(&params, n, 4);
        assert!(
            before_update
                .clone()
                .step(&ego, &people, &map, goal, 0.1)
                .updated
        );
        g.bench_function(format!("{name}update-{n}-people"), |b| {
            b.iter_batched(
                || before_update.clone(),
                |mut planner| black_box(planner.step(&ego, black_box(&people), &map, goal, 0.1)),
                BatchSize::SmallInput,
            )
        });
        let (map, ego, people) = scene(n, 5);
        let between = warmed(&params, n, 5);
        assert!(!between.clone().step(&ego, &people, &map, goal, 0.1).updated);
        g.bench_function(format!("{name}control-step-{n}-people"), |b| {
            b.iter_batched(
                || between.clone(),
                |mut planner| black_box(planner.step(&ego, black_box(&people), &map, goal, 0.1)),
                BatchSize::SmallInput,
            )
        });
    }
    g.finish();
}

criterion_group!(benches, asfm);
criterion_main!(benches);
