//! The robots' hardware, played by the simulator (`gapfleet hardware`): a site's world of
//! people and robots in which every robot it plays is a ROS 2 robot over rmw_zenoh
//! ([`super::ros_robots`]), driven by its `cmd_vel` and nothing else. It runs no tasks, no
//! traffic policy and no agent links: those belong to the agents (`gapfleet-agent --ros
//! --robot-id`) and to a coordinator that simulates no robot (`gapfleet coordinator --live`),
//! as on a real site.
//!
//! A robot another process plays is parked off the site ([`PARKED_AT`]), where nothing it
//! plays can see or meet it.

use super::messages::{map_message, observation};
use super::ros_robots::{RosRobots, RosSimConfig};
use agent::math::Vec2;
use agent::model::Command;
use std::future::Future;
use std::time::Duration;
use world_sim::fleet::{Fleet, FleetSummary};

/// Where a robot this process does not play stands (m): far off any site, beyond every
/// sensor.
pub const PARKED_AT: (f64, f64) = (-1.0e5, -1.0e5);

/// How the hardware runs.
#[derive(Debug, Clone)]
pub struct HardwareConfig {
    /// Simulated seconds per wall second.
    pub speed: f64,
    /// Stop after this many simulated seconds (None: until shutdown).
    pub seconds: Option<f64>,
    /// The robots this process plays (by id); the others are parked.
    pub played: Vec<bool>,
    /// How the robots appear on ROS 2.
    pub ros: RosSimConfig,
    /// The robots' clock at simulated time 0 (s): their stamps are this plus the simulated
    /// time. Robots stamp with their own clock (a ROS 2 robot's is the Unix time), not the
    /// coordinator's; `gapfleet hardware` takes the Unix time at its start.
    pub clock_offset_s: f64,
}

/// What the hardware saw, for its summary.
#[derive(Debug, Clone, Default)]
pub struct HardwareReport {
    /// Simulated seconds run.
    pub sim_time: f64,
    /// Ticks run.
    pub ticks: u64,
    /// Robot-ticks driven on a fresh `cmd_vel`.
    pub driven: u64,
    /// Robot-ticks stood still for want of one (none yet, or older than the watchdog's).
    pub starved: u64,
    /// Robot-ticks driven on the same `cmd_vel` as the tick before, none newer having come in
    /// time: the command planned on the newest state came too late, or none was planned for
    /// this tick (an agent plans at its coordinator's rate, not the hardware's). Either way,
    /// one tick of actuation latency.
    pub repeated: u64,
    /// `cmd_vel` messages a newer one replaced before any tick drove on them.
    pub overtaken: u64,
    /// The played robots' figures (`world_sim::fleet::FleetSummary`): contacts, metres
    /// driven, the closest any came to a person, their mean SVR.
    pub played: FleetSummary,
    /// `cmd_vel` payloads refused.
    pub rejected: u64,
}

/// Runs the hardware on `session` until `config.seconds` or `shutdown`, calling `status` about
/// once per wall second.
pub async fn run_hardware(
    session: &zenoh::Session,
    mut fleet: Fleet,
    config: HardwareConfig,
    shutdown: impl Future<Output = ()>,
    mut status: impl FnMut(&HardwareReport),
) -> Result<HardwareReport, super::CoordinatorError> {
    let n = fleet.robots();
    let played: Vec<bool> = (0..n)
        .map(|i| config.played.get(i).copied().unwrap_or(false))
        .collect();
    for (i, &plays) in played.iter().enumerate() {
        if !plays {
            fleet.set_external(i, true);
            fleet.place(
                i,
                Vec2::new(PARKED_AT.0, PARKED_AT.1),
                0.0,
                Vec2::zeros(),
                0.0,
            );
        }
    }
    // Observations become ROS 2 topics here: the version names the map, not a layer setting.
    let version = map_message(&fleet, &agent::safety::SafetyParams::default()).map_version;
    let mut ros = RosRobots::declare_some(session, &played, fleet.world.map.clone(), &config.ros)
        .await
        .map_err(|(what, source)| super::CoordinatorError::Ros { what, source })?;
    ros.clock_offset_s = config.clock_offset_s;
    let dt = fleet.world.dt;
    let tick_wall = Duration::from_secs_f64(dt / config.speed);
    let mut ticker = tokio::time::interval(tick_wall);
    ticker.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    let end_tick = config.seconds.map(|s| (s / dt).round() as u64);
    let mut report = HardwareReport::default();
    let mut last_status = std::time::Instant::now();
    let mut commands = vec![Command::STOP; n];
    let mut received = vec![0_u64; n];
    tokio::pin!(shutdown);
    loop {
        tokio::select! {
            biased;
            () = &mut shutdown => break,
            _ = ticker.tick() => {}
        }
        if end_tick.is_some_and(|end| report.ticks >= end) {
            break;
        }
        for i in (0..n).filter(|&i| played[i]) {
            let heading = fleet.world.robots[i].state.heading;
            let count = ros.commands_received(i);
            let new = count - received[i];
            received[i] = count;
            commands[i] = match ros.command(i, heading) {
                Some(command) => {
                    report.driven += 1;
                    match new {
                        0 => report.repeated += 1,
                        k => report.overtaken += k - 1,
                    }
                    command
                }
                None => {
                    report.starved += 1;
                    Command::STOP
                }
            };
        }
        fleet.step(&commands);
        report.ticks += 1;
        for i in (0..n).filter(|&i| played[i]) {
            let obs = observation(&mut fleet, i, report.ticks, version);
            ros.publish(&obs).await;
        }
        report.sim_time = fleet.world.time;
        if last_status.elapsed() >= Duration::from_secs(1) {
            last_status = std::time::Instant::now();
            tally(&fleet, &played, &ros, &mut report);
            status(&report);
        }
    }
    tally(&fleet, &played, &ros, &mut report);
    Ok(report)
}

/// The report's counters from the fleet's metrics of the played robots.
fn tally(fleet: &Fleet, played: &[bool], ros: &RosRobots, report: &mut HardwareReport) {
    report.sim_time = fleet.world.time;
    report.played = FleetSummary::of_robots(fleet, |i| played[i]);
    report.rejected = ros.rejected.load(std::sync::atomic::Ordering::Relaxed);
}
