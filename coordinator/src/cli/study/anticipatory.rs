//! `gapfleet study anticipatory`: the anticipatory Social Force paper's experiment.

use super::non_negative;
use crate::cli::positive;
use agent::asfm::AsfmParams;
use anyhow::Result;
use std::path::PathBuf;
use studies::anticipatory::AnticipatoryStudy;

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
    #[command(flatten)]
    run: super::RunArgs,
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
    let (runner, done) = args.run.run(&args.out, &study)?;
    let rows = done.rows;
    let cells = studies::anticipatory::write_outputs(&args.out, &study, &rows)?;
    runner.finish()?;
    eprintln!(
        "wrote {}/runs.csv, summary.json, estimate.csv and the figures",
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
