//! `gapfleet`: the user-facing binary.

use anyhow::{Context, Result, bail};
use clap::builder::TypedValueParser as _;
use clap::{Parser, Subcommand};
use coordinator::experiment::{StudyPlan, parse_runs_csv, write_outputs, write_summary};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::time::Instant;
use world_sim::scenario::Scenario;

#[derive(Parser)]
#[command(
    name = "gapfleet",
    version,
    about = "Fleet coordination among people: planners, simulation, experiments"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Batch experiments with the planners in-process.
    #[command(subcommand)]
    Experiment(Experiment),
    /// Measure how fast things run on this machine, to size a deployment.
    #[command(subcommand)]
    Bench(Bench),
    /// The whole fleet in one process: a coordinator and one agent per robot, each with its
    /// own Zenoh session on loopback, in a warehouse with people.
    Demo(DemoArgs),
    /// Run the warehouse world and serve agents over Zenoh (`gapfleet-agent` processes).
    Coordinator(CoordinatorArgs),
}

#[derive(clap::Args)]
struct DemoArgs {
    /// Robots (one agent each).
    #[arg(long, default_value_t = 8)]
    robots: usize,
    /// People.
    #[arg(long, default_value_t = 40)]
    humans: usize,
    /// Simulated seconds.
    #[arg(long, default_value_t = 60.0)]
    seconds: f64,
    /// Seed of the world.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Planner stack of every agent.
    #[arg(long, default_value = "pgp+orca")]
    planner: agent::planner::PlannerSpec,
    /// Simulated seconds per wall second.
    #[arg(long, default_value_t = 1.0)]
    speed: f64,
    /// Built-in warehouse scenario or a scenario file.
    #[arg(long, default_value = "warehouse")]
    scenario: String,
    /// Where the coordinator listens (default: a free port on 127.0.0.1), e.g. to attach a
    /// Python client: tcp/127.0.0.1:7447.
    #[arg(long)]
    listen: Option<String>,
    /// Site name.
    #[arg(long, default_value = "demo")]
    site: String,
    /// Do not put other robots' intents into observations.
    #[arg(long)]
    no_intent_sharing: bool,
    #[command(flatten)]
    rerun: RerunArgs,
}

/// Where the Rerun dashboard goes (any combination; none: no dashboard).
#[derive(clap::Args, Clone, Default)]
struct RerunArgs {
    /// Save the dashboard recording to this .rrd file.
    #[arg(long, value_name = "PATH")]
    rrd: Option<PathBuf>,
    /// Serve the Rerun web viewer from this process and print its URL.
    #[arg(long)]
    web: bool,
    /// Stream to a running Rerun viewer, e.g. rerun+http://127.0.0.1:9876/proxy.
    #[arg(long, value_name = "URL")]
    rerun_connect: Option<String>,
    /// Spawn a native Rerun viewer (`rerun` on PATH, e.g. `pip install rerun-sdk==0.36.3`).
    #[arg(long)]
    spawn: bool,
}

impl RerunArgs {
    fn sinks(&self) -> dashboards::Sinks {
        dashboards::Sinks {
            rrd: self.rrd.clone(),
            web: self.web,
            connect: self.rerun_connect.clone(),
            spawn: self.spawn,
        }
    }
}

#[derive(clap::Args)]
struct CoordinatorArgs {
    /// Built-in warehouse scenario or a scenario file.
    #[arg(long, default_value = "warehouse")]
    scenario: String,
    /// Override the scenario's robot count.
    #[arg(long)]
    robots: Option<usize>,
    /// Override the scenario's people count.
    #[arg(long)]
    humans: Option<usize>,
    /// Override the scenario's seed.
    #[arg(long)]
    seed: Option<u64>,
    /// Simulated seconds per wall second.
    #[arg(long, default_value_t = 1.0)]
    speed: f64,
    /// Stop after this many simulated seconds (default: run until SIGINT/SIGTERM).
    #[arg(long)]
    seconds: Option<f64>,
    /// Site name.
    #[arg(long, default_value = "demo")]
    site: String,
    /// Do not put other robots' intents into observations.
    #[arg(long)]
    no_intent_sharing: bool,
    #[command(flatten)]
    net: agent::runtime::net::NetArgs,
    #[command(flatten)]
    rerun: RerunArgs,
}

