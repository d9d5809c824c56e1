//! foIGP replans on recorded scenes: the robot in an ETH pedestrian's place (partial runs, 3.2 s
//! in, so every person has a history), planners warmed on the 8 frames before.
//! Targets: foIGP with one GP per person (`foigp-1`, issue 6) and with mixtures over the
//! sequence's destinations (`foigp`, issue 25) ≤ 5 ms median on one core. Both are timed in
//! the same run, so that their ratio is stable on a drifting machine.
//!
//!     cargo bench -p world-sim --bench foigp

use agent::igp::IgpVariant;
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;

#[path = "../examples/foigp_scenes/mod.rs"]
mod foigp_scenes;
use foigp_scenes::{Scene, scenes};

fn replan(c: &mut Criterion) {
    let mut group = c.benchmark_group("foigp_replan_eth");
    for (name, variant) in [
        ("foigp", IgpVariant::Mixture),
        ("foigp-1", IgpVariant::Full),
        ("igp-diag", IgpVariant::Diagonal),
        ("igp-lin", IgpVariant::Linear),
        ("mc-1e5", IgpVariant::MonteCarlo),
    ] {
        if variant == IgpVariant::MonteCarlo {
            group.sample_size(10);
        }
        // Built on first use, so a filtered-out variant costs nothing.
        let mut cache = None;
        let mut next = 0;
        group.bench_function(BenchmarkId::from_parameter(name), |b| {
            let scenes: &Vec<Scene> = cache.get_or_insert_with(|| scenes(variant, 24));
            b.iter(|| {
                let s = &scenes[next % scenes.len()];
                next += 1;
                let mut planner = s.planner.clone();
                black_box(planner.plan(&s.ego, &s.neighbours, s.goal, 0.4))
            })
        });
    }
    group.finish();
}

criterion_group!(benches, replan);
criterion_main!(benches);
