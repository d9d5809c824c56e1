//! `gapfleet hardware`: the robots' hardware, played by the simulator, as ROS 2 robots.

use super::{RobotSet, SiteArgs, init_logging, positive, runtime, speed};
use anyhow::Result;
use coordinator::serve::hardware::{HardwareConfig, HardwareReport, run_hardware};
use coordinator::serve::ros_robots::RosSimConfig;
use fleet_net::{NetArgs, Role, config};
use world_sim::fleet::Fleet;

/// `gapfleet hardware`'s arguments.
#[derive(Debug, clap::Args)]
pub struct HardwareArgs {
    #[command(flatten)]
    site_args: SiteArgs,
    /// The robots this process plays: `all`, or ids such as `0-3,6` (the others are parked
    /// off the site, for another hardware process to play).
    #[arg(long, default_value = "all", value_name = "ROBOTS")]
    play: RobotSet,
    /// Simulated seconds per wall second, in [0.001, 1000].
    #[arg(long, default_value_t = 1.0, value_parser = speed)]
    speed: f64,
    /// Stop after this many simulated seconds (default: run until SIGINT/SIGTERM).
    #[arg(long, value_parser = positive)]
    seconds: Option<f64>,
    /// ROS_DOMAIN_ID of the robots.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=232))]
    domain_id: u32,
    /// The robots' ROS 2 distribution: humble, jazzy or kilted (type hashes in keys).
    #[arg(long, default_value = "jazzy")]
    distro: ros2_wire::Distro,
    #[command(flatten)]
    net: NetArgs,
}

/// One line of the hardware's status.
fn status_line(r: &HardwareReport) -> String {
    format!(
        "t {:6.1} s | driven {} starved {} robot-ticks, {} on the tick before's cmd_vel, {} cmd_vel overtaken | {:.0} m | closest person {:.2} m, SVR {:.3} | contacts: robot-caused {} person-caused {} robot-robot {} | cmd_vel refused {}",
        r.sim_time,
        r.driven,
        r.starved,
        r.repeated,
        r.overtaken,
        r.played.path_length_m,
        r.played.min_human_distance_m,
        r.played.svr,
        r.played.robot_caused_contacts,
        r.played.person_caused_contacts,
        r.played.robot_robot_contacts,
        r.rejected
    )
}

impl HardwareArgs {
    /// Plays the robots until the time is up or SIGINT/SIGTERM.
    pub fn run(self) -> Result<()> {
        init_logging("info,zenoh=warn");
        let scenario = self.site_args.scenario()?;
        let fleet = Fleet::new(&scenario)?;
        let n = fleet.robots();
        let mut played = vec![false; n];
        for id in self.play.ids(n)? {
            played[id as usize] = true;
        }
        let mut net = self.net.clone();
        if net.listen.is_empty() && net.connect.is_empty() && net.zenoh_config.is_none() {
            net.connect.push("tcp/127.0.0.1:7447".to_owned());
        }
        let hardware = HardwareConfig {
            speed: self.speed,
            seconds: self.seconds,
            played: played.clone(),
            ros: RosSimConfig {
                domain_id: self.domain_id,
                distro: self.distro,
            },
            // The robots' own clock, as a ROS 2 robot's: the Unix time.
            clock_offset_s: std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0.0, |d| d.as_secs_f64()),
        };
        runtime()?.block_on(async {
            let session = zenoh::open(config(&net, Role::Client)?)
                .await
                .map_err(|e| anyhow::anyhow!("cannot open the Zenoh session: {e}"))?;
            eprintln!(
                "gapfleet hardware: {} of {} robots as ROS 2 robots /robot<i> (domain {}, {}), {} people, connecting {:?}",
                played.iter().filter(|&&p| p).count(),
                n,
                self.domain_id,
                self.distro,
                fleet.world.humans.crowd.len(),
                net.connect
            );
            let report = run_hardware(
                &session,
                fleet,
                hardware,
                fleet_net::shutdown_signal(),
                |r| eprintln!("{}", status_line(r)),
            )
            .await?;
            eprintln!("{}", status_line(&report));
            eprintln!(
                "stopped after {:.1} simulated seconds ({} ticks)",
                report.sim_time, report.ticks
            );
            session
                .close()
                .await
                .map_err(|e| anyhow::anyhow!("closing the session: {e}"))?;
            Ok(())
        })
    }
}
