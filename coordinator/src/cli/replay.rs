//! `gapfleet replay DIR`: a recorded live run re-run in-process from its journal.

use super::{RerunArgs, init_logging};
use anyhow::Result;
use coordinator::serve::dashboard::DashboardObserver;
use coordinator::serve::journal::{Integrity, read, replay};
use coordinator::serve::{Observer, Status};
use std::path::PathBuf;

/// `gapfleet replay`'s arguments.
#[derive(Debug, clap::Args)]
pub struct ReplayArgs {
    /// The folder a `coordinator --state DIR` or `demo --state DIR` run wrote.
    dir: PathBuf,
    /// Print the event log too.
    #[arg(long)]
    events: bool,
    /// Print the task ledger too.
    #[arg(long)]
    tasks: bool,
    #[command(flatten)]
    rerun: RerunArgs,
}

impl ReplayArgs {
    /// Re-runs the journal and reports whether it came out bit for bit as recorded.
    pub fn run(self) -> Result<()> {
        init_logging("warn");
        let recorded = read(&self.dir)?;
        let h = &recorded.header;
        println!(
            "site {:?}, scenario {} ({} robots, {} people overridden), {} ticks recorded{}{}",
            h.site,
            h.scenario.name,
            h.scenario
                .robots
                .map_or("not".to_owned(), |n| n.to_string()),
            h.scenario
                .humans
                .map_or("not".to_owned(), |n| n.to_string()),
            recorded.ticks.len(),
            match recorded.first_tick() {
                0 => String::new(),
                first => format!(
                    " from tick {first} (the journal begins at a snapshot, recovered after damage)"
                ),
            },
            match &recorded.end {
                Some(end) => format!(", ended cleanly after {} ticks", end.ticks),
                None => ", no clean end (the coordinator stopped without one)".to_owned(),
            }
        );
        println!("traffic policy {}", h.policy_text());
        if !h.live.is_empty() {
            let placed: usize = recorded.ticks.iter().map(|t| t.placed.len()).sum();
            println!(
                "real robots {:?}: placed from {placed} reports of their agents",
                h.live
            );
        }
        if recorded.integrity == Integrity::Recovered {
            println!(
                "warning: the journal was damaged on disk: its newest commit does not verify; \
                 the one before does, and it is intact up to tick {} (the file is unchanged)",
                recorded.ticks_run()
            );
        }
        if let Some(end) = &recorded.end
            && end.lost > 0
        {
            println!(
                "warning: the journal dropped {} records while the run went on",
                end.lost
            );
        }
        if self.events {
            for e in &recorded.events {
                println!("tick {:6}  t {:7.1} s  {}", e.tick, e.sim_time, e.event);
            }
        }
        if self.tasks {
            let tick = |t: Option<u64>| t.map_or("-".to_owned(), |t| t.to_string());
            for t in &recorded.tasks {
                println!(
                    "ledger task {}: robot {}, station {} to dock {}, assigned at tick {}, \
                     picked at {}, done at {}",
                    t.task,
                    t.robot,
                    t.pick_station,
                    t.drop_station,
                    t.assigned_tick,
                    tick(t.picked_tick),
                    tick(t.done_tick)
                );
            }
        }
        let sinks = self.rerun.sinks();
        let mut dashboard = None;
        let mut status = Status::default();
        let replayed = replay(&recorded, |fleet, events| {
            if sinks.any() && dashboard.is_none() {
                match DashboardObserver::start(fleet, &sinks, "replay") {
                    Ok(d) => {
                        if let Some(url) = d.web_url() {
                            eprintln!("dashboard: open {url}");
                        }
                        dashboard = Some(d);
                    }
                    Err(e) => eprintln!("dashboard: {e}"),
                }
            }
            if let Some(d) = &mut dashboard {
                status.robots = fleet.robots();
                status.tick += 1;
                status.sim_time = fleet.world.time;
                d.tick(fleet, &status, events);
            }
        })?;
        if let Some(d) = dashboard {
            let stats = d.finish();
            eprintln!(
                "dashboard: {} frames logged, {} dropped",
                stats.logged, stats.dropped
            );
        }
        println!(
            "replayed {} ticks{}: {} tasks done, fingerprint {:016x}; {} fingerprints and {} \
             snapshots on the way, the final fingerprint and the ledger's {} tasks match the \
             recorded run",
            replayed.ticks - replayed.from,
            match replayed.from {
                0 => String::new(),
                from => format!(
                    " from the snapshot of tick {from} to tick {}",
                    replayed.ticks
                ),
            },
            replayed.tasks_done,
            replayed.fingerprint,
            replayed.checked,
            replayed.snapshots_checked,
            replayed.tasks_checked
        );
        if let Some(end) = &recorded.end {
            println!(
                "recorded: {} ticks, {} tasks done, fingerprint {:016x}",
                end.ticks, end.tasks_done, end.fingerprint
            );
        }
        Ok(())
    }
}
