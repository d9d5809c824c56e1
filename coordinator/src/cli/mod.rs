//! The `gapfleet` command line: one module per subcommand with its clap types. Values are
//! parsed once, into checked types (planners as `PlannerSpec`s, scenarios as [`ScenarioRef`]s,
//! ranges by value parsers), so that the work behind a command receives only valid input.

pub mod bench;
pub mod coordinator;
pub mod demo;
pub mod deployment;
pub mod hardware;
pub mod replay;
pub mod site;
#[cfg(feature = "studies")]
pub mod study;

use anyhow::Result;
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use world_sim::scenario::Scenario;

/// `gapfleet`'s arguments.
#[derive(Debug, Parser)]
#[command(
    name = "gapfleet",
    version,
    about = "Fleet coordination among people: planners, simulation, studies"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// The studies: the planners in batches of runs in-process (`experiment` is its old name).
    #[cfg(feature = "studies")]
    #[command(subcommand, alias = "experiment")]
    Study(study::Study),
    /// Measure how fast things run on this machine, to size a deployment.
    #[command(subcommand)]
    Bench(bench::Bench),
    /// The whole fleet in one process: a coordinator and one agent per robot, each with its
    /// own Zenoh session on loopback, in a warehouse with people.
    Demo(demo::DemoArgs),
    /// Run the warehouse world and serve agents over Zenoh (`gapfleet-agent` processes).
    Coordinator(coordinator::CoordinatorArgs),
    /// The robots' hardware, played by the simulator: the site's people and robots, each
    /// robot a ROS 2 robot over rmw_zenoh driven by its `cmd_vel`, for agents in ROS mode and a
    /// coordinator with `--live`.
    Hardware(hardware::HardwareArgs),
    /// The deployment topology on this machine: a real `zenohd`, the robots' hardware, one
    /// agent per robot driving it over ROS 2, and a coordinator that simulates no robot, each
    /// its own process (`--humans` sets the hardware's people: the coordinator has none).
    Loop(deployment::LoopArgs),
    /// A secured site: its certificate authority, identities and Zenoh configs.
    #[command(subcommand)]
    Site(site::Site),
    /// Re-run a recorded live run (`--state DIR` of `coordinator` or `demo`) in-process and
    /// check that it comes out bit for bit the same.
    Replay(replay::ReplayArgs),
}

impl Command {
    /// Runs the subcommand.
    pub fn run(self) -> Result<()> {
        match self {
            #[cfg(feature = "studies")]
            Command::Study(s) => s.run(),
            Command::Bench(b) => b.run(),
            Command::Demo(d) => d.run(),
            Command::Coordinator(c) => c.run(),
            Command::Hardware(h) => h.run(),
            Command::Loop(l) => l.run(),
            Command::Site(s) => s.run(),
            Command::Replay(r) => r.run(),
        }
    }
}

/// A scenario named on the command line, loaded and validated once: a built-in name
/// (`warehouse`, `open-space`, …) or a TOML file.
#[derive(Debug, Clone)]
pub struct ScenarioRef {
    /// As given.
    pub name: String,
    /// Its content (boxed: a scenario is large beside the other arguments).
    pub scenario: Box<Scenario>,
    /// Its TOML text (a journal keeps it, to build the scenario again).
    pub toml: String,
}

impl std::str::FromStr for ScenarioRef {
    type Err = anyhow::Error;

    fn from_str(name_or_path: &str) -> Result<Self> {
        let (scenario, toml) = Scenario::load(name_or_path)?;
        Ok(Self {
            name: name_or_path.to_owned(),
            scenario: Box::new(scenario),
            toml,
        })
    }
}

/// Changes to a warehouse scenario's counts and seed; `None` keeps the scenario's value.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Overrides {
    /// Robots.
    pub robots: Option<usize>,
    /// People.
    pub humans: Option<usize>,
    /// Seed of the world.
    pub seed: Option<u64>,
    /// Turn the safety layer off (`--no-safety`); `false` keeps the scenario's setting.
    pub no_safety: bool,
}

impl ScenarioRef {
    /// Where the scenario came from with `overrides`, for a journal.
    pub fn source(&self, overrides: Overrides) -> ::coordinator::serve::journal::ScenarioSource {
        ::coordinator::serve::journal::ScenarioSource {
            name: self.name.clone(),
            toml: self.toml.clone(),
            robots: overrides.robots,
            humans: overrides.humans,
            seed: overrides.seed,
            no_safety: overrides.no_safety,
            map_fingerprint: self
                .scenario
                .floor_plan
                .as_ref()
                .and_then(|f| f.plan.as_ref())
                .map(|p| p.fingerprint),
        }
    }

    /// The scenario as a fleet site (a warehouse or a fleet hallway) with `overrides` applied
    /// (and validated again), built as a journal builds it again.
    pub fn fleet_site(&self, overrides: Overrides) -> Result<Scenario> {
        Ok(self.source(overrides).scenario()?)
    }
}

