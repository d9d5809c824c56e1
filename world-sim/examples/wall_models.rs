//! The crowd under PySocialForce's wall points and under the tabulated wall field
//! (`humans.walls = "field"`), side by side: the same scenario and seed stepped with each, and
//! what people do in each (speed, distance kept from shelves and walls, bodies overlapping
//! them, waypoints reached). Trajectories part within seconds (crowds are chaotic), so the
//! comparison is of these statistics, not of positions.
//!
//!     cargo run --release -p world-sim --example wall_models -- [SCENARIO] [STEPS]
//!
//! SCENARIO is a built-in name (default `warehouse`), STEPS the number of 0.1 s steps (default
//! 3000, 5 simulated minutes).

use agent::model::Command;
use std::time::Instant;
use world_sim::scenario::{Scenario, WallModel};
use world_sim::world::World;

/// What the crowd did over a run.
#[derive(Debug, Default)]
struct CrowdStats {
    person_steps: usize,
    speed_sum: f64,
    clearance_sum: f64,
    overlapping: usize,
    within_half_metre: usize,
    regoals: usize,
    step_micros: Vec<f64>,
}

fn run(scenario: &Scenario, steps: usize) -> (CrowdStats, f64) {
    let started = Instant::now();
    let mut world = World::from_scenario(scenario);
    let built = started.elapsed().as_secs_f64();
    let park = vec![Command::STOP; world.robots.len()];
    let radius = world.humans.radius;
    let mut stats = CrowdStats::default();
    for _ in 0..steps {
        let goals = world.humans.crowd.goals.clone();
        let started = Instant::now();
        world.step(&park);
        stats
            .step_micros
            .push(started.elapsed().as_secs_f64() * 1e6);
        let crowd = &world.humans.crowd;
        stats.regoals += goals
            .iter()
            .zip(&crowd.goals)
            .filter(|(a, b)| a != b)
            .count();
        for (p, v) in crowd.positions.iter().zip(&crowd.velocities) {
            let clearance = world.map.distance(p);
            stats.person_steps += 1;
            stats.speed_sum += v.norm();
            stats.clearance_sum += clearance;
            stats.overlapping += usize::from(clearance < radius);
            stats.within_half_metre += usize::from(clearance < radius + 0.5);
        }
    }
    (stats, built)
}

/// "mean ± sd" over seeds.
fn spread(values: &[f64], digits: usize) -> String {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let sd = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0)).sqrt();
    format!("{mean:.digits$} ± {sd:.digits$}")
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map_or("warehouse", String::as_str);
    let number = |i: usize, default: u64, what: &str| match args.get(i) {
        Some(n) => n.parse::<u64>().map_err(|e| format!("{what} {n:?}: {e}")),
        None => Ok(default),
    };
    let steps = number(1, 3000, "steps")? as usize;
    let seeds = number(2, 6, "seeds")?;
    if steps == 0 || seeds == 0 {
        return Err("steps and seeds must be at least 1".into());
    }
    let mut scenario = Scenario::builtin(name).map_err(|e| e.to_string())?;
    println!(
        "{name}, {steps} steps of {} s, seeds 1..={seeds}, robots parked; mean ± sd over seeds",
        scenario.dt_s
    );
    println!(
        "| walls | mean speed (m/s) | mean clearance (m) | bodies overlapping a wall (% of person-steps) | within 0.5 m of touching (%) | waypoints reached | step median (µs) | set-up (s) |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|");
    for walls in [WallModel::Points, WallModel::Field] {
        scenario.humans.walls = walls;
        let mut columns: [Vec<f64>; 7] = Default::default();
        for seed in 1..=seeds {
            scenario.seed = seed;
            let (mut s, built) = run(&scenario, steps);
            s.step_micros.sort_by(f64::total_cmp);
            let n = s.person_steps as f64;
            let row = [
                s.speed_sum / n,
                s.clearance_sum / n,
                100.0 * s.overlapping as f64 / n,
                100.0 * s.within_half_metre as f64 / n,
                s.regoals as f64,
                s.step_micros[steps / 2],
                built,
            ];
            for (column, value) in columns.iter_mut().zip(row) {
                column.push(value);
            }
        }
        let digits = [4, 4, 4, 3, 0, 0, 2];
        let cells: Vec<String> = columns
            .iter()
            .zip(digits)
            .map(|(c, d)| spread(c, d))
            .collect();
        println!("| {walls:?} | {} |", cells.join(" | "));
    }
    Ok(())
}
