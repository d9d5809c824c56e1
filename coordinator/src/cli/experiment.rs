//! `gapfleet experiment`: the studies, run in-process on all cores with a progress bar.

use super::{Overrides, ScenarioRef, density, positive};
use agent::asfm::AsfmParams;
use agent::igp::SeedRule;
use agent::planner::PlannerSpec;
use anyhow::{Context, Result, bail};
use clap::Subcommand;
use coordinator::study::anticipatory::AnticipatoryStudy;
use coordinator::study::hallway::{HallwayStudy, hallway_scenario};
use coordinator::study::intent_sharing::{IntentSharingStudy, report};
use coordinator::study::laned::{LanedStudy, laned_hallway};
use coordinator::study::open_space::{StudyPlan, write_outputs, write_summary};
use coordinator::study::replay::{Half, ReplayStudy, table_markdown};
use coordinator::study::runs::parse_runs_csv;
use coordinator::study::traffic::{self as traffic_study, TrafficStudy};
use coordinator::study::{with_progress, write_json};
use std::path::PathBuf;
use std::sync::{Mutex, PoisonError};
use std::time::Instant;
use world_sim::dataset::Recording;
use world_sim::replay::{ReplayOptions, RunKind, map_of, median_speed};
use world_sim::scenario::Scenario;

/// The studies.
#[derive(Debug, Subcommand)]
pub enum Experiment {
    /// The PGP paper's open-space study: algorithms × densities × seeds.
    OpenSpace(OpenSpaceArgs),
    /// The same warehouse seeds with robots sharing intents and without: robot–robot near
    /// misses and collisions, in-process.
    IntentSharing(IntentSharingArgs),
    /// The foIGP paper's protocol on a recorded crowd (OpenTraj obsmat.txt format: ETH, UCY,
    /// …): each planner in turn takes a pedestrian's place among the others as recorded.
    #[command(alias = "eth")]
    Replay(ReplayArgs),
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

/// `experiment open-space`'s arguments.
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
    /// Seeds per (algorithm, density): 1..=N, the same for every algorithm.
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u64).range(1..))]
    seeds: u64,
    /// Worker threads (default: all cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// Output folder for runs.csv and summary.json.
    #[arg(long, default_value = "results/open-space")]
    out: PathBuf,
    /// A built-in scenario name or a scenario file to start from.
    #[arg(long, default_value = "open-space")]
    scenario: ScenarioRef,
    /// Run the planners' commands without the safety layer (agent/README.md), as the papers'
    /// studies ran (as does a scenario whose `[robot]` says `safety = false`).
    #[arg(long)]
    no_safety: bool,
}

/// `experiment intent-sharing`'s arguments.
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
    /// Write the per-run table here as JSON.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Run the planners' commands without the safety layer (agent/README.md), as the papers'
    /// studies ran (as does a scenario whose `[robot]` says `safety = false`).
    #[arg(long)]
    no_safety: bool,
}

/// `experiment replay`'s arguments.
#[derive(Debug, clap::Args)]
pub struct ReplayArgs {
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
    /// Worker threads (default: all cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// Output folder (default: results/eth/<sequence>-<runs>).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Run the planners' commands without the safety layer (agent/README.md), as the papers'
    /// studies ran (as does a scenario whose `[robot]` says `safety = false`).
    #[arg(long)]
    no_safety: bool,
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

/// `experiment hallway`'s arguments.
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
    /// Seeds per (planner, length, speed): 1..=N, the same for every planner.
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u64).range(1..))]
    seeds: u64,
    /// The robot's top speed (m/s; the paper's: 3).
    #[arg(long, default_value_t = 3.0, value_parser = positive)]
    robot_speed: f64,
    /// Worker threads (default: all cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// Output folder.
    #[arg(long, default_value = "results/hallway")]
    out: PathBuf,
    /// Run the planners' commands without the safety layer (agent/README.md), as the papers'
    /// studies ran (as does a scenario whose `[robot]` says `safety = false`).
    #[arg(long)]
    no_safety: bool,
}

