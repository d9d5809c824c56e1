//! The coordinator's bookkeeping per robot (is its agent alive, its newest command, the
//! observations it has yet to answer) and what arrives from the agents: liveliness changes and
//! commands.

use super::status::{CoordinatorConfig, Event, RoundTrip, Status};
use agent::model::Command;
use agent::runtime::{percentile, wire};
use schemas::{CommandMsg, Keys, RobotState, SafetyZone, decode};
use std::collections::VecDeque;
use std::time::Instant;
use world_sim::fleet::Fleet;
use zenoh::sample::{Sample, SampleKind};

/// Round-trip samples kept (the oldest half is dropped beyond this).
const MAX_ROUND_TRIP_SAMPLES: usize = 400_000;

/// Recent observations kept per robot for matching their commands.
const SENT_KEPT: usize = 16;

/// Per-robot bookkeeping.
#[derive(Debug, Clone, Default)]
pub(super) struct Link {
    pub(super) alive: bool,
    pub(super) flagged: bool,
    /// The agent's token went in an earlier tick and the exit is not yet classed: its last
    /// command (a safe stop, if it shut down cleanly) may still be on its way, as data and
    /// liveliness travel on different priorities and need not arrive in order.
    leaving: bool,
    /// Newest command: the observation it answers, the command, whether it was a safe stop.
    pub(super) command: Option<(u64, Command, bool)>,
    /// Next observation sequence number.
    pub(super) next_seq: u64,
    /// Recent observations: sequence number, wall time published, whether answered.
    sent: VecDeque<(u64, Instant, bool)>,
    /// A real robot's newest state report, not yet placed in the fleet.
    pub(super) report: Option<RobotState>,
    /// When the newest state report arrived.
    reported_at: Option<Instant>,
    /// When the agent's token last came.
    joined_at: Option<Instant>,
    /// A real robot whose agent stopped reporting its state.
    pub(super) lost: bool,
}

impl Link {
    /// The newest command if at most `stale_ticks` observations newer than the one it
    /// answers have gone out, and it is not a safe stop.
    pub(super) fn fresh_command(&self, stale_ticks: u64) -> Option<Command> {
        self.command
            .filter(|c| !c.2 && self.unanswered() <= stale_ticks)
            .map(|c| c.1)
    }

    /// Observations sent after the one the newest command answers (all of them before the
    /// first command).
    pub(super) fn unanswered(&self) -> u64 {
        self.command
            .map_or(self.next_seq, |c| self.next_seq.saturating_sub(c.0 + 1))
    }

    /// Records observation `seq` as published now.
    pub(super) fn sent(&mut self, seq: u64) {
        self.next_seq += 1;
        self.sent.push_back((seq, Instant::now(), false));
        if self.sent.len() > SENT_KEPT {
            self.sent.pop_front();
        }
    }
}

/// Round trips timed so far (µs, in arrival order) and where each one goes as it is counted.
#[derive(Debug)]
pub(super) struct RoundTrips {
    pub(super) us: Vec<u32>,
    log: Option<std::sync::mpsc::Sender<RoundTrip>>,
}

impl RoundTrips {
    pub(super) fn new(log: Option<std::sync::mpsc::Sender<RoundTrip>>) -> Self {
        Self {
            us: Vec::new(),
            log,
        }
    }

    fn record(&mut self, trip: RoundTrip) {
        let us = trip
            .arrived
            .saturating_duration_since(trip.published)
            .as_micros();
        if self.us.len() >= MAX_ROUND_TRIP_SAMPLES {
            self.us.drain(..MAX_ROUND_TRIP_SAMPLES / 2);
        }
        self.us.push(us.min(u32::MAX as u128) as u32);
        if let Some(log) = &self.log {
            let _ = log.send(trip);
        }
    }
}

/// Counts a rejected message and logs why (the first ten, then every hundredth).
pub(super) fn reject(status: &mut Status, why: std::fmt::Arguments<'_>) {
    status.rejected += 1;
    if fleet_net::log_rejection(status.rejected) {
        tracing::warn!(rejected = status.rejected, "rejected: {why}");
    }
}

/// Tells the status and the event channel that `event` happened.
pub(super) fn emit(status: &mut Status, config: &CoordinatorConfig, event: Event) {
    if let Some(journal) = &config.journal {
        journal.event(super::journal::EventRecord {
            tick: status.tick,
            sim_time: status.sim_time,
            event: format!("{event:?}"),
        });
    }
    if let Some(tx) = &config.events {
        let _ = tx.send((Instant::now(), event.clone()));
    }
    status.push_event(event);
}