#[derive(Subcommand)]
enum Bench {
    /// How steadily this machine's CPU runs, with nothing else of gapfleet's running: a fixed
    /// job timed every 5 ms in its own thread CPU time. On a shared VM the host slows the CPU
    /// down at times (often unseen by the steal counter), and latency tails follow.
    Cpu {
        /// Seconds to sample.
        #[arg(long, default_value_t = 20.0)]
        seconds: f64,
        /// Print one JSON object instead of text.
        #[arg(long)]
        json: bool,
    },
    /// A coordinator tick with and without the Rerun dashboard (recording to an .rrd file).
    Dashboard {
        /// Robots (parked).
        #[arg(long, default_value_t = 100)]
        robots: usize,
        /// People.
        #[arg(long, default_value_t = 1000)]
        humans: usize,
        /// Ticks timed per variant (after 20 warm-up ticks).
        #[arg(long, default_value_t = 300)]
        ticks: usize,
        /// Where the recording goes.
        #[arg(long, default_value = "target/bench-dashboard.rrd")]
        rrd: PathBuf,
        /// Print one JSON object instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Observation → command round trip of a live fleet over Zenoh (loopback, one session per
    /// agent), messages lost, and a raw Zenoh request/reply round trip for comparison.
    Fleet {
        /// Agents (robots).
        #[arg(long, default_value_t = 100)]
        agents: usize,
        /// People (0 measures the fleet's transport and planning alone).
        #[arg(long, default_value_t = 0)]
        humans: usize,
        /// Seconds to run (real time, 10 Hz).
        #[arg(long, default_value_t = 30.0)]
        seconds: f64,
        /// Print one JSON object instead of text.
        #[arg(long)]
        json: bool,
    },
    /// World steps per second: people walking (robots parked, planners not included).
    World {
        /// `open-space` (sized to --density), or a warehouse scenario (built-in name or file;
        /// --density is then ignored).
        #[arg(long, default_value = "open-space")]
        scenario: String,
        /// Number of people.
        #[arg(long, default_value_t = 1000)]
        humans: usize,
        /// People per m² (the stage is sized to fit them).
        #[arg(long, default_value_t = 0.3)]
        density: f64,
        /// Steps to time (after 20 warm-up steps).
        #[arg(long, default_value_t = 500)]
        steps: usize,
        /// How walls push people: `points` (PySocialForce) or `field` (the same force read from
        /// a table built at set-up; see world-sim/README.md). Overrides the scenario's.
        #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(["points", "field"])
            .try_map(|name| name.parse::<world_sim::scenario::WallModel>()))]
        walls: Option<world_sim::scenario::WallModel>,
        /// Print one JSON object instead of text.
        #[arg(long)]
        json: bool,
    },
}

#[derive(Subcommand)]
enum Experiment {
    /// The PGP paper's open-space study: algorithms × densities × seeds.
    OpenSpace {
        /// Planners, comma-separated.
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "dwa,orca,sf,pgp+dwa,pgp+orca,pgp+sf"
        )]
        algorithms: Vec<String>,
        /// People per m², comma-separated.
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "0.01,0.1,0.2,0.3,0.4,0.5,0.6,0.7,0.8,0.9,1.0"
        )]
        densities: Vec<f64>,
        /// Seeds per (algorithm, density): 1..=N, the same for every algorithm.
        #[arg(long, default_value_t = 100)]
        seeds: u64,
        /// Worker threads (default: all cores).
        #[arg(long)]
        jobs: Option<usize>,
        /// Output folder for runs.csv and summary.json.
        #[arg(long, default_value = "results/open-space")]
        out: PathBuf,
        /// A built-in scenario name or a scenario file to start from (default: open-space).
        #[arg(long)]
        scenario: Option<PathBuf>,
    },
    /// The same warehouse seeds with robots sharing intents and without: robot–robot near
    /// misses and collisions, in-process.
    IntentSharing {
        /// Seeds 1..=N.
        #[arg(long, default_value_t = 10)]
        seeds: u64,
        /// Simulated seconds per run.
        #[arg(long, default_value_t = 300.0)]
        seconds: f64,
        /// Robots.
        #[arg(long, default_value_t = 12)]
        robots: usize,
        /// People.
        #[arg(long, default_value_t = 40)]
        humans: usize,
        /// Planner stack of every robot.
        #[arg(long, default_value = "pgp+orca")]
        planner: agent::planner::PlannerSpec,
        /// Built-in warehouse scenario or a scenario file.
        #[arg(long, default_value = "warehouse")]
        scenario: String,
        /// Write the per-run table here as JSON.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// The foIGP paper's protocol on a recorded crowd (OpenTraj obsmat.txt format): each
    /// planner in turn takes a pedestrian's place among the others as recorded.
    Eth {
        /// A sequence folder with obsmat.txt (and optionally map.xml), e.g.
        /// world-sim/datasets/ETH/seq_eth.
        #[arg(long)]
        dataset: PathBuf,
        /// Planners, comma-separated.
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "foigp,igp-diag,igp-lin,mc,dwa,pgp+orca"
        )]
        planners: Vec<String>,
        /// partial (≈ 10 m stretches, start and goal only) or full (whole tracks).
        #[arg(long, default_value = "partial")]
        runs: world_sim::replay::RunKind,
        /// Only the first N runs.
        #[arg(long)]
        limit: Option<usize>,
        /// The robot's top speed, for every planner (m/s; default: the recording's median
        /// walking speed).
        #[arg(long)]
        robot_speed: Option<f64>,
        /// Worker threads (default: all cores).
        #[arg(long)]
        jobs: Option<usize>,
        /// Output folder (default: results/eth/<sequence>-<runs>).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Rebuild summary.json and the figures from a study's runs.csv, without re-running.
    Summarize {
        /// The study's output folder.
        #[arg(long, default_value = "results/open-space")]
        dir: PathBuf,
    },
}

