//! Follows one recorded-crowd run (`gapfleet study playback`'s protocol, the layer on as
//! shipped) replan by replan: where the robot is, how fast it drives, how far its goal is,
//! what the layer did, and the nearest people.
//!
//!     cargo run --release -p world-sim --example replay_probe -- DATASET PEDESTRIAN \
//!         [SEGMENT [PLANNER [--no-safety] [--quiet]]]
//!
//! DATASET is a sequence folder (e.g. world-sim/datasets/ETH/seq_eth); the robot's top speed
//! is the recording's median walking speed, as in the study.

use agent::math::Real;
use agent::planner::{PlannerSpec, PlannerStack};
use agent::safety::Zone;
use std::path::PathBuf;
use world_sim::dataset::Recording;
use world_sim::playback::{self, PlaybackOptions, RunKind, map_of, median_speed};

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [dataset, pedestrian, ..] = args.as_slice() else {
        return Err(
            "usage: replay_probe DATASET PEDESTRIAN [SEGMENT [PLANNER [--no-safety] [--quiet]]]"
                .into(),
        );
    };
    let pedestrian: u64 = pedestrian.parse().map_err(|e| format!("{e}"))?;
    let segment: usize = args
        .get(2)
        .map_or(Ok(0), |s| s.parse())
        .map_err(|e| format!("{e}"))?;
    let spec: PlannerSpec = args
        .get(3)
        .map_or("pgp+orca", String::as_str)
        .parse()
        .map_err(|e| format!("{e}"))?;
    let safety = !args.iter().any(|a| a == "--no-safety");
    let quiet = args.iter().any(|a| a == "--quiet");
    let recording = Recording::load(&PathBuf::from(dataset)).map_err(|e| e.to_string())?;
    let map = map_of(&recording).map_err(|e| e.to_string())?;
    let mut options = PlaybackOptions::default();
    options.robot.max_speed = (median_speed(&recording) * 100.0).round() / 100.0;
    options.robot.safety = safety;
    let run = playback::runs(&recording, RunKind::Partial, &options)
        .into_iter()
        .find(|r| r.pedestrian == pedestrian && r.segment == segment)
        .ok_or("no such run")?;
    println!(
        "run: pedestrian {pedestrian} segment {segment}, t {:.1}–{:.1} s, start ({:.2}, {:.2}) goal ({:.2}, {:.2}), {} map obstacles, top speed {:.2} m/s",
        run.t_start,
        run.t_end,
        run.start.x,
        run.start.y,
        run.goal.x,
        run.goal.y,
        map.obstacles().len(),
        options.robot.max_speed
    );
    let mut stack = PlannerStack::with_max_speed(spec, options.robot.max_speed);
    stack.set_record_fan(false);
    stack.set_destinations(&recording.destinations);
    let mut guard = options.robot.guard(0.0);
    let mut t = run.t_start;
    let mut last = (run.start, true);
    let outcome = playback::play(&recording, &map, &run, &options, &mut |input| {
        let plan = stack_plan(&mut stack, guard.as_mut(), input);
        let ego = input.ego;
        let mut near: Vec<(Real, u64, Real)> = input
            .neighbours
            .iter()
            .map(|n| {
                (
                    (n.position - ego.position).norm() - n.radius - ego.radius,
                    n.id,
                    n.velocity.norm(),
                )
            })
            .collect();
        near.sort_by(|a, b| a.0.total_cmp(&b.0));
        let people: Vec<String> = near
            .iter()
            .take(3)
            .map(|(d, id, v)| format!("#{id} {d:.2} m ({v:.1} m/s)"))
            .collect();
        let wall = map.distance(&ego.position);
        last = (ego.position, map.line_of_sight(ego.position, input.goal));
        if !quiet {
            println!(
                "t {t:6.1}  at ({:6.2}, {:6.2})  v {:.2}  to goal {:5.2}  wall {:5.2}  {:?} -> {:?}  near: {}",
                ego.position.x,
                ego.position.y,
                ego.velocity.norm(),
                (input.goal - ego.position).norm(),
                wall,
                plan.1,
                plan.0,
                people.join(", ")
            );
        }
        t += options.replan_period;
        plan.0
    });
    println!(
        "reached {} in {:.1} s (person: {:.1} s), path {:.2} m; last at ({:.2}, {:.2}), goal in sight {}",
        outcome.reached,
        outcome.duration_s,
        run.t_arrive - run.t_start,
        outcome.path_m,
        last.0.x,
        last.0.y,
        last.1
    );
    Ok(())
}

fn stack_plan(
    stack: &mut PlannerStack,
    guard: Option<&mut agent::guard::Guard>,
    input: &agent::planner::PlanningInput<'_>,
) -> (agent::model::Command, Option<Zone>) {
    match guard {
        Some(g) => {
            let (_, guarded) = g.plan(stack, input);
            (guarded.command, Some(guarded.zone))
        }
        None => (stack.plan(input).command, None),
    }
}
