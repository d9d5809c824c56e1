//! One call of the safety layer on a robot driving at full speed among 50 perceived people
//! (the planners' benchmark scene, 0.5 persons/m²), in open space and between two walls; and
//! on a robot standing among them, which people walking on would walk into (a yield), and
//! one `admits` call, the predicate planners ask; the open-ground call with the opt-in
//! across-the-way bound on people's strays (`person_accel_across = 2.4`); and the robot's
//! `Guard` checking a command with its memory on (the default) and off, while a fifth of the
//! people are hidden every other call, and with everyone seen (the memory's bookkeeping
//! alone).
//!
//! Target (issue 43): one call with 50 perceived bodies ≤ 20 µs median, yields included
//! (met: results/safety/REPORT.md, "Speed").
//!
//!     cargo bench -p agent --bench safety

mod scene;

use agent::guard::Guard;
use agent::map::{Obstacle, StaticMap};
use agent::math::vec2;
use agent::model::{Command, EgoState};
use agent::planner::PlanningInput;
use agent::safety::{SafetyLayer, SafetyLimits, SafetyParams};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn safety(c: &mut Criterion) {
    let limits = SafetyLimits::SIMULATED_ROBOT;
    let e = scene::ego();
    let people = scene::crowd(50, 7);
    let corridor = StaticMap::new(vec![
        Obstacle::Wall(vec2(-20.0, -1.5), vec2(20.0, -1.5)),
        Obstacle::Wall(vec2(-20.0, 1.5), vec2(20.0, 1.5)),
    ])
    .expect("two valid walls");
    let mut group = c.benchmark_group("safety");
    let standing = EgoState {
        velocity: vec2(0.0, 0.0),
        ..e
    };
    for (name, map) in [("open", StaticMap::empty()), ("corridor", corridor)] {
        let mut layer = SafetyLayer::new(SafetyParams::default());
        let command = Command::Velocity(vec2(1.0, 0.0));
        let threatened = layer.prepare(&e, &limits, &people, &map).threatened();
        group.bench_function(BenchmarkId::new(name, 50), |b| {
            b.iter(|| black_box(layer.guard(command, &e, &limits, black_box(&people), &map)))
        });
        let stay = Command::Velocity(vec2(0.0, 0.0));
        let set = layer.prepare(&standing, &limits, &people, &map);
        eprintln!(
            "{name}: driving threatened {threatened}, standing threatened {}, standing yields: {:?}",
            set.threatened(),
            set.guard(stay).zone
        );
        group.bench_function(BenchmarkId::new(format!("{name}-standing"), 50), |b| {
            b.iter(|| black_box(layer.guard(stay, &standing, &limits, black_box(&people), &map)))
        });
        group.bench_function(BenchmarkId::new(format!("{name}-admits"), 50), |b| {
            let set = layer.prepare(&e, &limits, &people, &map);
            b.iter(|| black_box(set.admits(black_box(command))))
        });
    }
    // The opt-in across-the-way bound (`person_accel_across`) on the open-ground scene.
    let mut across = SafetyLayer::new(SafetyParams {
        person_accel_across: 2.4,
        ..SafetyParams::default()
    });
    let command = Command::Velocity(vec2(1.0, 0.0));
    let open = StaticMap::empty();
    group.bench_function(BenchmarkId::new("open-across", 50), |b| {
        b.iter(|| black_box(across.guard(command, &e, &limits, black_box(&people), &open)))
    });
    // The Guard: the same call through the robot's runtime, with and without its memory.
    let some = &people[..40];
    for (name, memory_time, hiding) in [
        ("guard-memory", 1.0, true),
        ("guard-no-memory", 0.0, true),
        ("guard-memory-all-seen", 1.0, false),
        ("guard-no-memory-all-seen", 0.0, false),
    ] {
        let params = SafetyParams {
            memory_time,
            ..SafetyParams::default()
        };
        let mut guard = Guard::with_params(limits, params);
        let mut hidden = false;
        group.bench_function(BenchmarkId::new(name, 50), |b| {
            b.iter(|| {
                hidden = hiding && !hidden;
                let input = PlanningInput {
                    ego: &e,
                    neighbours: if hidden { some } else { &people },
                    map: &open,
                    goal: vec2(10.0, 0.0),
                    dt: limits.control_period,
                    visibility: None,
                    safety: None,
                };
                black_box(guard.check(command, black_box(&input)))
            })
        });
    }
    group.finish();
}

criterion_group!(benches, safety);
criterion_main!(benches);
