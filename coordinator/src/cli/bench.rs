//! `gapfleet bench`: how fast things run on this machine, printed as text or one JSON object.

use super::{Overrides, ScenarioRef, density, init_logging, positive, runtime};
use anyhow::{Result, bail};
use clap::Subcommand;
use clap::builder::TypedValueParser as _;
use coordinator::bench::machine::{CpuSpeedProbe, CpuTimes};
use coordinator::bench::round_trip::FleetBench;
use coordinator::bench::world::bench_world;
use coordinator::serve::demo::Transport;
use std::path::PathBuf;
use world_sim::scenario::{Scenario, WallModel};

/// A count of at least one.
fn at_least_one(text: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(0) => Err("must be at least 1".to_owned()),
        Ok(n) => Ok(n),
        Err(e) => Err(e.to_string()),
    }
}

/// The fleet's own sizes for the dashboard and fleet benchmarks.
fn warehouse_large(robots: usize, humans: usize) -> Result<Scenario> {
    let large: ScenarioRef = "warehouse-large".parse()?;
    large.fleet_site(Overrides {
        robots: Some(robots),
        humans: Some(humans),
        ..Overrides::default()
    })
}

#[derive(Debug, Subcommand)]
pub enum Bench {
    /// How steadily this machine's CPU runs, with nothing else of gapfleet's running: a fixed
    /// job timed every 5 ms in its own thread CPU time. On a shared VM the host slows the CPU
    /// down at times (often unseen by the steal counter), and latency tails follow.
    Cpu {
        /// Seconds to sample.
        #[arg(long, default_value_t = 20.0, value_parser = positive)]
        seconds: f64,
        /// Print one JSON object instead of text.
        #[arg(long)]
        json: bool,
    },
    /// A coordinator tick with and without the Rerun dashboard (recording to an .rrd file).
    Dashboard {
        /// Robots (parked).
        #[arg(long, default_value_t = 100, value_parser = at_least_one)]
        robots: usize,
        /// People.
        #[arg(long, default_value_t = 1000)]
        humans: usize,
        /// Ticks timed per variant (after 20 warm-up ticks).
        #[arg(long, default_value_t = 300, value_parser = at_least_one)]
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
        #[arg(long, default_value_t = 100, value_parser = at_least_one)]
        agents: usize,
        /// People (0 measures the fleet's transport and planning alone).
        #[arg(long, default_value_t = 0)]
        humans: usize,
        /// Seconds to run (real time, 10 Hz).
        #[arg(long, default_value_t = 30.0, value_parser = positive)]
        seconds: f64,
        /// `plain` TCP; `secured`: mutual TLS, user/password and the access-control list of
        /// a site written by `site init`; `both`: plain, secured, plain, secured in one run
        /// (alternated, so that the machine's drift falls on both) and the ratios.
        #[arg(long, value_enum, default_value_t = Security::Plain)]
        security: Security,
        /// Print one JSON object instead of text (with `--security both`, one per run).
        #[arg(long)]
        json: bool,
    },
    /// A fleet run long and fast, watched window by window for memory growth, round-trip
    /// drift and lost observations.
    Soak {
        /// Agents (robots).
        #[arg(long, default_value_t = 100, value_parser = at_least_one)]
        agents: usize,
        /// People.
        #[arg(long, default_value_t = 0)]
        humans: usize,
        /// Ticks to run (0.1 simulated s each).
        #[arg(long, default_value_t = 1_000_000)]
        ticks: u64,
        /// Simulated seconds per wall second, in [0.001, 1000] (the fleet runs as fast as the
        /// machine allows below it).
        #[arg(long, default_value_t = 1000.0, value_parser = super::speed)]
        speed: f64,
        /// Wall seconds per window.
        #[arg(long, default_value_t = 60.0, value_parser = positive)]
        window_s: f64,
        /// Wall seconds of warm-up: memory growth and the p99 are compared from the end of the
        /// window that closes it.
        #[arg(long, default_value_t = 600.0, value_parser = positive)]
        warm_up_s: f64,
        /// Every agent's planner stack. The soak watches the fleet's plumbing (transport,
        /// coordinator, memory); a lighter planner runs more ticks in the same time.
        #[arg(long, default_value = "pgp+orca")]
        planner: agent::planner::PlannerSpec,
        /// Print one JSON object instead of text.
        #[arg(long)]
        json: bool,
    },
    /// World steps per second: people walking (robots parked, planners not included).
    World {
        /// `open-space` (sized to --density), or a warehouse scenario (built-in name or file;
        /// --density is then ignored).
        #[arg(long, default_value = "open-space")]
        scenario: ScenarioRef,
        /// Number of people.
        #[arg(long, default_value_t = 1000, value_parser = at_least_one)]
        humans: usize,
        /// People per m² (the stage is sized to fit them).
        #[arg(long, default_value_t = 0.3, value_parser = density)]
        density: f64,
        /// Steps to time (after 20 warm-up steps).
        #[arg(long, default_value_t = 500, value_parser = at_least_one)]
        steps: usize,
        /// How walls push people: `points` (PySocialForce) or `field` (the same force read from
        /// a table built at set-up; see world-sim/README.md). Overrides the scenario's.
        #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(["points", "field"])
            .try_map(|name| name.parse::<WallModel>()))]
        walls: Option<WallModel>,
        /// Print one JSON object instead of text.
        #[arg(long)]
        json: bool,
    },
}

