//! foIGP replans on recorded scenes: the robot in an ETH pedestrian's place (partial runs, 3.2 s
//! in, so every person has a history), planners warmed on the 8 frames before.
//! Targets: foIGP with one GP per person (`foigp-1`, issue 6) and with mixtures over the
//! sequence's destinations (`foigp`, issue 25) ≤ 5 ms median on one core. Both are timed in
//! the same run, so that their ratio is stable on a drifting machine.
//!
//!     cargo bench -p world-sim --bench foigp

use agent::igp::{IgpParams, IgpPlanner, IgpVariant};
use agent::model::{EgoState, Neighbour};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;
use world_sim::dataset::Recording;
use world_sim::replay::{ReplayOptions, RunKind, median_speed, perceived, runs};

/// A planner warmed up on a scene's history, and the scene.
struct Scene {
    planner: IgpPlanner,
    ego: EgoState,
    neighbours: Vec<Neighbour>,
    goal: agent::math::Vec2,
}

fn scenes(variant: IgpVariant, count: usize) -> Vec<Scene> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("datasets/ETH/seq_eth");
    let rec = Recording::load(&dir).expect("seq_eth loads");
    let speed = median_speed(&rec);
    let params = IgpParams {
        preferred_speed: speed,
        max_speed: speed,
        ..IgpParams::default()
    };
    let options = ReplayOptions::default();
    let all = runs(&rec, RunKind::Partial, &options);
    let step = (all.len() / count).max(1);
    all.iter()
        .step_by(step)
        .take(count)
        .map(|run| {
            let track = rec.track(run.pedestrian).expect("run's track");
            let at = |t: f64| {
                let (position, velocity) = track.state_at(t).expect("inside the run");
                let seen: Vec<Neighbour> =
                    perceived(&rec, t, run.pedestrian, position, &options).collect();
                let ego = EgoState {
                    position,
                    heading: velocity.y.atan2(velocity.x),
                    velocity,
                    yaw_rate: 0.0,
                    radius: 0.3,
                };
                (ego, seen)
            };
            let now = (run.t_start + 3.2).min(run.t_end);
            let mut planner = IgpPlanner::new(variant, params);
            planner.set_destinations(&rec.destinations);
            for k in (1..=8).rev() {
                let t = now - k as f64 * 0.4;
                if t >= track.start() {
                    let (ego, seen) = at(t);
                    planner.plan(&ego, &seen, run.goal, 0.4);
                }
            }
            let (ego, neighbours) = at(now);
            Scene {
                planner,
                ego,
                neighbours,
                goal: run.goal,
            }
        })
        .collect()
}

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
