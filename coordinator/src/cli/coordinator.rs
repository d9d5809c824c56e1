//! `gapfleet coordinator`: the warehouse world served to `gapfleet-agent` processes over Zenoh.

use super::{RerunArgs, RobotSet, SiteArgs, init_logging, positive, runtime, speed};
use anyhow::Result;
use coordinator::serve::dashboard::{DashboardObserver, HUMAN_IMPACT_WINDOW_S};
use coordinator::serve::demo::status_line;
use coordinator::serve::journal::{self, Header, Journal};
use coordinator::serve::{CoordinatorConfig, Event, Resume, Status, run_coordinator};
use fleet_net::{NetArgs, Role, config};
use world_sim::fleet::Fleet;

/// `gapfleet coordinator`'s arguments.
#[derive(Debug, clap::Args)]
pub struct CoordinatorArgs {
    #[command(flatten)]
    site_args: SiteArgs,
    /// Simulated seconds per wall second, in [0.001, 1000].
    #[arg(long, default_value_t = 1.0, value_parser = speed)]
    speed: f64,
    /// Stop after this many simulated seconds (default: run until SIGINT/SIGTERM).
    #[arg(long, value_parser = positive)]
    seconds: Option<f64>,
    /// Site name.
    #[arg(long, default_value = "demo")]
    site: schemas::Keys,
    /// Do not put other robots' intents into observations.
    #[arg(long)]
    no_intent_sharing: bool,
    #[command(flatten)]
    policy: super::PolicyArgs,
    /// Keep the run's inputs and events in DIR, so that `gapfleet replay DIR` re-runs it bit
    /// for bit; on a DIR that holds a run of the same site and scenario, go on with that run
    /// where its journal ends (after a crash, say). See coordinator/README.md, Journal.
    #[arg(long, value_name = "DIR")]
    state: Option<std::path::PathBuf>,
    /// With --state: if its journal is damaged, keep the damaged file beside it
    /// (`state.redb.damaged`) and go on from its newest intact commit or from the newest intact
    /// snapshot file in DIR/snapshots (whichever is further on), or begin a new journal when
    /// neither exists. Without this flag a damaged journal stops the start, with what is wrong.
    #[arg(long, requires = "state")]
    recover_state: bool,
    /// The planner the site's agents run: the fleet's efficiency is measured against one robot
    /// alone on the site with it (the free flow, run in-process beside the run; efficiency
    /// shows once it is in).
    #[arg(long, default_value = agent::planner::PlannerSpec::FLEET)]
    free_flow_planner: agent::planner::PlannerSpec,
    /// Real robots the coordinator does not simulate: `all`, or ids such as `0-3,6`. Each
    /// stands where its agent reports it (an agent driving a ROS 2 robot, `gapfleet-agent
    /// --ros --robot-id`); one whose reports stop is lost (held, no tasks) until they return.
    /// With `--humans 0` the coordinator simulates nothing at all.
    #[arg(long, default_value = "none", value_name = "ROBOTS")]
    live: RobotSet,
    #[command(flatten)]
    net: NetArgs,
    #[command(flatten)]
    rerun: RerunArgs,
}

