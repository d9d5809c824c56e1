//! `gapfleet study open-space` (and `summarize`): the PGP paper's open-space study.

use crate::cli::{ScenarioRef, density};
use agent::planner::PlannerSpec;
use anyhow::{Context, Result};
use std::path::PathBuf;
use studies::open_space::{StudyPlan, write_outputs, write_summary};
use studies::runs::parse_runs_csv;
use world_sim::scenario::Scenario;

/// `study open-space`'s arguments.
#[derive(Debug, clap::Args)]
pub struct OpenSpaceArgs {
    /// Planners, comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "dwa,orca,sf,pgp+dwa,pgp+orca,pgp+sf"
    )]
    algorithms: Vec<PlannerSpec>,
    /// People per m², comma-separated, each in (0, 3].
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "0.01,0.1,0.2,0.3,0.4,0.5,0.6,0.7,0.8,0.9,1.0",
        value_parser = density
    )]
    densities: Vec<f64>,
    /// Seeds per (algorithm, density), the same for every algorithm.
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u64).range(1..))]
    seeds: u64,
    #[command(flatten)]
    first: super::FirstSeed,
    #[command(flatten)]
    run: super::RunArgs,
    /// Output folder for runs.csv and summary.json.
    #[arg(long, default_value = "results/open-space")]
    out: PathBuf,
    /// A built-in scenario name or a scenario file to start from.
    #[arg(long, default_value = "open-space")]
    scenario: ScenarioRef,
    #[command(flatten)]
    layer: super::LayerArg,
}

/// Runs the study and writes its outputs.
pub(super) fn run(args: OpenSpaceArgs) -> Result<()> {
    let mut scenario = *args.scenario.scenario;
    if args.layer.no_safety {
        scenario.robot.safety = false;
    }
    scenario.robot.safety_layer = args.layer.apply(scenario.robot.safety_layer)?;
    let plan = StudyPlan {
        scenario,
        algorithms: args.algorithms,
        densities: args.densities,
        first_seed: args.first.first_seed,
        seeds: args.seeds,
    };
    let (runner, done) = args.run.run(&args.out, &plan)?;
    let summary = write_outputs(&args.out, &plan, &done.rows)?;
    runner.finish()?;
    eprintln!("wrote {}/runs.csv and summary.json", args.out.display());
    for c in summary.comparisons.iter().filter(|c| c.metric == "svr") {
        eprintln!(
            "  svr {:>8} {:.4} vs {:>4} {:.4} (Wilcoxon p = {})",
            c.with_pgp,
            c.mean_with.unwrap_or(f64::NAN),
            c.baseline,
            c.mean_without.unwrap_or(f64::NAN),
            c.wilcoxon_p.map_or("n/a".into(), |p| format!("{p:.3e}"))
        );
    }
    Ok(())
}

/// Rebuilds summary.json and the figures from `dir`'s runs.csv.
pub(super) fn summarize(dir: &std::path::Path) -> Result<()> {
    let path = dir.join("runs.csv");
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let parsed = parse_runs_csv(&text)?;
    let rows = parsed.rows;
    let first_seed = rows.iter().map(|r| r.seed).min().unwrap_or(1);
    let last_seed = rows.iter().map(|r| r.seed).max().unwrap_or(0);
    let plan = StudyPlan {
        scenario: Scenario::builtin("open-space")?,
        algorithms: parsed.algorithms,
        densities: parsed.densities,
        first_seed,
        seeds: (last_seed + 1).saturating_sub(first_seed),
    };
    write_summary(dir, &plan, &rows)?;
    eprintln!(
        "{} runs: wrote {1}/summary.json, fig4_success.png, fig5_social.png",
        rows.len(),
        dir.display()
    );
    Ok(())
}
