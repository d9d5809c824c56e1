//! One world step (people walking, robots parked).
//! Target (issue 3): 1,000 people in a warehouse (≤ 0.3 people/m²) ≤ 1 ms median on one core.
//!
//!     cargo bench -p world-sim --bench world_step
//!
//! `open/N`: N people on an open stage at 0.3 people/m²; `warehouse-large/1000`: the built-in
//! site-scale warehouse (1,000 people, 0.18 per m² of floor, 50 parked robots), with
//! PySocialForce's wall points; `warehouse-large-field/1000`: the same with
//! `humans.walls = "field"` (the wall force read from a table built before timing). Every
//! sample starts from the same crowd (see `time_steps`).

use agent::model::Command;
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Instant;
use world_sim::scenario::{Scenario, WallModel};
use world_sim::world::World;

/// Steps `world` 20 times, then times steps from that state: every sample starts from a copy
/// of it, so that every variant is timed over the same stretch of crowd motion (a
/// warehouse's 1,000 people jam more the longer they walk, and each step then costs more;
/// without the reset a faster variant would be timed on a later, denser crowd).
fn time_steps(c: &mut Criterion, name: &str, people: usize, mut world: World) {
    let park = vec![Command::STOP; world.robots.len()];
    for _ in 0..20 {
        world.step(&park);
    }
    c.benchmark_group("world_step")
        .bench_function(BenchmarkId::new(name, people), |b| {
            b.iter_custom(|steps| {
                let mut world = world.clone();
                let started = Instant::now();
                for _ in 0..steps {
                    world.step(black_box(&park));
                }
                started.elapsed()
            })
        });
}

fn world_step(c: &mut Criterion) {
    for people in [100usize, 1000] {
        let s = Scenario::sized_for(people, 0.3).expect("valid scenario");
        time_steps(c, "open", people, World::open_space(&s));
    }
    let mut s = Scenario::builtin("warehouse-large").expect("built-in scenario");
    time_steps(c, "warehouse-large", 1000, World::from_scenario(&s));
    s.humans.walls = WallModel::Field;
    time_steps(c, "warehouse-large-field", 1000, World::from_scenario(&s));
}

criterion_group!(benches, world_step);
criterion_main!(benches);