/// A built-in scenario by name, or a scenario file.
fn load_scenario(name_or_path: &str) -> Result<Scenario> {
    let path = std::path::Path::new(name_or_path);
    match Scenario::builtin(name_or_path) {
        Ok(s) => return Ok(s),
        // Neither a built-in nor a file: the error lists the built-ins.
        Err(unknown) if !path.exists() => return Err(unknown.into()),
        Err(_) => {}
    }
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    Ok(Scenario::from_toml(&text, name_or_path)?)
}

/// A warehouse scenario with counts and seed overridden.
fn warehouse(
    name_or_path: &str,
    robots: Option<usize>,
    humans: Option<usize>,
    seed: Option<u64>,
) -> Result<Scenario> {
    let mut s = load_scenario(name_or_path)?;
    let Some(w) = s.warehouse.as_mut() else {
        bail!("scenario {name_or_path:?} is not a warehouse (it needs a [warehouse] table)");
    };
    if let Some(r) = robots {
        w.robots = r;
    }
    if let Some(h) = humans {
        w.humans = h;
    }
    if let Some(seed) = seed {
        s.seed = seed;
    }
    s.validate(name_or_path)?;
    Ok(s)
}

fn init_logging(default: &str) {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| default.into()),
        )
        .with_writer(std::io::stderr)
        .init();
}

fn runtime() -> Result<tokio::runtime::Runtime> {
    Ok(tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()?)
}

fn demo(args: DemoArgs) -> Result<()> {
    use coordinator::demo::{DemoOptions, run_demo, status_line, summary};
    use std::io::IsTerminal;
    init_logging("warn");
    let positive = |x: f64| x.is_finite() && x > 0.0;
    if !positive(args.speed) || !positive(args.seconds) {
        bail!("--speed and --seconds must be positive");
    }
    let scenario = warehouse(
        &args.scenario,
        Some(args.robots),
        Some(args.humans),
        Some(args.seed),
    )?;
    if !args.planner.avoids_static_obstacles() {
        eprintln!(
            "warning: {} does not see shelves or walls (the foIGP paper models people only); \
             robots will drive into them",
            args.planner
        );
    }
    let options = DemoOptions {
        scenario,
        planner: args.planner,
        seconds: args.seconds,
        speed: args.speed,
        site: args.site,
        listen: args.listen,
        share_intents: !args.no_intent_sharing,
        sinks: args.rerun.sinks(),
        round_trips: None,
    };
    eprintln!(
        "gapfleet demo: {} robots ({}), {} people, {} s at {}x; Ctrl-C stops early",
        args.robots, args.planner, args.humans, args.seconds, args.speed
    );
    let tty = std::io::stderr().is_terminal();
    let mut printed = 0u64;
    let report = runtime()?.block_on(run_demo(
        options,
        agent::runtime::shutdown_signal(),
        |status| {
            printed += 1;
            if tty {
                eprint!("\r{}", status_line(status));
            } else if printed.is_multiple_of(5) {
                eprintln!("{}", status_line(status));
            }
        },
        |url| eprintln!("dashboard: open {url}"),
    ))?;
    if tty {
        eprintln!();
    }
    println!("{}", summary(&report, args.planner));
    Ok(())
}