/// An agent's liveliness token came (its robot is released) or went (its robot is held and
/// flagged at once; whether it left cleanly or crashed is decided a tick later, by
/// [`settle_exits`]).
pub(super) fn liveliness_change(
    sample: &Sample,
    keys: &Keys,
    links: &mut [Link],
    fleet: &mut Fleet,
    status: &mut Status,
    config: &CoordinatorConfig,
) {
    let Some(id) = keys.parse_alive(sample.key_expr().as_str()) else {
        return;
    };
    let n = links.len();
    let Some(link) = links.get_mut(id as usize) else {
        reject(
            status,
            format_args!("agent {id} has no robot here ({n} robots)"),
        );
        return;
    };
    match sample.kind() {
        SampleKind::Put => {
            if link.leaving {
                settle_exit(id, link, status, config);
            }
            link.alive = true;
            link.flagged = false;
            link.command = None;
            link.joined_at = Some(Instant::now());
            link.lost = false;
            // A new agent: what an earlier one reported is not its robot's state.
            link.report = None;
            link.reported_at = None;
            fleet.set_held(id as usize, false);
            tracing::info!(robot = id, "agent joined");
            emit(status, config, Event::Joined(id));
        }
        SampleKind::Delete => {
            link.alive = false;
            link.flagged = true;
            link.leaving = true;
            link.lost = false;
            fleet.set_held(id as usize, true);
        }
    }
}

/// Classes the exits of agents whose tokens went in an earlier tick, after this tick's
/// commands are in: a clean leave if the last command was a safe stop, a crash otherwise.
pub(super) fn settle_exits(links: &mut [Link], status: &mut Status, config: &CoordinatorConfig) {
    for (id, link) in links.iter_mut().enumerate() {
        if link.leaving {
            settle_exit(id as u32, link, status, config);
        }
    }
}

fn settle_exit(id: u32, link: &mut Link, status: &mut Status, config: &CoordinatorConfig) {
    link.leaving = false;
    let event = if link.command.is_some_and(|c| c.2) {
        Event::Left(id)
    } else {
        Event::Crashed(id)
    };
    tracing::warn!(
        robot = id,
        "agent gone: {event:?}; robot stopped and flagged"
    );
    emit(status, config, event);
}

/// Real robots (`config.live`) with a live agent: one that reports its state is released
/// (it gets tasks); one whose agent has reported nothing for `config.lost_after` since its
/// last report or its joining is held and flagged lost, until its reports come back. A
/// robot's first report releases it without an event; before it, it is held.
pub(super) fn watch_reports(
    links: &mut [Link],
    fleet: &mut Fleet,
    status: &mut Status,
    config: &CoordinatorConfig,
    now: Instant,
) {
    for &id in &config.live {
        let Some(link) = links.get_mut(id as usize) else {
            continue;
        };
        if !link.alive {
            continue;
        }
        let within = |t: Option<Instant>| {
            t.is_some_and(|t| now.saturating_duration_since(t) <= config.lost_after)
        };
        if within(link.reported_at) {
            fleet.set_held(id as usize, false);
            if link.lost {
                link.lost = false;
                tracing::info!(robot = id, "robot reports again: released");
                emit(status, config, Event::Found(id));
            }
        } else {
            fleet.set_held(id as usize, true);
            // A robot that never reported has from its joining to do so.
            let waiting = link.reported_at.is_none() && within(link.joined_at);
            if !link.lost && !waiting {
                link.lost = true;
                let never = if link.reported_at.is_none() {
                    " (it never did: is its agent driving a real robot, `--ros`?)"
                } else {
                    ""
                };
                tracing::warn!(
                    robot = id,
                    "robot lost: no state report for {:?}{never}; held",
                    config.lost_after
                );
                emit(status, config, Event::Lost(id));
            }
        }
    }
}

/// Takes in every command that arrived: the newest per robot is kept; answers to recent
/// observations are counted once and timed.
pub(super) fn take_commands(
    cmd_rx: &std::sync::mpsc::Receiver<(Instant, Sample)>,
    keys: &Keys,
    links: &mut [Link],
    status: &mut Status,
    round_trips: &mut RoundTrips,
) {
    while let Ok((arrived, sample)) = cmd_rx.try_recv() {
        let key_id = keys.parse_robot(sample.key_expr().as_str()).map(|k| k.0);
        let bytes = sample.payload().to_bytes();
        take_command(key_id, &bytes, arrived, links, status, round_trips);
    }
}

