//! `gapfleet demo`: a coordinator and one agent per robot in one process.

use super::{Overrides, RerunArgs, ScenarioRef, init_logging, positive, runtime, speed};
use agent::planner::PlannerSpec;
use anyhow::Result;
use coordinator::serve::demo::{DemoOptions, Transport, run_demo, status_line, summary};
use coordinator::serve::journal::{Header, Journal};
use coordinator::site::TemporarySite;
use std::io::IsTerminal;
use world_sim::scenario::Scenario;

/// `gapfleet demo`'s arguments.
#[derive(Debug, clap::Args)]
pub struct DemoArgs {
    /// Robots, one agent each [default: the scenario's; 8 in the built-in warehouse].
    #[arg(long)]
    robots: Option<usize>,
    /// People [default: the scenario's; 40 in the built-in warehouse].
    #[arg(long)]
    humans: Option<usize>,
    /// Simulated seconds.
    #[arg(long, default_value_t = 60.0, value_parser = positive)]
    seconds: f64,
    /// Seed of the world [default: the scenario's; 1 in the built-in warehouse].
    #[arg(long)]
    seed: Option<u64>,
    /// Planner stack of every agent.
    #[arg(long, default_value = agent::planner::PlannerSpec::FLEET)]
    planner: PlannerSpec,
    /// Simulated seconds per wall second, in [0.001, 1000].
    #[arg(long, default_value_t = 1.0, value_parser = speed)]
    speed: f64,
    /// Built-in warehouse scenario or a scenario file.
    #[arg(long, default_value = "warehouse")]
    scenario: ScenarioRef,
    /// Where the coordinator listens (default: a free port on 127.0.0.1), e.g. to attach a
    /// Python client: tcp/127.0.0.1:7447.
    #[arg(long)]
    listen: Option<String>,
    /// Site name.
    #[arg(long, default_value = "demo")]
    site: schemas::Keys,
    /// Secure the fleet as a deployed site would be (`gapfleet site init` into a temporary
    /// folder): mutual TLS on every link, user/password authentication, and an access-control
    /// list that lets each agent use only its own robot's keys. Not with --listen.
    #[arg(long, conflicts_with = "listen")]
    secure: bool,
    /// Keep the run's inputs and events in DIR (a new folder), so that `gapfleet replay DIR`
    /// re-runs it bit for bit (coordinator/README.md, Journal).
    #[arg(long, value_name = "DIR")]
    state: Option<std::path::PathBuf>,
    /// Do not put other robots' intents into observations.
    #[arg(long)]
    no_intent_sharing: bool,
    #[command(flatten)]
    policy: super::PolicyArgs,
    /// Run the planners' commands without the safety layer (agent/README.md), as the papers'
    /// planners run (as does a scenario whose `[robot]` says `safety = false`).
    #[arg(long)]
    no_safety: bool,
    /// Play every robot as a ROS 2 robot over rmw_zenoh (namespace `/robot<i>`: odom, scan,
    /// people out, cmd_vel in) and run every agent in ROS mode, driving it through those
    /// topics (schemas/ros2/README.md).
    #[arg(long)]
    ros: bool,
    #[command(flatten)]
    rerun: RerunArgs,
}

impl DemoArgs {
    /// The warehouse to run: the scenario with the counts and seed given on the command line.
    pub fn scenario(&self) -> Result<Scenario> {
        self.scenario.fleet_site(self.overrides())
    }

    fn overrides(&self) -> Overrides {
        Overrides {
            robots: self.robots,
            humans: self.humans,
            seed: self.seed,
            no_safety: self.no_safety,
        }
    }

    /// Runs the demo, printing a live status line and the final metrics table.
    pub fn run(self) -> Result<()> {
        init_logging("warn");
        let scenario = self.scenario()?;
        let (robots, humans) = scenario.fleet_size().unwrap_or((0, 0));
        if !self.planner.avoids_static_obstacles() {
            eprintln!(
                "warning: {} does not see shelves or walls (the foIGP paper models people only); \
                 robots will drive into them",
                self.planner
            );
        }
        // The site's files live as long as the demo runs.
        let site = if self.secure {
            let robots = u32::try_from(robots).unwrap_or(u32::MAX);
            Some(TemporarySite::new(&self.site, robots)?)
        } else {
            None
        };
        let transport = match &site {
            Some(site) => {
                eprintln!(
                    "secured: mutual TLS, user/password and the access-control list; site files in {}",
                    site.paths.dir.display()
                );
                Transport::Secured(site.paths.clone())
            }
            None => Transport::Tcp,
        };
        let journal = match &self.state {
            Some(dir) => Some(Journal::create(
                dir,
                &Header::new(
                    self.site.site(),
                    self.scenario.source(self.overrides()),
                    !self.no_intent_sharing,
                    self.policy.policy(),
                ),
            )?),
            None => None,
        };
        let options = DemoOptions {
            scenario,
            planner: self.planner,
            seconds: self.seconds,
            speed: self.speed,
            keys: self.site,
            listen: self.listen,
            transport,
            journal: journal.as_ref().map(Journal::sink),
            share_intents: !self.no_intent_sharing,
            traffic_policy: self.policy.policy(),
            sinks: self.rerun.sinks(),
            round_trips: None,
            ros: self.ros,
        };
        eprintln!(
            "gapfleet demo: {robots} robots ({}), {humans} people, {} s at {}x; Ctrl-C stops early",
            self.planner, self.seconds, self.speed
        );
        let tty = std::io::stderr().is_terminal();
        let mut printed = 0u64;
        let report = runtime()?.block_on(run_demo(
            options,
            fleet_net::shutdown_signal(),
            |status, _| {
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
        println!("{}", summary(&report, self.planner));
        if let (Some(journal), Some(dir)) = (journal, &self.state) {
            let ticks = journal.finish()?;
            println!(
                "journal: {ticks} ticks in {}; `gapfleet replay {}` re-runs them",
                dir.display(),
                dir.display()
            );
        }
        Ok(())
    }
}