fn coordinator_main(args: CoordinatorArgs) -> Result<()> {
    use agent::runtime::net::{Role, config};
    use coordinator::demo::status_line;
    use coordinator::server::{CoordinatorConfig, Event, run_coordinator};
    init_logging("info,zenoh=warn");
    if !(args.speed.is_finite() && args.speed > 0.0) {
        bail!("--speed must be positive");
    }
    let scenario = warehouse(&args.scenario, args.robots, args.humans, args.seed)?;
    let mut net = args.net.clone();
    if net.listen.is_empty() && net.connect.is_empty() && net.zenoh_config.is_none() {
        net.listen.push("tcp/127.0.0.1:7447".to_owned());
    }
    let mut fleet = world_sim::fleet::Fleet::new(&scenario)?;
    fleet.share_intents = !args.no_intent_sharing;
    let mut config_ = CoordinatorConfig::new(&args.site);
    config_.speed = args.speed;
    config_.seconds = args.seconds;
    runtime()?.block_on(async {
        let session = zenoh::open(config(&net, Role::Router)?)
            .await
            .map_err(|e| anyhow::anyhow!("cannot open the Zenoh session: {e}"))?;
        eprintln!(
            "gapfleet coordinator: site {:?}, {} robots, {} people, listening {:?} connecting {:?}",
            args.site,
            fleet.robots(),
            fleet.world.humans.crowd.len(),
            net.listen,
            net.connect
        );
        let mut seen_events = 0;
        let log = |status: &coordinator::server::Status, _: &world_sim::fleet::Fleet| {
            for event in &status.events[seen_events..] {
                if !matches!(event, Event::TaskDone { .. }) {
                    eprintln!("event: {event:?}");
                }
            }
            seen_events = status.events.len();
            eprintln!("{}", status_line(status));
        };
        let sinks = args.rerun.sinks();
        let dashboard = if sinks.any() {
            fleet.measure_human_impact(coordinator::dashboard::HUMAN_IMPACT_WINDOW_S);
            let d = coordinator::dashboard::DashboardObserver::start(&fleet, &sinks, "agent")?;
            if let Some(url) = d.web_url() {
                eprintln!("dashboard: open {url}");
            }
            Some(d)
        } else {
            None
        };
        let mut observers = (log, dashboard);
        let status = run_coordinator(
            &session,
            fleet,
            config_,
            agent::runtime::shutdown_signal(),
            &mut observers,
        )
        .await?;
        if let Some(d) = observers.1 {
            let stats = d.finish();
            eprintln!(
                "dashboard: {} frames logged, {} dropped",
                stats.logged, stats.dropped
            );
        }
        eprintln!(
            "stopped after {:.1} simulated seconds, {} tasks done",
            status.sim_time, status.tasks_done
        );
        session
            .close()
            .await
            .map_err(|e| anyhow::anyhow!("closing the session: {e}"))?;
        Ok(())
    })
}