/// `experiment laned`'s arguments.
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
    /// Worker threads (default: all cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// Output folder.
    #[arg(long, default_value = "results/laned")]
    out: PathBuf,
    /// Run the planner's commands under the safety layer (the paper's study ran without it).
    #[arg(long)]
    safety: bool,
}

/// `experiment anticipatory`'s arguments.
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

/// `experiment traffic`'s arguments.
#[derive(Debug, clap::Args)]
pub struct TrafficArgs {
    /// Seeds per (site, fleet size, policy).
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u64).range(1..))]
    seeds: u64,
    /// The first seed: runs take seeds `first-seed` to `first-seed + seeds - 1` (e.g. 101 for
    /// seeds held out from the default study's 1–100).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..1 << 62))]
    first_seed: u64,
    /// Simulated seconds per run.
    #[arg(long, default_value_t = 300.0, value_parser = positive)]
    seconds: f64,
    /// Fleet sizes in the narrow-aisle warehouse (`warehouse-narrow`), comma-separated; empty
    /// (`''`) for none.
    #[arg(long, default_value = "10,20,40", value_parser = fleet_sizes)]
    narrow_fleets: FleetSizes,
    /// Fleet sizes in the fleet hallway (`hallway-fleet`), comma-separated; empty for none.
    #[arg(long, default_value = "10,20", value_parser = fleet_sizes)]
    hallway_fleets: FleetSizes,
    /// The traffic policy off, on, or both (`off,on`), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "off,on", value_parser = on_off)]
    policy: Vec<bool>,
    /// Take runs from this earlier `runs.csv` instead of running them again, for the policy
    /// settings given here (`off`, `on`): only for settings whose code has not changed.
    #[arg(long, requires = "reuse_policy")]
    reuse: Option<PathBuf>,
    /// The policy settings to take from `--reuse`, comma-separated.
    #[arg(long, value_delimiter = ',', value_parser = on_off, requires = "reuse")]
    reuse_policy: Vec<bool>,
    /// Planner stack of every robot.
    #[arg(long, default_value = "pgp+orca")]
    planner: PlannerSpec,
    /// Worker threads (default: all cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// Output folder.
    #[arg(long, default_value = "results/traffic")]
    out: PathBuf,
}

/// `experiment asfm-estimates`'s arguments.
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
    /// Open-space density (people per m²).
    #[arg(long, default_value_t = 0.1, value_parser = density)]
    density: f64,
    /// Worker threads (default: all cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// Added to the Kalman filter's P after each update (m²; Eq. 9 has none: 0).
    #[arg(long, default_value_t = 0.0, value_parser = non_negative)]
    process_noise: f64,
    /// Output folder.
    #[arg(long, default_value = "results/anticipatory/estimates")]
    out: PathBuf,
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

impl Experiment {
    /// Runs the study and writes its outputs.
    pub fn run(self) -> Result<()> {
        match self {
            Experiment::OpenSpace(args) => open_space(args),
            Experiment::IntentSharing(args) => intent_sharing(args),
            Experiment::Replay(args) => replay(args),
            Experiment::Hallway(args) => hallway(args),
            Experiment::Laned(args) => laned(args),
            Experiment::Anticipatory(args) => anticipatory(args),
            Experiment::AsfmEstimates(args) => asfm_estimates(args),
            Experiment::Traffic(args) => traffic(args),
            Experiment::Summarize { dir } => summarize(&dir),
        }
    }
}

