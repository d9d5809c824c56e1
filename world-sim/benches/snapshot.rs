//! Fleet snapshots (issue 24): what a snapshot costs the coordinator's tick (a copy of the
//! fleet, handed to the journal's writer) and the writer (encoding), and what a restart pays
//! to restore one. Target: the copy ≤ 5 ms for the site-scale warehouse, 5 % of a 100 ms tick,
//! once every 30 simulated s.
//!
//!     cargo bench -p world-sim --bench snapshot
//!
//! `warehouse-large`: the built-in site-scale warehouse with 100 robots and 1,000 people, the
//! traffic policy on and the human-impact measurement attached (its shadow crowd doubles the
//! people), after 50 steps with tasks dispatched.

use agent::model::Command;
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use world_sim::fleet::Fleet;
use world_sim::scenario::Scenario;
use world_sim::traffic_policy::PolicyParams;

fn snapshot(c: &mut Criterion) {
    let mut s = Scenario::builtin("warehouse-large").expect("built-in scenario");
    s.warehouse.as_mut().expect("a warehouse").robots = 100;
    let mut fleet = Fleet::new(&s).expect("a warehouse");
    fleet.set_traffic_policy(Some(PolicyParams::default()));
    fleet.measure_human_impact(5.0);
    let stop = vec![Command::STOP; fleet.robots()];
    for _ in 0..50 {
        fleet.dispatch();
        fleet.step(&stop);
    }
    let bytes = fleet.snapshot();
    eprintln!("snapshot: {} bytes", bytes.len());
    let mut group = c.benchmark_group("snapshot");
    group.sample_size(20);
    group.bench_function("clone/warehouse-large", |b| {
        b.iter(|| black_box(fleet.clone()));
    });
    group.bench_function("encode/warehouse-large", |b| {
        b.iter(|| black_box(fleet.snapshot()));
    });
    group.bench_function("restore/warehouse-large", |b| {
        b.iter(|| black_box(Fleet::restore(&s, &bytes).expect("restores")));
    });
    group.finish();
}

criterion_group!(benches, snapshot);
criterion_main!(benches);