impl CoordinatorArgs {
    /// Serves the fleet until the time is up or SIGINT/SIGTERM.
    pub fn run(self) -> Result<()> {
        init_logging("info,zenoh=warn");
        let overrides = self.site_args.overrides();
        let scenario = self.site_args.scenario()?;
        let live = self
            .live
            .ids(scenario.fleet_size().map_or(0, |(robots, _)| robots))?;
        // A folder with a journal: the run goes on from it, from its newest snapshot and the
        // ticks after it.
        let (journal, recorded) = match &self.state {
            Some(dir) => {
                if self.recover_state {
                    match journal::recover(dir)? {
                        journal::Recovery::Intact => {}
                        journal::Recovery::Restored { kept, ticks } => eprintln!(
                            "journal damaged: kept at {}; going on from its newest intact \
                             commit ({ticks} ticks)",
                            kept.display()
                        ),
                        journal::Recovery::FromSnapshot {
                            kept,
                            snapshot,
                            ticks,
                            what,
                        } => eprintln!(
                            "journal damaged ({what}): kept at {}; a new journal begins at the \
                             newest intact snapshot, {} ({ticks} ticks), and the run goes on \
                             from it",
                            kept.display(),
                            snapshot.display()
                        ),
                        journal::Recovery::Kept { kept, what } => eprintln!(
                            "journal damaged beyond repair ({what}): kept at {}; beginning a \
                             new journal, the run starts anew",
                            kept.display()
                        ),
                    }
                }
                let header = Header::new(
                    self.site.site(),
                    self.site_args.scenario.source(overrides),
                    !self.no_intent_sharing,
                    self.policy.policy(),
                )
                .with_live(live.clone());
                let (journal, recorded) = Journal::open(dir, &header)?;
                (Some(journal), recorded)
            }
            None => (None, None),
        };
        let mut net = self.net.clone();
        if net.listen.is_empty() && net.connect.is_empty() && net.zenoh_config.is_none() {
            net.listen.push("tcp/127.0.0.1:7447".to_owned());
        }
        let mut resume = None;
        let mut fleet = match &recorded {
            Some(recorded) => {
                let started = std::time::Instant::now();
                let replayed = journal::resume(recorded)?;
                eprintln!(
                    "resuming at tick {}, {} tasks done: snapshot of tick {} restored, {} ticks \
                     replayed from the journal in {:.2} s ({} fingerprints checked)",
                    replayed.ticks,
                    replayed.tasks_done,
                    replayed.from,
                    replayed.ticks - replayed.from,
                    started.elapsed().as_secs_f64(),
                    replayed.checked
                );
                resume = Some(Resume {
                    tick: replayed.ticks,
                    tasks_done: replayed.tasks_done,
                });
                replayed.fleet
            }
            None => Fleet::new(&scenario)?,
        };
        fleet.share_intents = !self.no_intent_sharing;
        if recorded.is_none() {
            fleet.set_traffic_policy(self.policy.policy());
        }
        let mut config_ = CoordinatorConfig::new(self.site.clone());
        config_.speed = self.speed;
        config_.seconds = self.seconds;
        config_.journal = journal.as_ref().map(Journal::sink);
        config_.resume = resume;
        config_.live = live.clone();
        config_.safety_layer = scenario.robot.safety_layer;
        // The free flow (one robot alone, for the efficiency) is measured beside the run, so
        // that a start or a restart does not wait for it; efficiency shows once it is in.
        {
            let (slot, planner, seconds) = (
                config_.free_flow.clone(),
                self.free_flow_planner,
                self.seconds,
            );
            let (scenario, share, policy) = (
                scenario.clone(),
                fleet.share_intents,
                fleet.traffic_policy().map(|p| p.params),
            );
            std::thread::Builder::new()
                .name("free-flow".to_owned())
                .spawn(move || {
                    match coordinator::serve::free_flow(&scenario, planner, share, policy, seconds)
                    {
                        Ok(free) => {
                            eprintln!(
                                "free flow (one robot alone, {planner}): {} tasks in {:.0} s, \
                                 {:.2} per minute",
                                free.tasks,
                                free.seconds,
                                free.tasks_per_min()
                            );
                            let _ = slot.set(free);
                        }
                        Err(e) => eprintln!("free flow not measured, no efficiency: {e}"),
                    }
                })?;
        }
        runtime()?.block_on(async {
            let session = zenoh::open(config(&net, Role::Router)?)
                .await
                .map_err(|e| anyhow::anyhow!("cannot open the Zenoh session: {e}"))?;
            eprintln!(
                "gapfleet coordinator: site {:?}, {} robots ({} real), {} people, listening {:?} connecting {:?}",
                self.site.site(),
                fleet.robots(),
                live.len(),
                fleet.world.humans.crowd.len(),
                net.listen,
                net.connect
            );
            let mut seen_events = 0;
            let log = |status: &Status, _: &Fleet| {
                for event in status.events_since(seen_events) {
                    if !matches!(event, Event::TaskDone { .. }) {
                        eprintln!("event: {event:?}");
                    }
                }
                seen_events = status.events_total();
                eprintln!("{}", status_line(status));
            };
            let sinks = self.rerun.sinks();
            let dashboard = if sinks.any() {
                fleet.measure_human_impact(HUMAN_IMPACT_WINDOW_S);
                let d = DashboardObserver::start(&fleet, &sinks, "agent")?;
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
                fleet_net::shutdown_signal(),
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
            if let (Some(journal), Some(dir)) = (journal, &self.state) {
                let ticks = journal.finish()?;
                eprintln!("journal: {ticks} ticks in {}", dir.display());
            }
            Ok(())
        })
    }
}
