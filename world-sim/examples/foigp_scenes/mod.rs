//! The foIGP benchmark's recorded scenes, shared by `benches/foigp.rs` and
//! `examples/foigp_replan_times.rs`: the robot in an ETH pedestrian's place (`seq_eth` partial
//! runs, 3.2 s in, so every person has a history), its planner warmed on the 8 frames before.

use agent::igp::{IgpParams, IgpPlanner, IgpVariant};
use agent::math::Vec2;
use agent::model::{EgoState, Neighbour};
use std::path::Path;
use world_sim::dataset::Recording;
use world_sim::playback::{PlaybackOptions, RunKind, median_speed, runs, scene_at};

/// A planner warmed up on a scene's history, and the scene.
pub struct Scene {
    pub planner: IgpPlanner,
    pub ego: EgoState,
    pub neighbours: Vec<Neighbour>,
    pub goal: Vec2,
}

/// `count` scenes spread evenly over `seq_eth`'s partial runs, in the same order for every
/// variant, with a `variant` planner (the sequence's destinations set, its median walking
/// speed as the robot's) warmed on each.
pub fn scenes(variant: IgpVariant, count: usize) -> Vec<Scene> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("datasets/ETH/seq_eth");
    let rec = Recording::load(&dir).expect("seq_eth loads");
    let speed = median_speed(&rec);
    let params = IgpParams {
        preferred_speed: speed,
        max_speed: speed,
        ..IgpParams::default()
    };
    let options = PlaybackOptions::default();
    let all = runs(&rec, RunKind::Partial, &options);
    let step = (all.len() / count).max(1);
    all.iter()
        .step_by(step)
        .take(count)
        .map(|run| {
            let track = rec.track(run.pedestrian).expect("run's track");
            let at = |t: f64| scene_at(&rec, run, t, &options).expect("inside the run");
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