/// The traffic policy of a served fleet: on with the default parameters unless changed.
#[derive(Debug, Clone, clap::Args)]
pub struct PolicyArgs {
    /// Leave the robots' goals to their routes: no one-way aisles, keep-right lanes or
    /// retreats (`world_sim::traffic_policy`).
    #[arg(long, conflicts_with = "policy_params")]
    no_traffic_policy: bool,
    /// Changes to the traffic policy's parameters (`world_sim::traffic_policy::PolicyParams`),
    /// as `key=value,…`: e.g. `people_route_weight_m=3`. The journal (`--state`) records
    /// them, so that `gapfleet replay` re-runs the same policy.
    #[arg(long, value_name = "KEY=VALUE,…", value_parser = policy_params)]
    policy_params: Option<world_sim::traffic_policy::PolicyParams>,
}

impl PolicyArgs {
    /// The policy's parameters, or `None` with `--no-traffic-policy`.
    pub fn policy(&self) -> Option<world_sim::traffic_policy::PolicyParams> {
        (!self.no_traffic_policy).then(|| self.policy_params.unwrap_or_default())
    }
}

/// The default traffic policy with the changes `text` names (`key=value,…`).
fn policy_params(text: &str) -> Result<world_sim::traffic_policy::PolicyParams, String> {
    world_sim::traffic_policy::PolicyParams::default().with_overrides(text)
}

/// A finite number above zero.
pub fn positive(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        Ok(x) => Err(format!("{x} is not a positive number")),
        Err(e) => Err(e.to_string()),
    }
}

/// Simulated seconds per wall second: [0.001, 1000]. (Beyond, a tick's wall period overflows
/// a `Duration` or rounds to zero, which a tokio interval refuses with a panic.)
pub fn speed(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if (1e-3..=1e3).contains(&x) => Ok(x),
        Ok(x) => Err(format!(
            "{x} is not in [0.001, 1000] simulated seconds per wall second"
        )),
        Err(e) => Err(e.to_string()),
    }
}

/// The fleet site a process runs (`coordinator`, `hardware`, `loop`): a scenario and the
/// counts and seed given over it.
#[derive(Debug, Clone, clap::Args)]
pub struct SiteArgs {
    /// Built-in fleet site or a scenario file.
    #[arg(long, default_value = "warehouse")]
    pub scenario: ScenarioRef,
    /// Override the scenario's robot count.
    #[arg(long)]
    pub robots: Option<usize>,
    /// Override the scenario's people count.
    #[arg(long)]
    pub humans: Option<usize>,
    /// Override the scenario's seed.
    #[arg(long)]
    pub seed: Option<u64>,
}

impl SiteArgs {
    /// The counts and seed given.
    pub fn overrides(&self) -> Overrides {
        Overrides {
            robots: self.robots,
            humans: self.humans,
            seed: self.seed,
            ..Overrides::default()
        }
    }

    /// The scenario with the overrides.
    pub fn scenario(&self) -> Result<Scenario> {
        self.scenario.fleet_site(self.overrides())
    }
}

/// A set of robots on the command line: `all`, `none`, or ids and ranges such as `0-3,6`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RobotSet {
    /// Every robot of the site.
    All,
    /// These ids (sorted, without repeats).
    Ids(Vec<u32>),
}

impl RobotSet {
    /// The ids among `n` robots; an id the site does not have is an error.
    pub fn ids(&self, n: usize) -> Result<Vec<u32>> {
        match self {
            RobotSet::All => Ok((0..n as u32).collect()),
            RobotSet::Ids(ids) => {
                if let Some(&bad) = ids.iter().find(|&&i| i as usize >= n) {
                    anyhow::bail!(
                        "robot {bad} named, but the site has {n} robots (0-{})",
                        n.saturating_sub(1)
                    );
                }
                Ok(ids.clone())
            }
        }
    }
}

impl std::str::FromStr for RobotSet {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        match text {
            "all" => return Ok(RobotSet::All),
            "none" => return Ok(RobotSet::Ids(Vec::new())),
            _ => {}
        }
        let id = |t: &str| {
            t.trim().parse::<u32>().map_err(|e| {
                format!("{t:?} is not a robot id: {e} (give all, none, or ids like 0-3,6)")
            })
        };
        let mut ids = Vec::new();
        for part in text.split(',') {
            match part.split_once('-') {
                Some((a, b)) => {
                    let (a, b) = (id(a)?, id(b)?);
                    if a > b {
                        return Err(format!("{part:?}: the range runs backwards"));
                    }
                    if b - a > 100_000 {
                        return Err(format!("{part:?}: more than 100000 robots"));
                    }
                    ids.extend(a..=b);
                }
                None => ids.push(id(part)?),
            }
        }
        ids.sort_unstable();
        ids.dedup();
        Ok(RobotSet::Ids(ids))
    }
}

/// People per m² for a generated stage: (0, 3].
pub fn density(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(d) if d.is_finite() && d > 0.0 && d <= 3.0 => Ok(d),
        Ok(d) => Err(format!("{d} is not in (0, 3] people per m²")),
        Err(e) => Err(e.to_string()),
    }
}

