//! `gapfleet study laned`: the peek-and-pass paper's laned study (Fig. 4).

use super::walking_speed;
use crate::cli::positive;
use anyhow::{Context, Result};
use std::path::PathBuf;
use studies::laned::{LanedStudy, laned_hallway};

/// `study laned`'s arguments.
#[derive(Debug, clap::Args)]
pub struct LanedArgs {
    /// The exploration-to-exploitation ratios 1/(c1·c3), comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "0.0001,0.001,0.01,0.03,0.1,0.3,1,10",
        value_parser = positive
    )]
    ratios: Vec<f64>,
    /// Seeds per ratio.
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u64).range(1..))]
    seeds: u64,
    /// Hallway length (m).
    #[arg(long, default_value_t = 50.0, value_parser = positive)]
    length: f64,
    /// Lanes.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u64).range(1..=20))]
    lanes: u64,
    /// People's mean walking speed (m/s; each walks at ½–1½ of it).
    #[arg(long, default_value_t = 1.0, value_parser = walking_speed)]
    human_speed: f64,
    /// The robot's top speed (m/s; the paper's: 3).
    #[arg(long, default_value_t = 3.0, value_parser = positive)]
    robot_speed: f64,
    #[command(flatten)]
    run: super::RunArgs,
    /// Output folder.
    #[arg(long, default_value = "results/laned")]
    out: PathBuf,
    /// Run the planner's commands under the safety layer (the paper's study ran without it).
    #[arg(long)]
    safety: bool,
}

/// Runs the study and writes its outputs.
pub(super) fn run(args: LanedArgs) -> Result<()> {
    let scenario = laned_hallway(
        args.length,
        args.lanes as usize,
        args.human_speed,
        args.robot_speed,
        args.safety,
    )
    .context("the laned hallway")?;
    let study = LanedStudy {
        scenario,
        ratios: args.ratios,
        seeds: args.seeds,
    };
    let (runner, done) = args.run.run(&args.out, &study)?;
    let rows = done.rows;
    let cells = studies::laned::write_outputs(&args.out, &study, &rows)?;
    runner.finish()?;
    eprintln!(
        "wrote {}/runs.csv, summary.json, average_speed.png",
        args.out.display(),
    );
    println!(
        "| 1/(c1·c3) | c3 | runs | reached | average speed: min / q1 / median / q3 / max (m/s) | robot-caused |"
    );
    println!("|---|---|---|---|---|---|");
    for c in &cells {
        let q = c.speed_quartiles;
        println!(
            "| {} | {:.4} | {} | {:.0}% | {:.2} / {:.2} / {:.2} / {:.2} / {:.2} | {} |",
            c.ratio,
            study.params(c.ratio).c3,
            c.runs,
            100.0 * c.reached,
            q[0],
            q[1],
            q[2],
            q[3],
            q[4],
            c.robot_caused_contacts
        );
    }
    Ok(())
}
