//! `gapfleet study hallway`: the peek-and-pass paper's hallway study (Fig. 6).

use super::walking_speed;
use crate::cli::positive;
use agent::planner::PlannerSpec;
use anyhow::{Context, Result};
use std::path::PathBuf;
use studies::hallway::{HallwayStudy, hallway_scenario};

/// `study hallway`'s arguments.
#[derive(Debug, clap::Args)]
pub struct HallwayArgs {
    /// Planners, comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "pnp,pnp-nopeek,pgp+orca,pgp+dwa,orca,sf"
    )]
    planners: Vec<PlannerSpec>,
    /// Hallway lengths (m), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "25,50,100", value_parser = positive)]
    lengths: Vec<f64>,
    /// Hallway width (m). The paper gives none; at the built-in hallway's 3 m, people
    /// standing still (speed 0) block the way in most trials.
    #[arg(long, default_value_t = 4.0, value_parser = positive)]
    width: f64,
    /// People's walking speeds (m/s), comma-separated, each in [0, 3.5]; one per trial.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "0,0.25,0.5,0.75,1,1.25,1.5,1.75,2,2.25,2.5,2.75,3,3.25,3.5",
        value_parser = walking_speed
    )]
    speeds: Vec<f64>,
    /// Seeds per (planner, length, speed), the same for every planner.
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u64).range(1..))]
    seeds: u64,
    #[command(flatten)]
    first: super::FirstSeed,
    /// The robot's top speed (m/s; the paper's: 3).
    #[arg(long, default_value_t = 3.0, value_parser = positive)]
    robot_speed: f64,
    #[command(flatten)]
    run: super::RunArgs,
    /// Output folder.
    #[arg(long, default_value = "results/hallway")]
    out: PathBuf,
    #[command(flatten)]
    layer: super::LayerArg,
}

/// Runs the study and writes its outputs.
pub(super) fn run(args: HallwayArgs) -> Result<()> {
    let mut scenario = hallway_scenario(args.robot_speed, !args.layer.no_safety)?;
    scenario.robot.safety_layer = args.layer.apply(scenario.robot.safety_layer)?;
    let study = HallwayStudy {
        scenario,
        planners: args.planners,
        lengths: args.lengths,
        width_m: args.width,
        speeds: args.speeds,
        first_seed: args.first.first_seed,
        seeds: args.seeds,
    };
    if args.first.first_seed.checked_add(args.seeds).is_none() {
        anyhow::bail!("--first-seed plus --seeds overflows");
    }
    // Every run's scenario must be valid before hours of work start.
    for &l in &study.lengths {
        for &v in &study.speeds {
            study
                .scenario_for(l, v, 1)
                .validate("study hallway")
                .with_context(|| format!("hallway {l} m, people at {v} m/s"))?;
        }
    }
    let (runner, done) = args.run.run(&args.out, &study)?;
    let rows = done.rows;
    let summary = studies::hallway::write_outputs(&args.out, &study, &rows)?;
    runner.finish()?;
    eprintln!(
        "wrote {}/runs.csv, summary.json and figures",
        args.out.display(),
    );
    println!(
        "| planner | length (m) | runs | reached | median time to goal (s) | mean time, reached (s) | path changes | personal-space entries | robot-caused | person-caused |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let time = |t: Option<f64>| t.map_or("–".to_string(), |t| format!("{t:.1}"));
    for l in &summary.lengths {
        println!(
            "| {} | {} | {} | {:.0}% | {} | {} | {:.2} | {:.2} | {} | {} |",
            l.planner,
            l.length_m,
            l.runs,
            100.0 * l.reached,
            time(l.median_time_to_goal_s),
            time(l.mean_time_to_goal_s),
            l.path_changes,
            l.personal_space_entries,
            l.robot_caused_contacts,
            l.person_caused_contacts,
        );
    }
    Ok(())
}
