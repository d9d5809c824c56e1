//! `gapfleet study intent-sharing`: the same warehouse seeds with and without shared intents.

use crate::cli::{Overrides, ScenarioRef, positive};
use agent::planner::PlannerSpec;
use anyhow::Result;
use std::path::PathBuf;
use studies::intent_sharing::{IntentSharingStudy, report};
use studies::{Runner, write_json};

/// `study intent-sharing`'s arguments.
#[derive(Debug, clap::Args)]
pub struct IntentSharingArgs {
    /// Seeds 1..=N.
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u64).range(1..))]
    seeds: u64,
    /// Simulated seconds per run.
    #[arg(long, default_value_t = 300.0, value_parser = positive)]
    seconds: f64,
    /// Robots [default: the scenario's].
    #[arg(long)]
    robots: Option<usize>,
    /// People [default: the scenario's].
    #[arg(long)]
    humans: Option<usize>,
    /// Planner stack of every robot.
    #[arg(long, default_value = "pgp+orca")]
    planner: PlannerSpec,
    /// Built-in warehouse scenario or a scenario file.
    #[arg(long, default_value = "warehouse")]
    scenario: ScenarioRef,
    /// Write the per-run table here as JSON (and save runs as they end beside it, in
    /// `<out>.checkpoint.bin`).
    #[arg(long)]
    out: Option<PathBuf>,
    #[command(flatten)]
    run: super::RunArgs,
    #[command(flatten)]
    layer: super::LayerArg,
}

/// Runs the study and writes its outputs.
pub(super) fn run(args: IntentSharingArgs) -> Result<()> {
    let mut scenario = args.scenario.fleet_site(Overrides {
        robots: args.robots,
        humans: args.humans,
        seed: None,
        no_safety: args.layer.no_safety,
    })?;
    scenario.robot.safety_layer = args.layer.apply(scenario.robot.safety_layer)?;
    let (robots, humans) = scenario.fleet_size().unwrap_or((0, 0));
    let study = IntentSharingStudy {
        scenario,
        planner: args.planner,
        seeds: args.seeds,
        seconds: args.seconds,
    };
    let checkpoint = args.out.as_ref().map(|out| {
        let mut name = out.as_os_str().to_owned();
        name.push(".checkpoint.bin");
        PathBuf::from(name)
    });
    let runner = Runner::new(args.run.jobs, ".", args.run.resume).checkpoint_at(checkpoint);
    let (runner, done) = args.run.run_with(runner, &study)?;
    let runs = done.rows;
    println!(
        "{} seeds x {} s, {robots} robots ({}), {humans} people; means per run:",
        args.seeds, args.seconds, args.planner
    );
    print!("{}", report(&runs));
    if let Some(path) = args.out {
        // Through a JSON value, whose keys are in alphabetical order.
        write_json(&path, &serde_json::to_value(&runs)?)?;
    }
    runner.finish()?;
    Ok(())
}
