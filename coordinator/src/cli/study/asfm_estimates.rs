//! `gapfleet study asfm-estimates`: asfm's estimate Â_o per tracked person.

use super::non_negative;
use crate::cli::density;
use agent::asfm::{AsfmParams, AsfmVariant};
use agent::planner::{LocalKind, PlannerSpec};
use anyhow::{Context, Result};
use std::path::PathBuf;
use world_sim::dataset::Recording;
use world_sim::playback::{PlaybackOptions, map_of, median_speed};
use world_sim::scenario::Scenario;

/// `study asfm-estimates`'s arguments.
#[derive(Debug, clap::Args)]
pub struct AsfmEstimatesArgs {
    /// Recorded sequences (OpenTraj obsmat.txt folders), comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "world-sim/datasets/ETH/seq_eth,world-sim/datasets/UCY/zara01"
    )]
    datasets: Vec<PathBuf>,
    /// Only the first N partial runs of each recording.
    #[arg(long, default_value_t = 60)]
    limit: usize,
    /// Open-space seeds per crowd (reacting to robots, and not).
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u64).range(1..))]
    seeds: u64,
    #[command(flatten)]
    first: super::FirstSeed,
    /// Open-space density (people per m²).
    #[arg(long, default_value_t = 0.1, value_parser = density)]
    density: f64,
    /// Density of the mixed crowd, where half the people react to robots and half do not
    /// (people per m²).
    #[arg(long, default_value_t = 0.3, value_parser = density)]
    mixed_density: f64,
    #[command(flatten)]
    run: super::RunArgs,
    /// The variant: asfm (the paper's), asfm-q or asfm-crowd.
    #[arg(long, default_value = "asfm", value_parser = asfm_variant)]
    planner: AsfmVariant,
    /// Added to the Kalman filter's P after each update (m²), instead of the variant's.
    #[arg(long, value_parser = non_negative)]
    process_noise: Option<f64>,
    /// Output folder.
    #[arg(long, default_value = "results/anticipatory/estimates")]
    out: PathBuf,
}

/// An anticipatory Social Force variant by its planner name.
fn asfm_variant(name: &str) -> Result<AsfmVariant, String> {
    match name.parse::<PlannerSpec>().map_err(|e| e.to_string())? {
        PlannerSpec {
            pgp: false,
            local: LocalKind::Asfm(variant),
        } => Ok(variant),
        _ => Err(format!("{name} is not asfm, asfm-q or asfm-crowd")),
    }
}

/// Runs the study and writes its outputs.
pub(super) fn run(args: AsfmEstimatesArgs) -> Result<()> {
    use studies::estimates::{
        EstimatesStudy, RecordedCrowd, SimCrowd, mixed_auc, mixed_closest_auc, write_outputs,
    };
    let recorded = args
        .datasets
        .iter()
        .map(|d| {
            let recording = Recording::load(d)?;
            let map = map_of(&recording)
                .with_context(|| format!("{}: map.xml obstacles", d.display()))?;
            let mut options = PlaybackOptions::default();
            options.robot.max_speed = (median_speed(&recording) * 100.0).round() / 100.0;
            Ok(RecordedCrowd {
                recording,
                map,
                options,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let variant = args.planner.params();
    let study = EstimatesStudy {
        recorded,
        limit: Some(args.limit),
        base: Scenario::builtin("open-space")?,
        crowds: vec![
            (SimCrowd::Reacting, args.density),
            (SimCrowd::Ignoring, args.density),
            (SimCrowd::Mixed(0.5), args.mixed_density),
        ],
        seeds: args.first.first_seed..=args.first.first_seed + args.seeds - 1,
        params: AsfmParams {
            process_noise: args.process_noise.unwrap_or(variant.process_noise),
            ..variant
        },
    };
    let (runner, done) = args.run.run(&args.out, &study)?;
    let rows: Vec<_> = done.rows.into_iter().flatten().collect();
    let summary = write_outputs(&args.out, &rows)?;
    runner.finish()?;
    eprintln!(
        "{} people; wrote {}/estimates.csv, summary.json, estimates.png",
        rows.len(),
        args.out.display(),
    );
    if let (Some(auc), Some(closest)) = (mixed_auc(&rows), mixed_closest_auc(&rows)) {
        println!(
            "mixed crowd, reacting against ignoring: AUC of Â_o after {} s near the robot {auc:.3}; \
             of the closest approach {closest:.3}",
            studies::estimates::NEAR_S
        );
    }
    println!("| source | people | Â_o: min / q1 / median / q3 / max | mean | \\|Â_o\\| < 2 |");
    println!("|---|---|---|---|---|");
    for s in &summary {
        let q = s.quartiles;
        println!(
            "| {} | {} | {:.1} / {:.1} / {:.1} / {:.1} / {:.1} | {:.2} | {:.0}% |",
            s.source,
            s.people,
            q[0],
            q[1],
            q[2],
            q[3],
            q[4],
            s.mean,
            100.0 * s.near_zero
        );
    }
    Ok(())
}