impl Bench {
    /// Runs the benchmark and prints what it measured.
    pub fn run(self) -> Result<()> {
        match self {
            Bench::Cpu { seconds, json } => cpu(seconds, json),
            Bench::Dashboard {
                robots,
                humans,
                ticks,
                rrd,
                json,
            } => {
                let scenario = warehouse_large(robots, humans)?;
                let b = coordinator::bench::dashboard::bench_dashboard(&scenario, ticks, &rrd)?;
                if json {
                    println!("{}", serde_json::to_string(&b)?);
                } else {
                    println!(
                        "{} robots, {} people, {} ticks: median tick {:.0} µs without dashboard, {:.0} µs with (.rrd): overhead {:.1} %, {} frames dropped\n\
                         the tick thread's CPU time: {:.0} µs without, {:.0} µs with ({:+.1} %)",
                        b.robots,
                        b.humans,
                        b.ticks,
                        b.without_us,
                        b.with_us,
                        b.overhead * 100.0,
                        b.dropped,
                        b.without_cpu_us,
                        b.with_cpu_us,
                        (b.with_cpu_us / b.without_cpu_us - 1.0) * 100.0,
                    );
                }
                Ok(())
            }
            Bench::Fleet {
                agents,
                humans,
                seconds,
                security,
                json,
            } => {
                init_logging("warn");
                let scenario = warehouse_large(agents, humans)?;
                let secured_runs: &[bool] = match security {
                    Security::Plain => &[false],
                    Security::Secured => &[true],
                    Security::Both => &[false, true, false, true],
                };
                let rt = runtime()?;
                let mut results = Vec::new();
                for &secured in secured_runs {
                    // A fresh site per secured run; its files go with it.
                    let site = if secured {
                        let robots = u32::try_from(agents).unwrap_or(u32::MAX);
                        Some(coordinator::site::TemporarySite::new(
                            &schemas::Keys::new("bench").expect("a valid site name"),
                            robots,
                        )?)
                    } else {
                        None
                    };
                    let transport = match &site {
                        Some(site) => Transport::Secured(site.paths.clone()),
                        None => Transport::Tcp,
                    };
                    if !json && secured_runs.len() > 1 {
                        println!(
                            "\n== {} ==",
                            if secured {
                                "secured: mutual TLS + user/password + access control"
                            } else {
                                "plain TCP"
                            }
                        );
                    }
                    let b = rt.block_on(coordinator::bench::round_trip::bench_fleet(
                        scenario.clone(),
                        agents,
                        humans,
                        seconds,
                        transport,
                    ))?;
                    print_fleet(&b, json)?;
                    results.push((secured, b));
                }
                if !json && secured_runs.len() > 1 {
                    print_security_cost(&results);
                }
                Ok(())
            }
            Bench::Soak {
                agents,
                humans,
                ticks,
                speed,
                window_s,
                warm_up_s,
                planner,
                json,
            } => {
                init_logging("warn");
                let scenario = warehouse_large(agents, humans)?;
                if !json {
                    println!(
                        "  wall s     ticks   RSS MiB  anon MiB  threads  state KiB   round trips   p50 ms   p99 ms"
                    );
                }
                let row = |w: &coordinator::bench::soak::SoakWindow| {
                    println!(
                        "{:8.0} {:9} {:9.1} {:9.1} {:8} {:10.1} {:13} {:8.2} {:8.2}",
                        w.wall_s,
                        w.ticks,
                        w.rss_mib,
                        w.anon_mib,
                        w.threads,
                        w.state_kib,
                        w.round_trips,
                        w.p50_ms,
                        w.p99_ms
                    );
                };
                let soak = runtime()?.block_on(coordinator::bench::soak::bench_soak(
                    scenario,
                    planner,
                    agents,
                    ticks,
                    speed,
                    std::time::Duration::from_secs_f64(window_s),
                    std::time::Duration::from_secs_f64(warm_up_s),
                    fleet_net::shutdown_signal(),
                    |w| {
                        if !json {
                            row(w);
                        }
                    },
                ))?;
                if json {
                    println!("{}", serde_json::to_string(&soak)?);
                    return Ok(());
                }
                if let Some(last) = soak.windows.last() {
                    row(last);
                }
                println!(
                    "{} agents, {} ticks in {:.0} wall s (asked {}x): {} observations, {} lost \
                     ({} seen missing by their agent), {} skipped for a newer one, {} answered; {} stale-command ticks, {} rejected",
                    soak.agents,
                    soak.ticks,
                    soak.wall_s,
                    soak.speed,
                    soak.observations,
                    soak.lost,
                    soak.missed,
                    soak.superseded,
                    soak.answered,
                    soak.stale_commands,
                    soak.rejected
                );
                println!(
                    "resident memory from the first window to the last: {:+.1} %",
                    soak.rss_growth_percent
                );
                match &soak.after_warm_up {
                    Some(a) => println!(
                        "after the warm-up (from {:.0} wall s): resident memory {:.1} → {:.1} MiB \
                         ({:+.1} %; peak {:.1} MiB, {:+.1} %), median window p99 {:.2} ms \
                         against {:.2} ms in the warm-up",
                        a.from_wall_s,
                        a.rss_start_mib,
                        a.rss_end_mib,
                        a.rss_growth_percent,
                        a.rss_peak_mib,
                        a.rss_peak_growth_percent,
                        a.p99_after_ms,
                        a.p99_warm_up_ms
                    ),
                    None => println!("no window closed after the {warm_up_s:.0} s warm-up"),
                }
                println!(
                    "the fleet: {} tasks done, {} contacts of every cause ({} robot-caused)",
                    soak.tasks, soak.contacts, soak.robot_caused_contacts
                );
                Ok(())
            }
            Bench::World {
                scenario,
                humans,
                density,
                steps,
                walls,
                json,
            } => world(&scenario, humans, density, steps, walls, json),
        }
    }
}

