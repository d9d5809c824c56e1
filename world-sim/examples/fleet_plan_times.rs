//! How long each robot's plan takes in the fleet that `gapfleet bench fleet` runs
//! (`warehouse-large`, 100 robots, no people, intents shared), planning in-process as
//! `run_fleet` does. The fleet is deterministic, so it is run `repeats` times and each plan's
//! fastest time is kept: what is left is the plan's own cost, without the moments a shared
//! machine runs slow.
//!
//!     cargo run --release -p world-sim --example fleet_plan_times -- [ticks] [repeats] [planner]
//!
//! Defaults: 200 ticks (20 s), 3 repeats, `pgp+orca`.

use agent::model::Command;
use agent::planner::{PlannerSpec, PlannerStack};
use std::time::Instant;
use world_sim::fleet::{Fleet, plan_all};
use world_sim::scenario::Scenario;

/// Robots, as in `bench fleet`'s default.
const ROBOTS: usize = 100;

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let number = |i: usize, default: usize| -> Result<usize, String> {
        args.get(i).map_or(Ok(default), |s| {
            s.parse().map_err(|e| format!("argument {s:?}: {e}"))
        })
    };
    let ticks = number(0, 200)?;
    let repeats = number(1, 3)?.max(1);
    let planner: PlannerSpec = args
        .get(2)
        .map_or("pgp+orca", String::as_str)
        .parse()
        .map_err(|e| format!("planner: {e}"))?;
    let mut scenario = Scenario::builtin("warehouse-large").map_err(|e| e.to_string())?;
    let layout = scenario
        .warehouse
        .as_mut()
        .ok_or("warehouse-large has no warehouse table")?;
    layout.robots = ROBOTS;
    layout.humans = 0;

    // Fastest time of every (tick, robot) plan over the repeats, µs.
    let mut fastest: Vec<Option<u32>> = Vec::new();
    for _ in 0..repeats {
        let times = plan_times(&scenario, planner, ticks)?;
        fastest.resize(times.len(), None);
        for (best, t) in fastest.iter_mut().zip(times) {
            *best = match (*best, t) {
                (Some(b), Some(t)) => Some(b.min(t)),
                (b, t) => b.or(t),
            };
        }
    }
    let mut all: Vec<u32> = fastest.iter().flatten().copied().collect();
    if all.is_empty() {
        return Err("no robot had a task to plan for".into());
    }
    all.sort_unstable();
    let q = |p: f64| all[((p * all.len() as f64) as usize).min(all.len() - 1)];
    println!(
        "{} plans ({planner}, fastest of {repeats} runs): p50 {} µs, p90 {}, p99 {}, p99.9 {}, max {}",
        all.len(),
        q(0.5),
        q(0.9),
        q(0.99),
        q(0.999),
        all[all.len() - 1]
    );
    // Planning per tick: a tick whose plans all cost more would make the fleet's CPU load come
    // in bursts.
    let mut per_tick: Vec<u64> = fastest
        .chunks(ROBOTS)
        .map(|tick| tick.iter().flatten().map(|&t| u64::from(t)).sum())
        .collect();
    let busiest = per_tick.iter().copied().max().unwrap_or(0);
    per_tick.sort_unstable();
    println!(
        "planning per tick (all robots): median {} µs, busiest {} µs",
        per_tick[per_tick.len() / 2],
        busiest
    );
    Ok(())
}

/// Each plan's time (µs) in tick-major order, None where the robot had no task.
fn plan_times(
    scenario: &Scenario,
    planner: PlannerSpec,
    ticks: usize,
) -> Result<Vec<Option<u32>>, String> {
    let mut fleet = Fleet::new(scenario).map_err(|e| e.to_string())?;
    fleet.share_intents = true;
    let mut stacks: Vec<PlannerStack> = (0..fleet.robots())
        .map(|_| PlannerStack::new(planner))
        .collect();
    let mut commands = vec![Command::STOP; fleet.robots()];
    let mut times = Vec::with_capacity(ticks * fleet.robots());
    for _ in 0..ticks {
        fleet.dispatch();
        let mut tick = vec![None; fleet.robots()];
        plan_all(&mut fleet, &mut stacks, &mut commands, |i, stack, input| {
            let started = Instant::now();
            let plan = stack.plan(input);
            tick[i] = Some(started.elapsed().as_micros().min(u32::MAX as u128) as u32);
            plan
        });
        times.extend(tick);
        fleet.step(&commands);
    }
    Ok(times)
}
