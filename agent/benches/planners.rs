//! One planning step of every planner, with 10, 50 and 200 neighbours spread around the robot
//! at 0.5 persons/m² (seeded), in open space like the PGP paper's study.
//!
//! Targets (issue 2): PGP+DWA with 50 neighbours ≤ 100 µs median; ORCA with 5 ≤ 5 µs.
//!
//!     cargo bench -p agent --bench planners

mod scene;

use agent::map::StaticMap;
use agent::math::vec2;
use agent::pgp::{Pgp, PgpParams};
use agent::planner::{PlannerSpec, PlannerStack, PlanningInput};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn planners(c: &mut Criterion) {
    let map = StaticMap::empty();
    let e = scene::ego();
    let goal = vec2(20.0, 0.0);
    let mut group = c.benchmark_group("plan");
    for n in [10usize, 50, 200] {
        let people = scene::crowd(n, 7);
        for spec in PlannerSpec::STUDY {
            let mut stack = PlannerStack::new(spec);
            let input = PlanningInput {
                ego: &e,
                neighbours: &people,
                map: &map,
                goal,
                dt: 0.1,
                visibility: None,
                safety: None,
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
    let five = scene::crowd(5, 11);
    let mut orca = PlannerStack::new("orca".parse().expect("known planner"));
    let input = PlanningInput {
        ego: &e,
        neighbours: &five,
        map: &map,
        goal,
        dt: 0.1,
        visibility: None,
        safety: None,
    };
    group.bench_function(BenchmarkId::new("orca", 5), |b| {
        b.iter(|| black_box(orca.plan(black_box(&input))))
    });
    group.finish();
}

criterion_group!(benches, planners);
criterion_main!(benches);
