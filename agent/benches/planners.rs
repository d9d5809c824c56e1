//! One planning step of every planner, with 10, 50 and 200 neighbours spread around the robot
//! at 0.5 persons/m² (seeded), in open space like the PGP paper's study.
//!
//! Targets (issue 2): PGP+DWA with 50 neighbours ≤ 100 µs median; ORCA with 5 ≤ 5 µs.
//!
//!     cargo bench -p agent --bench planners

use agent::map::StaticMap;
use agent::math::{Real, unit, vec2};
use agent::model::{AgentKind, EgoState, Neighbour};
use agent::pgp::{Pgp, PgpParams};
use agent::planner::{PlannerSpec, PlannerStack, PlanningInput};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;

const DENSITY: Real = 0.5;

fn ego() -> EgoState {
    EgoState {
        position: vec2(0.0, 0.0),
        heading: 0.0,
        velocity: vec2(0.8, 0.0),
        yaw_rate: 0.0,
        radius: 0.3,
    }
}

/// `n` people in a square centred on the robot at `DENSITY`, none within 0.8 m of it.
fn crowd(n: usize, seed: u64) -> Vec<Neighbour> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let half = (n as Real / DENSITY).sqrt() / 2.0;
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let p = vec2(rng.random_range(-half..half), rng.random_range(-half..half));
        if p.norm() < 0.8 {
            continue;
        }
        let v = unit(rng.random_range(0.0..std::f64::consts::TAU)) * rng.random_range(0.5..1.3);
        out.push(Neighbour::new(
            out.len() as u64,
            p,
            v,
            0.35,
            AgentKind::Human,
        ));
    }
    out
}

fn planners(c: &mut Criterion) {
    let map = StaticMap::empty();
    let e = ego();
    let goal = vec2(20.0, 0.0);
    let mut group = c.benchmark_group("plan");
    for n in [10usize, 50, 200] {
        let people = crowd(n, 7);
        for spec in PlannerSpec::STUDY {
            let mut stack = PlannerStack::new(spec);
            let input = PlanningInput {
                ego: &e,
                neighbours: &people,
                map: &map,
                goal,
                dt: 0.1,
            };
            group.bench_with_input(BenchmarkId::new(spec.to_string(), n), &input, |b, input| {
                b.iter(|| black_box(stack.plan(black_box(input))))
            });
        }
        for (name, record_fan) in [("pgp", true), ("pgp-nofan", false)] {
            let mut pgp = Pgp::new(PgpParams {
                record_fan,
                ..PgpParams::default()
            });
            group.bench_with_input(BenchmarkId::new(name, n), &people, |b, people| {
                b.iter(|| black_box(pgp.plan(&e, black_box(people), &map, goal)))
            });
        }
    }
    let five = crowd(5, 11);
    let mut orca = PlannerStack::new("orca".parse().expect("known planner"));
    let input = PlanningInput {
        ego: &e,
        neighbours: &five,
        map: &map,
        goal,
        dt: 0.1,
    };
    group.bench_function(BenchmarkId::new("orca", 5), |b| {
        b.iter(|| black_box(orca.plan(black_box(&input))))
    });
    group.finish();
}

criterion_group!(benches, planners);
criterion_main!(benches);