/// One command, `bytes`, that arrived on robot `key_id`'s key. Rejected (and counted) when it
/// does not decode, names another robot or one that is not here, or answers an observation
/// not yet sent (a forged future sequence number would otherwise lock out the agent's real
/// commands, which answer older ones).
fn take_command(
    key_id: Option<u32>,
    bytes: &[u8],
    arrived: Instant,
    links: &mut [Link],
    status: &mut Status,
    round_trips: &mut RoundTrips,
) {
    let n = links.len();
    let cmd = match decode::<CommandMsg>(bytes) {
        Ok(cmd) => cmd,
        Err(e) => {
            reject(
                status,
                format_args!("command on robot {key_id:?}'s key: {e}"),
            );
            return;
        }
    };
    let link = match links.get_mut(cmd.robot_id as usize) {
        Some(link) if Some(cmd.robot_id) == key_id && cmd.obs_seq < link.next_seq => link,
        _ => {
            reject(
                status,
                format_args!(
                    "command for robot {} answering observation {}: wrong key ({key_id:?}), no \
                     such robot ({n} here), or an observation not yet sent",
                    cmd.robot_id, cmd.obs_seq
                ),
            );
            return;
        }
    };
    status.commands += 1;
    if let Some(state) = cmd.state {
        link.report = Some(state);
        // The robot was last heard from when the odometry behind the report arrived.
        let age = std::time::Duration::from_secs_f64(state.age);
        link.reported_at = Some(arrived.checked_sub(age).unwrap_or(arrived));
    }
    if let Some(entry) = link.sent.iter_mut().find(|e| e.0 == cmd.obs_seq)
        && !entry.2
        && !cmd.safe_stop
    {
        entry.2 = true;
        status.answered += 1;
        round_trips.record(RoundTrip {
            robot: cmd.robot_id,
            published: entry.1,
            arrived,
        });
    }
    if link.command.is_none_or(|c| cmd.obs_seq >= c.0) {
        link.command = Some((cmd.obs_seq, wire::command(cmd.motion), cmd.safe_stop));
        status.safety.resize(n, SafetyZone::Clear);
        status.safety[cmd.robot_id as usize] = cmd.safety;
    }
}