/// `bench cpu`: the CPU-speed probe alone.
fn cpu(seconds: f64, json: bool) -> Result<()> {
    let before = CpuTimes::now();
    let probe = CpuSpeedProbe::start()?;
    std::thread::sleep(std::time::Duration::from_secs_f64(seconds));
    let steal = before
        .zip(CpuTimes::now())
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

/// `bench world`: an open stage sized for `humans` at `density`, or a warehouse with
/// `humans` people.
fn world(
    scenario: &ScenarioRef,
    humans: usize,
    density: f64,
    steps: usize,
    walls: Option<WallModel>,
    json: bool,
) -> Result<()> {
    // The open stage is sized to the density; a warehouse keeps its floor and takes the count.
    let mut s = if scenario.name == "open-space" {
        Scenario::sized_for(humans, density)?
    } else {
        scenario.fleet_site(Overrides {
            humans: Some(humans),
            ..Overrides::default()
        })?
    };
    if let Some(walls) = walls {
        s.humans.walls = walls;
    }
    let b = bench_world(&scenario.name, &s, steps);
    if json {
        println!("{}", serde_json::to_string(&b)?);
    } else {
        println!(
            "{}: {} people at {:.2}/m², walls = {}, {} steps: median {:.1} µs/step, mean {:.1} µs/step, {:.0} steps/s (set-up {:.2} s)",
            b.scenario,
            b.humans,
            b.density,
            b.walls,
            b.steps,
            b.median_us_per_step,
            b.mean_us_per_step,
            b.steps_per_s,
            b.set_up_s
        );
    }
    Ok(())
}

/// `bench fleet`'s report.
/// What `bench fleet` runs over.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Security {
    /// Plain TCP.
    Plain,
    /// Mutual TLS, user/password and the access-control list.
    Secured,
    /// Both, alternated: plain, secured, plain, secured.
    Both,
}

/// The round trips of plain and secured runs side by side, and their ratios.
fn print_security_cost(results: &[(bool, FleetBench)]) {
    println!("\nround trip (ms)      p50     p99   lost");
    for (secured, b) in results {
        println!(
            "{:<16} {:7.2} {:7.2} {:6}",
            if *secured { "secured" } else { "plain" },
            b.round_trip_p50_ms,
            b.round_trip_p99_ms,
            b.lost
        );
    }
    let median = |secured: bool, f: fn(&FleetBench) -> f64| {
        let mut v: Vec<f64> = results
            .iter()
            .filter(|r| r.0 == secured)
            .map(|r| f(&r.1))
            .collect();
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
    };
    let p50 = |b: &FleetBench| b.round_trip_p50_ms;
    let p99 = |b: &FleetBench| b.round_trip_p99_ms;
    println!(
        "secured / plain: p50 {:.2}x, p99 {:.2}x (each the upper median of its runs)",
        median(true, p50) / median(false, p50),
        median(true, p99) / median(false, p99)
    );
}

fn print_fleet(b: &FleetBench, json: bool) -> Result<()> {
    if json {
        println!("{}", serde_json::to_string(b)?);
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
                c.samples, c.nominal_us, c.slow_percent, c.worst_slowdown, b.slow_cpu_time_percent
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