fn main() -> Result<()> {
    match Cli::parse().command {
        Command::Demo(args) => demo(args),
        Command::Coordinator(args) => coordinator_main(args),
        Command::Bench(Bench::Dashboard {
            robots,
            humans,
            ticks,
            rrd,
            json,
        }) => {
            if robots == 0 || ticks == 0 {
                bail!("--robots and --ticks must be positive");
            }
            let scenario = warehouse("warehouse-large", Some(robots), Some(humans), None)?;
            let b = coordinator::bench::bench_dashboard(&scenario, ticks, &rrd)?;
            if json {
                println!("{}", serde_json::to_string(&b)?);
            } else {
                println!(
                    "{} robots, {} people, {} ticks: median tick {:.0} µs without dashboard, {:.0} µs with (.rrd): overhead {:.1} %, {} frames dropped",
                    b.robots,
                    b.humans,
                    b.ticks,
                    b.without_us,
                    b.with_us,
                    b.overhead * 100.0,
                    b.dropped
                );
            }
            Ok(())
        }
        Command::Bench(Bench::Fleet {
            agents,
            humans,
            seconds,
            json,
        }) => {
            init_logging("warn");
            if agents == 0 || !(seconds.is_finite() && seconds > 0.0) {
                bail!("--agents and --seconds must be positive");
            }
            let scenario = warehouse("warehouse-large", Some(agents), Some(humans), None)?;
            let b = runtime()?.block_on(coordinator::bench::bench_fleet(
                scenario, agents, humans, seconds,
            ))?;
            if json {
                println!("{}", serde_json::to_string(&b)?);
            } else {
                println!(
                    "{} agents, {} people, {} simulated s at 10 Hz in {:.1} wall s: {} observations, {} answered, {} lost\n\
                     observation -> command round trip: p50 {:.2} ms, p99 {:.2} ms (worst agent's planning p99 {:.2} ms)\n\
                     raw Zenoh get/reply ({} B) while the fleet ran ({} samples): p50 {:.3} ms, p99 {:.3} ms; ratio p50 {:.1}x, p99 {:.1}x\n\
                     raw Zenoh get/reply on the idle machine afterwards: p50 {:.3} ms, p99 {:.3} ms; ratio p50 {:.1}x, p99 {:.1}x",
                    b.agents,
                    b.humans,
                    b.seconds,
                    b.wall_seconds,
                    b.observations,
                    b.answered,
                    b.lost,
                    b.round_trip_p50_ms,
                    b.round_trip_p99_ms,
                    b.planner_p99_us / 1000.0,
                    b.raw_payload_bytes,
                    b.raw_samples,
                    b.raw_zenoh_p50_ms,
                    b.raw_zenoh_p99_ms,
                    b.round_trip_p50_ms / b.raw_zenoh_p50_ms,
                    b.round_trip_p99_ms / b.raw_zenoh_p99_ms,
                    b.raw_idle_p50_ms,
                    b.raw_idle_p99_ms,
                    b.round_trip_p50_ms / b.raw_idle_p50_ms,
                    b.round_trip_p99_ms / b.raw_idle_p99_ms,
                );
                if let (Some(process), Some(steal)) = (b.process_cpu_percent, b.steal_percent) {
                    println!(
                        "the machine while the fleet ran: this process used {process:.1}% of all \
                         cores' CPU time; steal reported by the hypervisor {steal:.1}%"
                    );
                    if steal >= 1.0 {
                        println!(
                            "note: the hypervisor gave {steal:.1}% of the CPU time to others; \
                             latencies measured now measure the host (the probe below cannot see \
                             stolen time)"
                        );
                    }
                }
                if let Some(c) = b.cpu_speed {
                    println!(
                        "CPU-speed probe ({} jobs of {:.0} us, in thread CPU time, every 5 ms): \
                         {:.1}% took over twice as long (the slowest {:.1}x); the CPU may have run \
                         slow for {:.1}% of the run",
                        c.samples,
                        c.nominal_us,
                        c.slow_percent,
                        c.worst_slowdown,
                        b.slow_cpu_time_percent
                    );
                    let share = 100.0 * b.round_trips_in_slow_cpu as f64 / b.answered.max(1) as f64;
                    println!(
                        "round trips overlapping those stretches: {} of {} ({share:.1}%); p99 of \
                         the other {}: {}",
                        b.round_trips_in_slow_cpu,
                        b.answered,
                        b.answered.saturating_sub(b.round_trips_in_slow_cpu),
                        b.round_trip_p99_clear_ms
                            .map_or("-".to_owned(), |p| format!("{p:.2} ms")),
                    );
                    if share > 1.0 {
                        println!(
                            "note: over 1% of the round trips overlapped slow CPU, so the p99 above \
                             measures the host as much as gapfleet (coordinator/README.md)"
                        );
                    }
                }
            }
            Ok(())
        }
        Command::Bench(Bench::Cpu { seconds, json }) => {
            if !(seconds.is_finite() && seconds > 0.0) {
                bail!("--seconds must be positive");
            }
            let before = coordinator::machine::CpuTimes::now();
            let probe = coordinator::machine::CpuSpeedProbe::start()?;
            std::thread::sleep(std::time::Duration::from_secs_f64(seconds));
            let steal = before
                .zip(coordinator::machine::CpuTimes::now())
                .and_then(|(a, b)| a.shares(b))
                .map(|s| s.1);
            let Some(c) = probe.finish().summary() else {
                bail!("the probe timed no job in {seconds} s");
            };
            if json {
                println!(
                    "{}",
                    serde_json::json!({ "cpu_speed": c, "steal_percent": steal })
                );
            } else {
                println!(
                    "{} jobs of {:.0} us: {:.1}% took over twice as long, the slowest {:.1}x; \
                     steal reported by the hypervisor {}",
                    c.samples,
                    c.nominal_us,
                    c.slow_percent,
                    c.worst_slowdown,
                    steal.map_or("unknown".to_owned(), |s| format!("{s:.1}%"))
                );
            }
            Ok(())
        }
        Command::Bench(Bench::World {
            scenario,
            humans,
            density,
            steps,
            walls,
            json,
        }) => bench_world(&scenario, humans, density, steps, walls, json),
        Command::Experiment(Experiment::OpenSpace {
            algorithms,
            densities,
            seeds,
            jobs,
            out,
            scenario,
        }) => {
            let scenario = match &scenario {
                Some(name_or_path) => load_scenario(&name_or_path.display().to_string())?,
                None => Scenario::builtin("open-space")?,
            };
            let algorithms = algorithms
                .iter()
                .map(|a| a.parse())
                .collect::<Result<Vec<_>, _>>()?;
            if let Some(bad) = densities
                .iter()
                .find(|d| !(d.is_finite() && **d > 0.0 && **d <= 3.0))
            {
                bail!("--densities: {bad} is not in (0, 3] people per m²");
            }
            if seeds == 0 {
                bail!("--seeds must be at least 1");
            }
            let plan = StudyPlan {
                scenario,
                algorithms,
                densities,
                seeds,
            };
            let threads =
                jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()?;
            let total = plan.runs().len() as u64;
            let bar = ProgressBar::new(total).with_style(
                ProgressStyle::with_template(
                    "{elapsed_precise} [{bar:40}] {pos}/{len} runs, eta {eta}",
                )?
                .progress_chars("=> "),
            );
            let started = Instant::now();
            let rows = pool.install(|| plan.execute(&|| bar.inc(1)));
            bar.finish();
            let summary = write_outputs(&out, &plan, &rows)
                .with_context(|| format!("writing {}", out.display()))?;
            eprintln!(
                "{} runs on {threads} threads in {:.1} s; wrote {}/runs.csv and summary.json",
                rows.len(),
                started.elapsed().as_secs_f64(),
                out.display(),
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
        Command::Experiment(Experiment::IntentSharing {
            seeds,
            seconds,
            robots,
            humans,
            planner,
            scenario,
            out,
        }) => intent_sharing(&scenario, seeds, seconds, robots, humans, planner, out),
        Command::Experiment(Experiment::Eth {
            dataset,
            planners,
            runs,
            limit,
            robot_speed,
            jobs,
            out,
        }) => replay_study(&dataset, &planners, runs, limit, robot_speed, jobs, out),
        Command::Experiment(Experiment::Summarize { dir }) => {
            let path = dir.join("runs.csv");
            let text = std::fs::read_to_string(&path)
                .with_context(|| format!("reading {}", path.display()))?;
            let parsed = parse_runs_csv(&text)?;
            let rows = parsed.rows;
            let seeds = rows.iter().map(|r| r.seed).max().unwrap_or(0);
            let plan = StudyPlan {
                scenario: Scenario::builtin("open-space")?,
                algorithms: parsed.algorithms,
                densities: parsed.densities,
                seeds,
            };
            write_summary(&dir, &plan, &rows)
                .with_context(|| format!("writing {}", dir.display()))?;
            eprintln!(
                "{} runs: wrote {1}/summary.json, fig4_success.png, fig5_social.png",
                rows.len(),
                dir.display()
            );
            Ok(())
        }
    }
}

/// Runs every seed with intent sharing on and off and prints the paired comparison.
fn intent_sharing(
    scenario: &str,
    seeds: u64,
    seconds: f64,
    robots: usize,
    humans: usize,
    planner: agent::planner::PlannerSpec,
    out: Option<PathBuf>,
) -> Result<()> {
    use rayon::prelude::*;
    if seeds == 0 || !(seconds.is_finite() && seconds > 0.0) {
        bail!("--seeds and --seconds must be positive");
    }
    let base = warehouse(scenario, Some(robots), Some(humans), None)?;
    let runs: Vec<(u64, bool)> = (1..=seeds).flat_map(|s| [(s, true), (s, false)]).collect();
    let bar = ProgressBar::new(runs.len() as u64);
    let results: Vec<(u64, bool, world_sim::fleet::FleetReport)> = runs
        .par_iter()
        .map(|&(seed, share)| {
            let mut s = base.clone();
            s.seed = seed;
            let report = world_sim::fleet::run_fleet(&s, planner, seconds, share)
                .expect("validated warehouse");
            bar.inc(1);
            (seed, share, report)
        })
        .collect();
    bar.finish();
    let row = |r: &world_sim::fleet::FleetReport| {
        let n = r.robots.len() as f64;
        serde_json::json!({
            "tasks": r.total_tasks(),
            "robot_near_miss_steps": r.robots.iter().map(|m| m.robot_near_misses).sum::<u64>(),
            "robot_contact_steps": r.robots.iter().map(|m| m.robot_contacts).sum::<u64>(),
            "collision_rate": r.robots.iter().map(|m| m.collision_rate).sum::<f64>() / n,
            "svr": r.robots.iter().map(|m| m.svr).sum::<f64>() / n,
        })
    };
    let table: Vec<serde_json::Value> = results
        .iter()
        .map(|(seed, share, r)| {
            let mut v = row(r);
            v["seed"] = (*seed).into();
            v["sharing"] = (*share).into();
            v
        })
        .collect();
    let mean = |share: bool, key: &str| {
        let values = table
            .iter()
            .filter(|v| v["sharing"] == share)
            .filter_map(|v| v[key].as_f64());
        coordinator::stats::mean(values).unwrap_or(0.0)
    };
    println!(
        "{} seeds x {seconds} s, {robots} robots ({planner}), {humans} people; means per run:",
        seeds
    );
    println!("sharing  tasks  robot_near_miss_steps  robot_contact_steps  collision%   SVR");
    for share in [true, false] {
        println!(
            "{:7}  {:5.1}  {:21.1}  {:19.1}  {:10.3}  {:.3}",
            if share { "on" } else { "off" },
            mean(share, "tasks"),
            mean(share, "robot_near_miss_steps"),
            mean(share, "robot_contact_steps"),
            mean(share, "collision_rate") * 100.0,
            mean(share, "svr")
        );
    }
    // Paired by seed: the seeds are the same world with sharing switched, so the per-seed
    // differences carry the effect and the Wilcoxon signed-rank test asks whether it is zero.
    println!(
        "paired by seed (on - off): metric, mean difference, seeds higher with sharing, \
         two-sided Wilcoxon signed-rank p (normal approximation)"
    );
    let value = |seed: u64, share: bool, key: &str| {
        table
            .iter()
            .find(|v| v["seed"] == seed && v["sharing"] == share)
            .and_then(|v| v[key].as_f64())
    };
    for key in [
        "tasks",
        "robot_near_miss_steps",
        "robot_contact_steps",
        "collision_rate",
        "svr",
    ] {
        let diffs: Vec<f64> = (1..=seeds)
            .filter_map(|seed| Some(value(seed, true, key)? - value(seed, false, key)?))
            .collect();
        let higher = diffs.iter().filter(|d| **d > 0.0).count();
        let p = coordinator::stats::wilcoxon_signed_rank(&diffs)
            .map_or_else(|| "n/a (no seed differs)".to_owned(), |p| format!("{p:.3}"));
        println!(
            "  {key:22} {:+12.4}  {higher:3} of {}  p = {p}",
            coordinator::stats::mean(diffs.iter().copied()).unwrap_or(0.0),
            diffs.len()
        );
    }
    if let Some(path) = out {
        std::fs::write(&path, serde_json::to_string_pretty(&table)?)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

/// Times `steps` world steps; reports the median and mean step time and steps per second.
fn bench_world(
    scenario: &str,
    humans: usize,
    density: f64,
    steps: usize,
    walls: Option<world_sim::scenario::WallModel>,
    json: bool,
) -> Result<()> {
    if humans == 0 || steps == 0 || !(density > 0.0 && density <= 3.0) {
        bail!("--humans and --steps must be positive and --density in (0, 3]");
    }
    // The open stage is sized to the density; a warehouse keeps its floor and takes the count.
    let mut s = if scenario == "open-space" {
        Scenario::sized_for(humans, density)?
    } else {
        warehouse(scenario, None, Some(humans), None)?
    };
    if let Some(walls) = walls {
        s.humans.walls = walls;
    }
    let set_up = Instant::now();
    let mut world = if scenario == "open-space" {
        world_sim::world::World::open_space(&s)
    } else {
        world_sim::world::World::from_scenario(&s)
    };
    let set_up = set_up.elapsed().as_secs_f64();
    let walls = s.humans.walls.name();
    let park = vec![agent::model::Command::STOP; world.robots.len()];
    for _ in 0..20 {
        world.step(&park);
    }
    let mut times = Vec::with_capacity(steps);
    let started = Instant::now();
    for _ in 0..steps {
        let t = Instant::now();
        world.step(&park);
        times.push(t.elapsed().as_secs_f64() * 1e6);
    }
    let total = started.elapsed().as_secs_f64();
    times.sort_by(f64::total_cmp);
    let median = times[times.len() / 2];
    let mean = times.iter().sum::<f64>() / times.len() as f64;
    let people = world.humans.crowd.len();
    // People per m² of floor: the open stage's as asked; a warehouse's over its free area.
    let density = world
        .site()
        .map_or(density, |site| people as f64 / site.free_area());
    if json {
        println!(
            "{}",
            serde_json::json!({
                "scenario": scenario, "humans": people, "density": density, "walls": walls,
                "steps": steps, "median_us_per_step": median, "mean_us_per_step": mean,
                "steps_per_s": steps as f64 / total, "set_up_s": set_up,
            })
        );
    } else {
        println!(
            "{scenario}: {people} people at {density:.2}/m², walls = {walls}, {steps} steps: median {median:.1} µs/step, mean {mean:.1} µs/step, {:.0} steps/s (set-up {set_up:.2} s)",
            steps as f64 / total
        );
    }
    Ok(())
}

/// `gapfleet experiment eth`.
fn replay_study(
    dataset: &std::path::Path,
    planners: &[String],
    kind: world_sim::replay::RunKind,
    limit: Option<usize>,
    robot_speed: Option<f64>,
    jobs: Option<usize>,
    out: Option<PathBuf>,
) -> Result<()> {
    use coordinator::replay_study::{ReplayStudy, write_outputs};
    use world_sim::dataset::Recording;
    use world_sim::replay::{ReplayOptions, map_of, median_speed};
    let recording = Recording::load(dataset)?;
    let map =
        map_of(&recording).with_context(|| format!("{}: map.xml obstacles", dataset.display()))?;
    let planners = planners
        .iter()
        .map(|p| p.parse())
        .collect::<Result<Vec<_>, _>>()?;
    let out = out
        .unwrap_or_else(|| PathBuf::from("results/eth").join(format!("{}-{kind}", recording.name)));
    let speed = robot_speed.unwrap_or_else(|| (median_speed(&recording) * 100.0).round() / 100.0);
    if !(speed.is_finite() && speed > 0.0 && speed <= 5.0) {
        bail!("--robot-speed: {speed} is not in (0, 5] m/s");
    }
    let mut options = ReplayOptions::default();
    options.robot.max_speed = speed;
    let study = ReplayStudy {
        recording,
        map,
        planners,
        kind,
        options,
        limit,
    };
    let runs = study.runs().len();
    if runs == 0 {
        bail!("{}: no {kind} runs in this recording", dataset.display());
    }
    let threads =
        jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    eprintln!(
        "{}: {} tracks, {runs} {kind} runs × ({} planners + human), robot top speed {speed} m/s, \
         on {threads} threads",
        study.recording.name,
        study.recording.tracks.len(),
        study.planners.len()
    );
    let bar = ProgressBar::new(study.jobs() as u64).with_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} runs, eta {eta}")?
            .progress_chars("=> "),
    );
    let started = Instant::now();
    let rows = pool.install(|| study.execute(&|| bar.inc(1)));
    bar.finish();
    let table =
        write_outputs(&out, &study, &rows).with_context(|| format!("writing {}", out.display()))?;
    eprintln!(
        "{} runs in {:.1} s; wrote {}/runs.csv, table.json, table.md",
        rows.len(),
        started.elapsed().as_secs_f64(),
        out.display()
    );
    print!("{}", coordinator::replay_study::table_markdown(&table));
    Ok(())
}