/// Updates the derived fields; round trips are kept in arrival order (percentiles sort a copy).
pub(super) fn refresh(status: &mut Status, links: &[Link], round_trips_us: &[u32]) {
    status.alive = links.iter().filter(|l| l.alive).count();
    status.flagged = (0..links.len() as u32)
        .filter(|&i| links[i as usize].flagged)
        .collect();
    status.lost = (0..links.len() as u32)
        .filter(|&i| links[i as usize].lost)
        .collect();
    let mut sorted = round_trips_us.to_vec();
    status.round_trip_ms = (
        percentile(&mut sorted, 0.5) / 1000.0,
        percentile(&mut sorted, 0.99) / 1000.0,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use schemas::{Motion, P2, encode};

    fn command(robot_id: u32, obs_seq: u64, vx: f64) -> Vec<u8> {
        encode(&CommandMsg {
            robot_id,
            obs_seq,
            stamp: 0.0,
            motion: Motion::Velocity(P2(vx, 0.0)),
            safe_stop: false,
            safety: SafetyZone::Clear,
            state: None,
        })
    }

    /// A command answering an observation not yet sent (a forged far-future sequence
    /// number, u64::MAX included) is rejected and counted, and the agent's real commands
    /// still get through; so are commands on another robot's key or for a robot not here.
    #[test]
    fn a_command_for_an_observation_not_yet_sent_is_rejected() {
        let mut links = vec![Link::default(); 2];
        let mut status = Status::default();
        let mut trips = RoundTrips::new(None);
        for seq in 0..3 {
            links[0].sent(seq);
        }
        let now = Instant::now();
        let mut take = |key: Option<u32>, bytes: &[u8], links: &mut [Link], status: &mut Status| {
            take_command(key, bytes, now, links, status, &mut trips);
        };
        take(Some(0), &command(0, 3, 9.0), &mut links, &mut status);
        take(Some(0), &command(0, u64::MAX, 9.0), &mut links, &mut status);
        assert_eq!((status.rejected, status.commands), (2, 0));
        assert!(links[0].command.is_none());
        take(Some(0), &command(0, 2, 0.5), &mut links, &mut status);
        assert_eq!((status.commands, status.answered), (1, 1));
        let fresh = links[0].fresh_command(5).expect("the real command");
        assert_eq!(fresh, wire::command(Motion::Velocity(P2(0.5, 0.0))));
        // Another robot's key, a robot not here, bytes that do not decode.
        take(Some(1), &command(0, 1, 9.0), &mut links, &mut status);
        take(Some(7), &command(7, 0, 9.0), &mut links, &mut status);
        take(Some(0), b"\x93garbage", &mut links, &mut status);
        assert_eq!(status.rejected, 5);
        assert_eq!(links[0].fresh_command(5), Some(fresh));
    }

    /// A real robot is released by its first report, lost 0.5 s after the odometry behind its
    /// newest report (not after the report's arrival), found again by a new report; one that
    /// never reports is lost 0.5 s after joining. Simulated robots are never lost.
    #[test]
    fn real_robots_are_lost_when_their_reports_stop_and_found_when_they_return() {
        let scenario = world_sim::scenario::Scenario::builtin("warehouse").expect("built in");
        let mut fleet = Fleet::new(&scenario).expect("a warehouse");
        let mut config =
            CoordinatorConfig::new(schemas::Keys::new("test").expect("a valid site name"));
        config.live = vec![0, 1];
        let mut links = vec![Link::default(); fleet.robots()];
        let mut status = Status::default();
        let mut trips = RoundTrips::new(None);
        let t0 = Instant::now();
        let ms = |n: u64| std::time::Duration::from_millis(n);
        for (i, link) in links.iter_mut().enumerate().take(3) {
            link.alive = true;
            link.joined_at = Some(t0);
            fleet.set_held(i, false);
            link.sent(0);
        }
        let report = |age: f64| {
            encode(&CommandMsg {
                state: Some(schemas::RobotState {
                    p: P2(1.0, 2.0),
                    heading: 0.0,
                    vel: P2(0.0, 0.0),
                    yaw_rate: 0.0,
                    age,
                }),
                ..CommandMsg {
                    robot_id: 0,
                    obs_seq: 0,
                    stamp: 0.0,
                    motion: Motion::Velocity(P2(0.0, 0.0)),
                    safe_stop: false,
                    safety: SafetyZone::Clear,
                    state: None,
                }
            })
        };
        // Robot 0 reports at once, from odometry 0.2 s old; robot 1 never does.
        take_command(
            Some(0),
            &report(0.2),
            t0,
            &mut links,
            &mut status,
            &mut trips,
        );
        let watch = |now, links: &mut [Link], fleet: &mut Fleet, status: &mut Status| {
            watch_reports(links, fleet, status, &config, now);
        };
        watch(t0 + ms(100), &mut links, &mut fleet, &mut status);
        assert!(!fleet.is_held(0), "released by its report");
        assert!(fleet.is_held(1), "held until its first report");
        assert!(status.events.is_empty());
        // 0.5 s after robot 0's odometry (0.3 s after its report arrived): lost. Robot 1,
        // 0.6 s after joining with no report: lost. Robot 2 is simulated: never lost.
        watch(t0 + ms(290), &mut links, &mut fleet, &mut status);
        assert!(status.events.is_empty(), "{:?}", status.events);
        watch(t0 + ms(310), &mut links, &mut fleet, &mut status);
        assert_eq!(status.events, vec![Event::Lost(0)]);
        watch(t0 + ms(600), &mut links, &mut fleet, &mut status);
        assert_eq!(status.events, vec![Event::Lost(0), Event::Lost(1)]);
        assert!(fleet.is_held(0) && fleet.is_held(1) && !fleet.is_held(2));
        // Robot 0 reports again: found and released, once.
        let back = t0 + ms(900);
        take_command(
            Some(0),
            &report(0.0),
            back,
            &mut links,
            &mut status,
            &mut trips,
        );
        watch(back, &mut links, &mut fleet, &mut status);
        watch(back + ms(100), &mut links, &mut fleet, &mut status);
        assert_eq!(
            status.events,
            vec![Event::Lost(0), Event::Lost(1), Event::Found(0)]
        );
        assert!(!fleet.is_held(0));
        assert_eq!(links[0].report.map(|r| r.p), Some(P2(1.0, 2.0)));
    }
}