fn open_space(args: OpenSpaceArgs) -> Result<()> {
    let mut scenario = *args.scenario.scenario;
    if args.no_safety {
        scenario.robot.safety = false;
    }
    let plan = StudyPlan {
        scenario,
        algorithms: args.algorithms,
        densities: args.densities,
        seeds: args.seeds,
    };
    let started = Instant::now();
    let (rows, threads) = with_progress(args.jobs, plan.runs().len() as u64, |progress| {
        plan.execute(progress)
    })?;
    let summary = write_outputs(&args.out, &plan, &rows)?;
    eprintln!(
        "{} runs on {threads} threads in {:.1} s; wrote {}/runs.csv and summary.json",
        rows.len(),
        started.elapsed().as_secs_f64(),
        args.out.display(),
    );
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

fn intent_sharing(args: IntentSharingArgs) -> Result<()> {
    let scenario = args.scenario.fleet_site(Overrides {
        robots: args.robots,
        humans: args.humans,
        seed: None,
        no_safety: args.no_safety,
    })?;
    let (robots, humans) = scenario.fleet_size().unwrap_or((0, 0));
    let study = IntentSharingStudy {
        scenario,
        planner: args.planner,
        seeds: args.seeds,
        seconds: args.seconds,
    };
    let (runs, _) = with_progress(None, 2 * args.seeds, |progress| study.execute(progress))?;
    let runs = runs?;
    println!(
        "{} seeds x {} s, {robots} robots ({}), {humans} people; means per run:",
        args.seeds, args.seconds, args.planner
    );
    print!("{}", report(&runs));
    if let Some(path) = args.out {
        // Through a JSON value, whose keys are in alphabetical order.
        write_json(&path, &serde_json::to_value(&runs)?)?;
    }
    Ok(())
}

fn replay(args: ReplayArgs) -> Result<()> {
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
    let mut options = ReplayOptions::default();
    options.robot.max_speed = speed;
    options.robot.safety = !args.no_safety;
    let study = ReplayStudy {
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
    let started = Instant::now();
    let (rows, threads) = with_progress(args.jobs, study.jobs() as u64, |progress| {
        study.execute(progress)
    })?;
    let table = coordinator::study::replay::write_outputs(&out, &study, &rows)?;
    eprintln!(
        "{} runs on {threads} threads in {:.1} s; wrote {}/runs.csv, table.json, table.md",
        rows.len(),
        started.elapsed().as_secs_f64(),
        out.display()
    );
    print!("{}", table_markdown(&table));
    Ok(())
}

fn hallway(args: HallwayArgs) -> Result<()> {
    let scenario = hallway_scenario(args.robot_speed, !args.no_safety)?;
    let study = HallwayStudy {
        scenario,
        planners: args.planners,
        lengths: args.lengths,
        width_m: args.width,
        speeds: args.speeds,
        seeds: args.seeds,
    };
    // Every run's scenario must be valid before hours of work start.
    for &l in &study.lengths {
        for &v in &study.speeds {
            study
                .scenario_for(l, v, 1)
                .validate("experiment hallway")
                .with_context(|| format!("hallway {l} m, people at {v} m/s"))?;
        }
    }
    let started = Instant::now();
    let (rows, threads) = with_progress(args.jobs, study.runs().len() as u64, |progress| {
        study.execute(progress)
    })?;
    let summary = coordinator::study::hallway::write_outputs(&args.out, &study, &rows)?;
    eprintln!(
        "{} runs on {threads} threads in {:.1} s; wrote {}/runs.csv, summary.json and figures",
        rows.len(),
        started.elapsed().as_secs_f64(),
        args.out.display(),
    );
    println!(
        "| planner | length (m) | runs | reached | time to goal (s) | path changes | personal-space entries | robot-caused |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let planners: Vec<String> = study.planners.iter().map(|p| p.to_string()).collect();
    for p in &planners {
        for &l in &study.lengths {
            let cells: Vec<_> = summary
                .cells
                .iter()
                .filter(|c| &c.planner == p && c.length_m == l)
                .collect();
            let runs: usize = cells.iter().map(|c| c.runs).sum();
            let w = |f: &dyn Fn(&coordinator::study::hallway::HallwayCell) -> f64| {
                cells.iter().map(|c| f(c) * c.runs as f64).sum::<f64>() / runs.max(1) as f64
            };
            let timed: Vec<f64> = cells.iter().filter_map(|c| c.time_to_goal_s).collect();
            println!(
                "| {p} | {l} | {runs} | {:.0}% | {} | {:.2} | {:.2} | {} |",
                100.0 * w(&|c| c.reached),
                if timed.is_empty() {
                    "–".to_string()
                } else {
                    format!("{:.1}", timed.iter().sum::<f64>() / timed.len() as f64)
                },
                w(&|c| c.path_changes),
                w(&|c| c.personal_space_entries),
                cells.iter().map(|c| c.robot_caused_contacts).sum::<u64>(),
            );
        }
    }
    Ok(())
}

fn laned(args: LanedArgs) -> Result<()> {
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
    let started = Instant::now();
    let (rows, threads) = with_progress(args.jobs, study.runs().len() as u64, |progress| {
        study.execute(progress)
    })?;
    let cells = coordinator::study::laned::write_outputs(&args.out, &study, &rows)?;
    eprintln!(
        "{} runs on {threads} threads in {:.1} s; wrote {}/runs.csv, summary.json, average_speed.png",
        rows.len(),
        started.elapsed().as_secs_f64(),
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

/// Fleet sizes, comma-separated; the empty list is allowed (a site left out).
#[derive(Debug, Clone)]
struct FleetSizes(Vec<usize>);

fn fleet_sizes(s: &str) -> Result<FleetSizes, String> {
    if s.trim().is_empty() {
        return Ok(FleetSizes(Vec::new()));
    }
    s.split(',')
        .map(|n| {
            n.trim()
                .parse()
                .map_err(|e| format!("fleet size `{n}`: {e}"))
        })
        .collect::<Result<_, _>>()
        .map(FleetSizes)
}

/// `on` or `off`.
fn on_off(s: &str) -> Result<bool, String> {
    match s {
        "on" => Ok(true),
        "off" => Ok(false),
        _ => Err(format!("`{s}` is neither `on` nor `off`")),
    }
}

fn traffic(args: TrafficArgs) -> Result<()> {
    let mut sites = Vec::new();
    for (name, fleets) in [
        ("warehouse-narrow", args.narrow_fleets.0),
        ("hallway-fleet", args.hallway_fleets.0),
    ] {
        if fleets.is_empty() {
            continue;
        }
        let most = world_sim::scenario::MAX_ROBOTS;
        if let Some(&bad) = fleets.iter().find(|&&n| !(1..=most).contains(&n)) {
            bail!("fleet size {bad} for {name} is not in [1, {most}]");
        }
        let scenario = Scenario::builtin(name)?;
        sites.push(traffic_study::Site { scenario, fleets });
    }
    if sites.is_empty() {
        bail!("no fleet sizes given: --narrow-fleets and --hallway-fleets are both empty");
    }
    if args.first_seed.checked_add(args.seeds).is_none() {
        bail!(
            "--first-seed {} with --seeds {} runs past the last seed",
            args.first_seed,
            args.seeds
        );
    }
    let mut policies = args.policy;
    policies.sort_unstable();
    policies.dedup();
    let study = TrafficStudy {
        sites,
        planner: args.planner,
        first_seed: args.first_seed,
        seeds: args.seeds,
        policies,
        seconds: args.seconds,
    };
    let earlier = match &args.reuse {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("reading {}", path.display()))?;
            let mut runs = traffic_study::parse_runs(&text).with_context(|| {
                format!("reading {} as a traffic study's runs.csv", path.display())
            })?;
            runs.retain(|r| args.reuse_policy.contains(&r.policy));
            eprintln!("reusing {} runs from {}", runs.len(), path.display());
            runs
        }
        None => Vec::new(),
    };
    // Each run is saved as it ends, so an interrupted study loses nothing finished.
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let partial_path = args.out.join("runs.partial.csv");
    let partial = Mutex::new(
        csv::Writer::from_path(&partial_path)
            .with_context(|| format!("creating {}", partial_path.display()))?,
    );
    let save_error: Mutex<Option<String>> = Mutex::new(None);
    eprintln!(
        "saving runs to {} as they end; if interrupted, go on with `--reuse {} --reuse-policy off,on`",
        partial_path.display(),
        partial_path.display()
    );
    let started = Instant::now();
    let (runs, threads) = with_progress(args.jobs, study.runs().len() as u64, |progress| {
        study.execute_reusing(&earlier, &|run| {
            progress();
            let mut writer = partial.lock().unwrap_or_else(PoisonError::into_inner);
            let saved = writer
                .serialize(run)
                .map_err(|e| e.to_string())
                .and_then(|()| writer.flush().map_err(|e| e.to_string()));
            if let Err(e) = saved {
                let mut first = save_error.lock().unwrap_or_else(PoisonError::into_inner);
                first.get_or_insert(e);
            }
        })
    })?;
    let runs = runs?;
    if let Some(e) = save_error
        .into_inner()
        .unwrap_or_else(PoisonError::into_inner)
    {
        eprintln!(
            "warning: saving runs to {} failed: {e}",
            partial_path.display()
        );
    }
    let cells = traffic_study::write_outputs(&args.out, &study, &runs)?;
    drop(partial);
    std::fs::remove_file(&partial_path)
        .with_context(|| format!("removing {}", partial_path.display()))?;
    eprintln!(
        "{} runs on {threads} threads in {:.1} s; wrote {}/runs.csv, summary.json, summary.md and throughput.png",
        runs.len(),
        started.elapsed().as_secs_f64(),
        args.out.display(),
    );
    print!("{}", traffic_study::table(&cells));
    println!("\nWhere the stuck robot-seconds went:");
    print!("{}", traffic_study::stuck_table(&cells));
    Ok(())
}

fn anticipatory(args: AnticipatoryArgs) -> Result<()> {
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

fn asfm_estimates(args: AsfmEstimatesArgs) -> Result<()> {
    use coordinator::study::estimates::{recorded, simulated, write_outputs};
    let recordings = args
        .datasets
        .iter()
        .map(|d| {
            let recording = Recording::load(d)?;
            let map = map_of(&recording)
                .with_context(|| format!("{}: map.xml obstacles", d.display()))?;
            Ok((recording, map))
        })
        .collect::<Result<Vec<_>>>()?;
    let base = Scenario::builtin("open-space")?;
    let params = AsfmParams {
        process_noise: args.process_noise,
        ..AsfmParams::default()
    };
    let total = recordings.len() * args.limit + 2 * args.seeds as usize;
    let started = Instant::now();
    let (rows, threads) = with_progress(args.jobs, total as u64, |progress| {
        let mut rows = Vec::new();
        for (recording, map) in &recordings {
            let mut options = ReplayOptions::default();
            options.robot.max_speed = (median_speed(recording) * 100.0).round() / 100.0;
            rows.extend(recorded(
                recording,
                map,
                &options,
                &params,
                Some(args.limit),
                progress,
            ));
        }
        for react in [true, false] {
            rows.extend(simulated(
                &base,
                &params,
                args.density,
                args.seeds,
                react,
                progress,
            ));
        }
        rows
    })?;
    let summary = write_outputs(&args.out, &rows)?;
    eprintln!(
        "{} people on {threads} threads in {:.1} s; wrote {}/estimates.csv, summary.json, estimates.png",
        rows.len(),
        started.elapsed().as_secs_f64(),
        args.out.display(),
    );
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

fn summarize(dir: &std::path::Path) -> Result<()> {
    let path = dir.join("runs.csv");
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let parsed = parse_runs_csv(&text)?;
    let rows = parsed.rows;
    let seeds = rows.iter().map(|r| r.seed).max().unwrap_or(0);
    let plan = StudyPlan {
        scenario: Scenario::builtin("open-space")?,
        algorithms: parsed.algorithms,
        densities: parsed.densities,
        seeds,
    };
    write_summary(dir, &plan, &rows)?;
    eprintln!(
        "{} runs: wrote {1}/summary.json, fig4_success.png, fig5_social.png",
        rows.len(),
        dir.display()
    );
    Ok(())
}
