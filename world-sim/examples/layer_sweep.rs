//! The safety layer's parameters against goals and contacts: the open-space study's cells
//! (`world_sim::episode::run_episode`, as `study open-space` runs them) once per set of
//! layer parameters, each a change to the scenario's `[robot.safety_layer]`.
//!
//!     cargo run --release -p world-sim --example layer_sweep [seeds] [densities] [planners]
//!         ["none;scenario;yield_time=2,yield_clearance=0.2;person_accel=2"]
//!
//! Defaults: seeds 1–20 (tuning seeds of the open-space study), densities 0.3–1.0, pgp+orca,
//! no layer against the scenario's own. Each set changes the scenario's as
//! `agent::safety::SafetyParams::with_overrides` reads it (`key=value,…`).

use agent::planner::PlannerSpec;
use agent::safety::SafetyParams;
use world_sim::episode::run_episode;
use world_sim::metrics::RobotMetrics;
use world_sim::scenario::Scenario;

/// One set of layer parameters: its label, and the parameters (`None`: no layer).
type Variant = (String, Option<SafetyParams>);

fn variants(text: &str, base: SafetyParams) -> Result<Vec<Variant>, String> {
    text.split(';')
        .map(|spec| match spec {
            "none" => Ok((spec.to_string(), None)),
            "scenario" => Ok((spec.to_string(), Some(base))),
            _ => Ok((spec.to_string(), Some(base.with_overrides(spec)?))),
        })
        .collect()
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let seeds: u64 = args.first().and_then(|a| a.parse().ok()).unwrap_or(20);
    let densities: Vec<f64> = args
        .get(1)
        .map(|a| a.split(',').filter_map(|d| d.parse().ok()).collect())
        .unwrap_or_else(|| vec![0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0]);
    let planners: Vec<PlannerSpec> = args
        .get(2)
        .map_or("pgp+orca", String::as_str)
        .split(',')
        .map(|name| name.parse().map_err(|e| format!("{name}: {e:?}")))
        .collect::<Result<_, String>>()?;
    let base = Scenario::builtin("open-space").map_err(|e| e.to_string())?;
    let variants = variants(
        args.get(3).map_or("none;scenario", String::as_str),
        base.robot.safety_layer,
    )?;
    println!("open space, densities {densities:?}, seeds 1–{seeds}\n");
    println!(
        "| planner | layer | runs | reached | time to goal (s) | robot-caused | total contacts | people's delay (s per run) |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let cells: Vec<(f64, u64)> = densities
        .iter()
        .flat_map(|&d| (1..=seeds).map(move |s| (d, s)))
        .collect();
    for &planner in &planners {
        for (label, params) in &variants {
            let run = |&(density, seed): &(f64, u64)| -> RobotMetrics {
                let mut s = base.clone();
                if let Some(open) = s.open_space.as_mut() {
                    open.density = density;
                }
                s.seed = seed;
                s.robot.safety = params.is_some();
                s.robot.safety_layer = params.unwrap_or_default();
                run_episode(&s, planner)[0]
            };
            // Two threads, each half of the cells; the sums do not depend on the split.
            let (left, right) = cells.split_at(cells.len() / 2);
            let runs: Vec<RobotMetrics> = std::thread::scope(|scope| {
                let other = scope.spawn(|| right.iter().map(run).collect::<Vec<_>>());
                let mut mine: Vec<RobotMetrics> = left.iter().map(run).collect();
                mine.extend(other.join().expect("no panic"));
                mine
            });
            let n = runs.len() as f64;
            let reached: Vec<&RobotMetrics> = runs.iter().filter(|m| m.success).collect();
            let time =
                reached.iter().map(|m| m.time_to_goal_s).sum::<f64>() / reached.len().max(1) as f64;
            println!(
                "| {planner} | {label} | {} | {:.1}% | {time:.1} | {} | {} | {:.2} |",
                runs.len(),
                100.0 * reached.len() as f64 / n,
                runs.iter().map(|m| m.robot_caused_contacts).sum::<u64>(),
                runs.iter().map(RobotMetrics::total_contacts).sum::<u64>(),
                runs.iter().map(|m| m.human_delay_s).sum::<f64>() / n,
            );
        }
    }
    Ok(())
}
