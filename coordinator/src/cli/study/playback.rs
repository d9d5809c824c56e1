//! `gapfleet study playback`: the foIGP paper's protocol on a recorded crowd.

use crate::cli::positive;
use agent::igp::SeedRule;
use agent::planner::PlannerSpec;
use anyhow::{Context, Result, bail};
use std::path::PathBuf;
use studies::playback::{Half, PlaybackStudy, table_markdown};
use world_sim::dataset::Recording;
use world_sim::playback::{PlaybackOptions, RunKind, map_of, median_speed};

/// `study playback`'s arguments.
#[derive(Debug, clap::Args)]
pub struct PlaybackArgs {
    /// A sequence folder with obsmat.txt (and optionally map.xml), e.g.
    /// world-sim/datasets/ETH/seq_eth or world-sim/datasets/UCY/zara01.
    #[arg(long)]
    dataset: PathBuf,
    /// Planners, comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "foigp,foigp-1,igp-diag,igp-lin,mc,dwa,pgp+orca"
    )]
    planners: Vec<PlannerSpec>,
    /// partial (≈ 10 m stretches, start and goal only) or full (whole tracks).
    #[arg(long, default_value = "partial")]
    runs: RunKind,
    /// Only the first N runs.
    #[arg(long)]
    limit: Option<usize>,
    /// The robot's top speed, for every planner (m/s, at most 5; default: the recording's
    /// median walking speed).
    #[arg(long, value_parser = positive)]
    robot_speed: Option<f64>,
    #[command(flatten)]
    run: super::RunArgs,
    /// Output folder (default: `results/eth/<sequence>-<runs>`).
    #[arg(long)]
    out: Option<PathBuf>,
    #[command(flatten)]
    layer: super::LayerArg,
    /// Where the foIGP planners' Newton seeds lie: per-body (the robot and the people shifted
    /// apart across the robot's path) or common (every body +kσ in x and y). Applies to the
    /// foIGP planners on their own (not behind pgp+).
    #[arg(long, default_value = "per-body", value_parser = seed_rule)]
    igp_seeds: SeedRule,
    /// Only the runs starting in the first or the second half of the recording's time (to
    /// tune on one and hold out the other).
    #[arg(long)]
    half: Option<Half>,
}

fn seed_rule(s: &str) -> Result<SeedRule, String> {
    match s {
        "per-body" => Ok(SeedRule::PerBody),
        "common" => Ok(SeedRule::Common),
        other => Err(format!("{other:?}: expected per-body or common")),
    }
}

/// Runs the study and writes its outputs.
pub(super) fn run(args: PlaybackArgs) -> Result<()> {
    let recording = Recording::load(&args.dataset)?;
    let map = map_of(&recording)
        .with_context(|| format!("{}: map.xml obstacles", args.dataset.display()))?;
    let kind = args.runs;
    let out = args
        .out
        .unwrap_or_else(|| PathBuf::from("results/eth").join(format!("{}-{kind}", recording.name)));
    let speed = args
        .robot_speed
        .unwrap_or_else(|| (median_speed(&recording) * 100.0).round() / 100.0);
    if !(speed.is_finite() && speed > 0.0 && speed <= 5.0) {
        bail!("--robot-speed: {speed} is not in (0, 5] m/s");
    }
    let mut options = PlaybackOptions::default();
    options.robot.max_speed = speed;
    options.robot.safety = !args.layer.no_safety;
    options.robot.safety_layer = args.layer.apply(options.robot.safety_layer)?;
    let study = PlaybackStudy {
        recording,
        map,
        planners: args.planners,
        kind,
        options,
        limit: args.limit,
        igp_seeds: args.igp_seeds,
        half: args.half,
    };
    let r = &study.recording;
    match r.rejected_destinations_fit {
        Some(fit) => eprintln!(
            "{}: destinations.txt set aside: only {:.0} % of steps head towards the destination \
             their track ends nearest to (at least {:.0} % needed); using {} clusters of the \
             tracks' end points instead ({:.0} %)",
            r.name,
            100.0 * fit,
            100.0 * world_sim::dataset::MIN_DESTINATION_FIT,
            r.destinations.len(),
            100.0 * r.destinations_fit
        ),
        None => eprintln!(
            "{}: {} destinations {} ({:.0} % of steps head towards them)",
            r.name,
            r.destinations.len(),
            if r.destinations_from_file {
                "from destinations.txt"
            } else {
                "clustered from the tracks' end points"
            },
            100.0 * r.destinations_fit
        ),
    }
    let runs = study.runs().len();
    if runs == 0 {
        bail!(
            "{}: no {kind} runs in this recording",
            args.dataset.display()
        );
    }
    eprintln!(
        "{}: {} tracks, {runs} {kind} runs × ({} planners + human), robot top speed {speed} m/s",
        study.recording.name,
        study.recording.tracks.len(),
        study.planners.len()
    );
    let (runner, done) = args.run.run(&out, &study)?;
    let rows = done.rows;
    let table = studies::playback::write_outputs(&out, &study, &rows)?;
    runner.finish()?;
    eprintln!("wrote {}/runs.csv, table.json, table.md", out.display());
    print!("{}", table_markdown(&table));
    Ok(())
}
