//! One world step (people walking, robot parked) for a crowd sized at 0.3 people/m².
//! Target (issue 3): 1,000 people ≤ 1 ms median on one core.
//!
//!     cargo bench -p world-sim --bench world_step

use agent::model::Command;
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use world_sim::scenario::Scenario;
use world_sim::world::World;

fn world_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("world_step");
    for people in [100usize, 1000] {
        let s = Scenario::sized_for(people, 0.3).expect("valid scenario");
        let mut world = World::open_space(&s);
        let park = vec![Command::STOP; world.robots.len()];
        group.bench_function(BenchmarkId::from_parameter(people), |b| {
            b.iter(|| world.step(black_box(&park)))
        });
    }
    group.finish();
}

criterion_group!(benches, world_step);
criterion_main!(benches);