/// Where the Rerun dashboard goes (any combination; none: no dashboard).
#[derive(Debug, clap::Args, Clone, Default)]
pub struct RerunArgs {
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
    /// The dashboard's sinks.
    pub fn sinks(&self) -> dashboards::Sinks {
        dashboards::Sinks {
            rrd: self.rrd.clone(),
            web: self.web,
            connect: self.rerun_connect.clone(),
            spawn: self.spawn,
        }
    }
}

/// Logs to stderr, filtered by `RUST_LOG` or else `default`.
pub fn init_logging(default: &str) {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| default.into()),
        )
        .with_writer(std::io::stderr)
        // Colours for a terminal only: a log file gets plain text.
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .init();
}

/// A multi-threaded Tokio runtime for the commands that talk Zenoh.
pub fn runtime() -> Result<tokio::runtime::Runtime> {
    Ok(tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(args: &[&str]) -> Cli {
        Cli::try_parse_from(std::iter::once("gapfleet").chain(args.iter().copied()))
            .expect("valid arguments")
    }

    /// Regression: `demo --scenario FILE` ignored the file's robot and people counts and seed
    /// (the demo's own 8, 40 and 1 always won). A scenario's values hold unless a flag is given.
    #[test]
    fn demo_takes_the_scenarios_counts_unless_flags_override_them() {
        let tmp = tempfile::tempdir().expect("a temporary folder");
        let dir = tmp.path().join("scenarios");
        std::fs::create_dir_all(&dir).expect("temp dir");
        let file = dir.join("busy.toml");
        let builtin = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../world-sim/scenarios/warehouse.toml"
        );
        let text = std::fs::read_to_string(builtin)
            .expect("the built-in warehouse's file")
            .replace("robots = 8", "robots = 13")
            .replace("humans = 40", "humans = 55")
            .replace("seed = 1", "seed = 9");
        std::fs::write(&file, text).expect("scenario file");
        let path = file.to_str().expect("UTF-8 path");

        let Command::Demo(args) = parse(&["demo", "--scenario", path]).command else {
            panic!("not a demo");
        };
        let s = args.scenario().expect("a warehouse");
        let w = s.warehouse.expect("warehouse table");
        assert_eq!((w.robots, w.humans, s.seed), (13, 55, 9));

        let Command::Demo(args) =
            parse(&["demo", "--scenario", path, "--robots", "3", "--seed", "4"]).command
        else {
            panic!("not a demo");
        };
        let s = args.scenario().expect("a warehouse");
        let w = s.warehouse.expect("warehouse table");
        assert_eq!((w.robots, w.humans, s.seed), (3, 55, 4));

        // The embedded default is unchanged: 8 robots, 40 people, seed 1.
        let Command::Demo(args) = parse(&["demo"]).command else {
            panic!("not a demo");
        };
        let s = args.scenario().expect("a warehouse");
        let w = s.warehouse.expect("warehouse table");
        assert_eq!((w.robots, w.humans, s.seed), (8, 40, 1));
    }

    /// Every robot a valid scenario may have fits on the wire.
    #[test]
    fn scenarios_allow_no_more_robots_than_the_wire() {
        assert_eq!(world_sim::scenario::MAX_ROBOTS, schemas::codec::MAX_ROBOTS);
    }

    #[test]
    fn bad_values_are_refused_while_parsing() {
        let refused = |args: &[&str]| {
            Cli::try_parse_from(std::iter::once("gapfleet").chain(args.iter().copied()))
                .expect_err("refused")
                .to_string()
        };
        for speed in ["0", "1e-300", "1e300", "nan", "-1"] {
            let arg = format!("--speed={speed}");
            for command in ["demo", "coordinator"] {
                let message = refused(&[command, &arg]);
                assert!(message.contains("not in [0.001, 1000]"), "{message}");
            }
        }
        assert!(refused(&["demo", "--seconds", "nan"]).contains("not a positive number"));
        assert!(refused(&["demo", "--scenario", "no-such-place"]).contains("no-such-place"));
        assert!(refused(&["demo", "--planner", "teleport"]).contains("teleport"));
        #[cfg(feature = "studies")]
        {
            assert!(
                refused(&["study", "open-space", "--densities", "0.1,4"]).contains("not in (0, 3]")
            );
            assert!(refused(&["study", "open-space", "--seeds", "0"]).contains("0"));
            assert!(
                refused(&["study", "open-space", "--algorithms", "dwa,teleport"])
                    .contains("teleport")
            );
        }
    }

    /// `study replay` and `study eth` are the old names of `study playback`, and `experiment`
    /// of `study`.
    #[cfg(feature = "studies")]
    #[test]
    fn experiment_replay_and_eth_are_aliases_of_playback() {
        for name in ["playback", "replay", "eth"] {
            let cli = parse(&["study", name, "--dataset", "x"]);
            assert!(
                matches!(
                    parse(&["experiment", name, "--dataset", "x"]).command,
                    Command::Study(study::Study::Playback(_))
                ),
                "experiment {name}"
            );
            assert!(
                matches!(cli.command, Command::Study(study::Study::Playback(_))),
                "{name}"
            );
        }
    }
}
