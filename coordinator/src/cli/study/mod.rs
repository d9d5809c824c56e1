//! `gapfleet study` (old name `experiment`): the studies, run in-process on all cores with a
//! progress bar.

mod anticipatory;
mod asfm_estimates;
mod hallway;
mod intent_sharing;
mod laned;
mod open_space;
mod playback;
mod traffic;

use anticipatory::AnticipatoryArgs;
use asfm_estimates::AsfmEstimatesArgs;
use hallway::HallwayArgs;
use intent_sharing::IntentSharingArgs;
use laned::LanedArgs;
use open_space::OpenSpaceArgs;
use playback::PlaybackArgs;
use traffic::TrafficArgs;

use anyhow::Result;
use clap::Subcommand;
use std::path::{Path, PathBuf};
use studies::{Finished, Runner};

/// The studies.
#[derive(Debug, Subcommand)]
pub enum Study {
    /// The PGP paper's open-space study: algorithms × densities × seeds.
    OpenSpace(OpenSpaceArgs),
    /// The same warehouse seeds with robots sharing intents and without: robot–robot near
    /// misses and collisions, in-process.
    IntentSharing(IntentSharingArgs),
    /// The foIGP paper's protocol on a recorded crowd (OpenTraj obsmat.txt format: ETH, UCY,
    /// …), played back: each planner in turn takes a pedestrian's place among the others as
    /// recorded. (Its names before: `replay`, `eth`.)
    #[command(alias = "replay", alias = "eth")]
    Playback(PlaybackArgs),
    /// The peek-and-pass paper's hallway study (Fig. 6): planners × hallway lengths × human
    /// speeds × seeds, a 3 m/s robot driving end to end through two-way foot traffic.
    Hallway(HallwayArgs),
    /// The peek-and-pass paper's laned study (Fig. 4): people in lanes walking one way at
    /// varied speeds, the robot's average speed against 1/(c1·c3).
    Laned(LanedArgs),
    /// The anticipatory Social Force paper's experiment (Sec. IV): a robot and one Social
    /// Force obstacle swapping places on a 3 × 3 m floor; Â_o estimated or fixed at 0 or 20.
    Anticipatory(AnticipatoryArgs),
    /// asfm's estimate Â_o per tracked person on a recorded crowd (people who never react to
    /// the robot) and in the simulator's open space with people who react and who do not.
    AsfmEstimates(AsfmEstimatesArgs),
    /// Fleet traffic: fleets of several sizes in the narrow-aisle warehouse and the fleet
    /// hallway, the traffic policy off and on, the same seeds; deadlocks, stuck robots, tasks
    /// per minute, contacts and people's delay, and throughput against fleet size.
    Traffic(TrafficArgs),
    /// Rebuild summary.json and the figures from a study's runs.csv, without re-running.
    Summarize {
        /// The study's output folder.
        #[arg(long, default_value = "results/open-space")]
        dir: PathBuf,
    },
}

/// What every study takes besides its own settings: threads, and resuming an interrupted run.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// Worker threads (default: all cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// Go on with an interrupted study: take the runs it had finished from the checkpoint in
    /// its output folder (`checkpoint.bin`, saved as each run ends) and make only the rest.
    /// Without it, a study refuses to start over a checkpoint.
    #[arg(long)]
    resume: bool,
}

/// The safety-layer switch common to the studies that can run without it, and changes to its
/// parameters.
#[derive(Debug, Clone, clap::Args)]
pub struct LayerArg {
    /// Run the planners' commands without the safety layer (agent/README.md), as the papers'
    /// studies ran (as does a scenario whose `[robot]` says `safety = false`).
    #[arg(long)]
    no_safety: bool,
    /// Changes to the safety layer's parameters (`agent::safety::SafetyParams`), as
    /// `key=value,…`: e.g. `warning_scale=1` or `person_accel_across=2.4`.
    #[arg(long, default_value = "")]
    safety_layer: String,
}

impl LayerArg {
    /// `params` with `--safety-layer`'s changes.
    fn apply(&self, params: agent::safety::SafetyParams) -> Result<agent::safety::SafetyParams> {
        params
            .with_overrides(&self.safety_layer)
            .map_err(|e| anyhow::anyhow!("--safety-layer: {e}"))
    }
}

/// The first seed of a study that takes `--seeds` consecutive seeds.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct FirstSeed {
    /// The first seed: runs take seeds `first-seed` to `first-seed + seeds - 1` (e.g. 101 for
    /// seeds held out from the tuning seeds 1–100).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..1 << 62))]
    first_seed: u64,
}

impl RunArgs {
    /// Runs `study` into `out` with a progress bar, saving each run as it ends; reports how
    /// it went on stderr. Call [`Runner::finish`] once the outputs are written.
    fn run<S: studies::Study>(&self, out: &Path, study: &S) -> Result<(Runner, Finished<S::Row>)> {
        self.run_with(Runner::new(self.jobs, out, self.resume), study)
    }

    /// [`RunArgs::run`] with `runner`'s checkpoint.
    fn run_with<S: studies::Study>(
        &self,
        runner: Runner,
        study: &S,
    ) -> Result<(Runner, Finished<S::Row>)> {
        if let Some(path) = runner.checkpoint().filter(|p| !self.resume && !p.exists()) {
            eprintln!(
                "saving runs to {} as they end; if interrupted, go on with --resume",
                path.display()
            );
        }
        let done = runner.run(study)?;
        eprintln!(
            "{} runs ({} resumed) on {} threads in {:.1} s",
            done.rows.len(),
            done.resumed,
            done.threads,
            done.elapsed.as_secs_f64()
        );
        Ok((runner, done))
    }
}

/// A finite number ≥ 0.
fn non_negative(s: &str) -> Result<f64, String> {
    let v: f64 = s.trim().parse().map_err(|e| format!("{s:?}: {e}"))?;
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(format!("{v} is not a finite number ≥ 0"))
    }
}

/// A walking speed in [0, 3.5] m/s.
fn walking_speed(s: &str) -> Result<f64, String> {
    let v: f64 = s.trim().parse().map_err(|e| format!("{s:?}: {e}"))?;
    if v.is_finite() && (0.0..=3.5).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{v} is not in [0, 3.5] m/s"))
    }
}

impl Study {
    /// Runs the study and writes its outputs.
    pub fn run(self) -> Result<()> {
        match self {
            Study::OpenSpace(args) => open_space::run(args),
            Study::IntentSharing(args) => intent_sharing::run(args),
            Study::Playback(args) => playback::run(args),
            Study::Hallway(args) => hallway::run(args),
            Study::Laned(args) => laned::run(args),
            Study::Anticipatory(args) => anticipatory::run(args),
            Study::AsfmEstimates(args) => asfm_estimates::run(args),
            Study::Traffic(args) => traffic::run(args),
            Study::Summarize { dir } => open_space::summarize(&dir),
        }
    }
}
