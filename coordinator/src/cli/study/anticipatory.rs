//! `gapfleet study anticipatory`: the anticipatory Social Force paper's experiment.

use super::non_negative;
use crate::cli::positive;
use agent::asfm::AsfmParams;
use anyhow::Result;
use coordinator::study::anticipatory::AnticipatoryStudy;
use coordinator::study::with_progress;
use std::path::PathBuf;
use std::time::Instant;

/// `study anticipatory`'s arguments.
#[derive(Debug, clap::Args)]
pub struct AnticipatoryArgs {
    /// Runs per (A_o, method): seeds 1..=RUNS of the observation noise (the paper's: 100).
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u64).range(1..))]
    runs: u64,
    /// The obstacle's A_o values, comma-separated (the paper's: 0 and 20).
    #[arg(long, value_delimiter = ',', default_value = "20,0", value_parser = non_negative)]
    a_o: Vec<f64>,
    /// Σ of Eq. 13 per axis (m²; Table II: 0.1).
    #[arg(long, default_value_t = 0.1, value_parser = positive)]
    likelihood_variance: f64,
    /// Worker threads (default: all cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// Output folder.
    #[arg(long, default_value = "results/anticipatory")]
    out: PathBuf,
}

/// Runs the study and writes its outputs.
pub(super) fn run(args: AnticipatoryArgs) -> Result<()> {
    let study = AnticipatoryStudy {
        params: AsfmParams {
            likelihood_variance: args.likelihood_variance,
            ..AsfmParams::default()
        },
        a_o: args.a_o,
        runs: args.runs,
    };
    let started = Instant::now();
    let (rows, threads) = with_progress(args.jobs, study.runs().len() as u64, |progress| {
        study.execute(progress)
    })?;
    let cells = coordinator::study::anticipatory::write_outputs(&args.out, &study, &rows)?;
    eprintln!(
        "{} runs on {threads} threads in {:.1} s; wrote {}/runs.csv, summary.json, estimate.csv and the figures",
        rows.len(),
        started.elapsed().as_secs_f64(),
        args.out.display(),
    );
    println!(
        "| A_o | method | runs | reached | min distance: min / q1 / median / q3 / max (m) | below d_min | movement time: median (q1–q3) (s) | final Â_o: median (q1–q3) |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for c in &cells {
        let d = c.min_distance;
        let t = c.movement_time;
        let e = c.final_estimate;
        println!(
            "| {} | {} | {} | {:.0}% | {:.2} / {:.2} / {:.2} / {:.2} / {:.2} | {:.0}% | {:.1} ({:.1}–{:.1}) | {:.1} ({:.1}–{:.1}) |",
            c.a_o,
            c.method,
            c.runs,
            100.0 * c.reached,
            d[0],
            d[1],
            d[2],
            d[3],
            d[4],
            100.0 * c.below_d_min,
            t[2],
            t[1],
            t[3],
            e[2],
            e[1],
            e[3],
        );
    }
    Ok(())
}
