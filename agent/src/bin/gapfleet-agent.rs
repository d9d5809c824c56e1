//! `gapfleet-agent`: one robot's planner stack as its own process on the fleet's Zenoh network.
//!
//! ```text
//! gapfleet-agent --robot-id 3 --planner pgp+orca --connect tcp/127.0.0.1:7447
//! ```
//! Runs until SIGINT or SIGTERM, then safe-stops its robot and withdraws its liveliness token.
//!
//! With `--ros` it drives a ROS 2 robot over rmw_zenoh (odometry, scan and people in, `cmd_vel`
//! out): in the fleet with `--robot-id` (goals and the other robots' intents from the
//! coordinator), or alone through the goals given:
//!
//! ```text
//! gapfleet-agent --ros --robot-id 1 --namespace /robot1 --connect tcp/<coordinator>:7447
//! gapfleet-agent --ros --namespace /robot1 --base differential --goal 3,0 --goal 3,3
//! ```

use agent::planner::PlannerSpec;
use agent::runtime::{AgentConfig, AgentCounters, run_agent};
use clap::Parser;
use fleet_net::{NetArgs, Role, config};
use std::sync::Arc;
use std::time::Duration;

/// One robot's on-board planner stack.
#[derive(Debug, Parser)]
#[command(version, about)]
struct Args {
    /// The robot this agent drives (its fleet id; not needed with --ros).
    #[arg(long, required_unless_present = "ros")]
    robot_id: Option<u32>,
    /// Planner stack, as agent/README.md lists them: e.g. pnp-right, pgp+orca, orca, dwa, sf,
    /// pnp-agile, asfm or foigp. The foIGP family does not see walls or shelves.
    /// [default: the fleet's, pnp-right, whose candidates are velocities; on `--base
    /// differential` pnp-agile, which plans turn-and-drive]
    #[arg(long)]
    planner: Option<PlannerSpec>,
    /// Site name (key prefix `gapfleet/<site>`).
    #[arg(long, default_value = "demo")]
    site: schemas::Keys,
    /// Safe-stop after this many milliseconds without observations, in [10, 3600000] (0 would
    /// stop the robot for good).
    #[arg(
        long,
        default_value_t = agent::runtime::DEFAULT_OBS_TIMEOUT.as_millis() as u64,
        value_parser = clap::value_parser!(u64).range(10..=3_600_000)
    )]
    obs_timeout_ms: u64,
    /// Publish PGP's candidate fan with every plan, for dashboards (`…/robot/<id>/fan`).
    #[arg(long)]
    share_fan: bool,
    /// Run the planner's commands without the safety layer (its protective and warning
    /// fields; agent/README.md), as the papers' planners run. The layer assumes the simulated
    /// robot's base: 1 m/s, 1.5 m/s² to speed up and to brake.
    #[arg(long)]
    no_safety: bool,
    /// Fault injection for tests: every plan takes this many milliseconds longer (the agent's
    /// thread sleeps, as a planner busy that long would hold it).
    #[arg(long, hide = true, default_value_t = 0, value_parser = clap::value_parser!(u64).range(0..=60_000))]
    fault_plan_delay_ms: u64,
    #[command(flatten)]
    ros: RosArgs,
    #[command(flatten)]
    net: NetArgs,
}

/// Driving a ROS 2 robot over rmw_zenoh (schemas/ros2/README.md).
#[derive(Debug, Clone, clap::Args)]
struct RosArgs {
    /// Drive a ROS 2 robot over rmw_zenoh: in the fleet with --robot-id, or alone through
    /// --goal points.
    #[arg(long)]
    ros: bool,
    /// The robot's namespace; relative topics resolve in it.
    #[arg(long, default_value = "/", requires = "ros")]
    namespace: String,
    /// ROS_DOMAIN_ID.
    #[arg(long, default_value_t = 0, requires = "ros", value_parser = clap::value_parser!(u32).range(0..=232))]
    domain_id: u32,
    /// The robot's ROS 2 distribution: humble, jazzy or kilted (type hashes in keys).
    #[arg(long, default_value = "jazzy", requires = "ros")]
    distro: ros2_wire::Distro,
    /// Publish geometry_msgs/TwistStamped on cmd_vel (Nav2's default since Jazzy) instead of Twist.
    #[arg(long, requires = "ros")]
    stamped_cmd: bool,
    /// The map frame; when odometry is in another frame, map→odom comes from /tf (or from
    /// --pose-topic).
    #[arg(long, default_value = "map", requires = "ros")]
    map_frame: String,
    /// Take map→odom from this geometry_msgs/PoseWithCovarianceStamped topic in the map frame
    /// (AMCL's `amcl_pose`) instead of /tf.
    #[arg(long, requires = "ros")]
    pose_topic: Option<String>,
    /// Where the scanner sits on the base, "x,y,yaw" (m, m, rad), overriding /tf_static.
    #[arg(long, value_parser = parse_mount, requires = "ros", allow_hyphen_values = true)]
    scan_mount: Option<(agent::math::Vec2, f64)>,
    /// The base's drive: holonomic, or differential (velocity commands become turn-and-drive).
    #[arg(long, value_enum, default_value = "holonomic", requires = "ros")]
    base: BaseArg,
    /// A goal in the map frame, "x,y" (repeatable, visited in order; "-1.5,2" works too).
    #[arg(long = "goal", value_parser = parse_goal, requires = "ros", allow_hyphen_values = true)]
    goals: Vec<agent::math::Vec2>,
    /// The robot's body radius (m).
    #[arg(long, default_value_t = 0.3, requires = "ros", value_parser = parse_radius)]
    robot_radius: f64,
    /// A person's body radius (m) for the planners and the safety layer: people_msgs/Person
    /// carries no size. Give the site's (a simulated site's `humans.radius_m`).
    #[arg(long, default_value_t = 0.3, requires = "ros", value_parser = parse_radius)]
    person_radius: f64,
    /// Exit once the last goal is reached (else hold the robot stopped until SIGINT/SIGTERM).
    #[arg(long, requires = "ros")]
    exit_at_last_goal: bool,
}

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum BaseArg {
    Holonomic,
    Differential,
}

/// A body radius: finite, above 0 and at most 2 m.
fn parse_radius(s: &str) -> Result<f64, String> {
    s.trim()
        .parse::<f64>()
        .ok()
        .filter(|r| r.is_finite() && *r > 0.0 && *r <= 2.0)
        .ok_or(format!("`{s}` is not a radius in (0, 2] m"))
}

fn parse_mount(s: &str) -> Result<(agent::math::Vec2, f64), String> {
    let parts: Vec<&str> = s.split(',').collect();
    let [x, y, yaw] = parts[..] else {
        return Err("a scanner mount is x,y,yaw".into());
    };
    let parse = |v: &str, bound: f64| {
        v.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && v.abs() <= bound)
            .ok_or(format!("`{v}` is not a number within ±{bound}"))
    };
    Ok((
        agent::math::Vec2::new(parse(x, 10.0)?, parse(y, 10.0)?),
        parse(yaw, 2.0 * std::f64::consts::PI)?,
    ))
}

fn parse_goal(s: &str) -> Result<agent::math::Vec2, String> {
    let (x, y) = s.split_once(',').ok_or("a goal is x,y")?;
    let parse = |v: &str| {
        v.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && v.abs() <= 1e5)
            .ok_or(format!("`{v}` is not a coordinate within 100 km"))
    };
    Ok(agent::math::Vec2::new(parse(x)?, parse(y)?))
}

#[tokio::main(flavor = "multi_thread", worker_threads = 2)]
async fn main() -> anyhow::Result<()> {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| "info,zenoh=warn".into()),
        )
        .with_writer(std::io::stderr)
        // Colours for a terminal only: a log file gets plain text.
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .init();
    let args = Args::parse();
    let planner = args
        .planner
        .unwrap_or_else(|| default_planner(args.ros.base));
    if !planner.avoids_static_obstacles() {
        tracing::warn!(
            "{planner} does not see shelves or walls (the foIGP paper models people only)"
        );
    }
    let mut net = args.net.clone();
    if net.connect.is_empty() && net.zenoh_config.is_none() {
        net.connect.push("tcp/127.0.0.1:7447".to_owned());
    }
    let session = zenoh::open(config(&net, Role::Client)?)
        .await
        .map_err(|e| anyhow::anyhow!("cannot open the Zenoh session: {e}"))?;
    if args.ros.ros && args.robot_id.is_none() {
        return run_ros(args, planner, &session).await;
    }
    if args.ros.ros && !args.ros.goals.is_empty() {
        anyhow::bail!(
            "--goal is for a robot driven alone; with --robot-id the coordinator gives the goals"
        );
    }
    let Some(robot_id) = args.robot_id else {
        anyhow::bail!("--robot-id is required without --ros");
    };
    let mut agent_config = AgentConfig::new(robot_id, args.site.clone(), planner);
    agent_config.obs_timeout = Duration::from_millis(args.obs_timeout_ms);
    agent_config.share_fan = args.share_fan;
    agent_config.fault_plan_delay = Duration::from_millis(args.fault_plan_delay_ms);
    if args.no_safety {
        agent_config.safety = None;
    }
    if args.ros.ros {
        agent_config.ros = Some(ros_config(&args.ros));
        agent_config.base = base_of(args.ros.base);
    }
    let counters = Arc::new(AgentCounters::default());
    run_agent(
        &session,
        agent_config,
        counters.clone(),
        fleet_net::shutdown_signal(),
    )
    .await?;
    session
        .close()
        .await
        .map_err(|e| anyhow::anyhow!("closing the session: {e}"))?;
    let count = |c: &std::sync::atomic::AtomicU64| c.load(std::sync::atomic::Ordering::Relaxed);
    eprintln!(
        "gapfleet-agent {}: {} plans, {} rejected messages; safety layer: {} slowed, {} protective, {} yields",
        robot_id,
        count(&counters.plans),
        count(&counters.rejected),
        count(&counters.warned),
        count(&counters.protective),
        count(&counters.yielded)
    );
    Ok(())
}

/// The planner an agent runs unless told: the fleet's, or on a differential base `pnp-agile`,
/// whose candidates turn and drive as the base does (agent/README.md).
fn default_planner(base: BaseArg) -> PlannerSpec {
    let name = match base {
        BaseArg::Holonomic => PlannerSpec::FLEET,
        BaseArg::Differential => "pnp-agile",
    };
    name.parse().expect("a known planner")
}

/// The base as the flag gives it (turn rates within the layer's limits).
fn base_of(base: BaseArg) -> agent::model::Base {
    match base {
        BaseArg::Holonomic => agent::model::Base::Holonomic,
        BaseArg::Differential => agent::model::Base::Differential {
            max_yaw_rate: agent::safety::SafetyLimits::SIMULATED_ROBOT.max_yaw_rate,
        },
    }
}

/// The robot's ROS 2 side as the flags give it.
fn ros_config(ros: &RosArgs) -> agent::runtime::ros::RosConfig {
    agent::runtime::ros::RosConfig {
        domain_id: ros.domain_id,
        namespace: ros.namespace.clone(),
        distro: ros.distro,
        stamped_cmd: ros.stamped_cmd,
        map_frame: ros.map_frame.clone(),
        pose_topic: ros.pose_topic.clone(),
        scan_mount: ros.scan_mount,
        robot_radius: ros.robot_radius,
        person_radius: ros.person_radius,
        ..Default::default()
    }
}

/// `--ros` without `--robot-id`: the robot's own topics in, its cmd_vel out, through the goals.
async fn run_ros(args: Args, planner: PlannerSpec, session: &zenoh::Session) -> anyhow::Result<()> {
    use agent::runtime::standalone::{RosAgentConfig, run_ros_agent};
    if args.ros.goals.is_empty() {
        anyhow::bail!("--ros needs --robot-id (in a fleet) or at least one --goal x,y (alone)");
    }
    let limits = agent::safety::SafetyLimits::SIMULATED_ROBOT;
    let base = base_of(args.ros.base);
    let config = RosAgentConfig {
        ros: ros_config(&args.ros),
        planner,
        safety: (!args.no_safety).then_some(limits),
        base,
        goals: args.ros.goals.clone(),
        goal_tolerance: 0.3,
        period: Duration::from_millis(100),
        map: agent::map::StaticMap::empty(),
        scan: agent::scan::ScanParams::default(),
        exit_at_last_goal: args.ros.exit_at_last_goal,
    };
    let goals = config.goals.len();
    let counters = Arc::new(AgentCounters::default());
    let reached = run_ros_agent(
        session,
        config,
        counters.clone(),
        fleet_net::shutdown_signal(),
    )
    .await?;
    let load = |c: &std::sync::atomic::AtomicU64| c.load(std::sync::atomic::Ordering::Relaxed);
    let ros_counters = &counters.ros;
    eprintln!(
        "gapfleet-agent (ROS 2, {}): {reached} of {goals} goals, {} plans, {} odometry, {} scans ({} plans held for the scanner's transform), {} people messages, {} transforms, {} map poses, {} refused, {} commands; safety layer: {} slowed, {} protective, {} yields",
        args.ros.namespace,
        load(&counters.plans),
        load(&ros_counters.odom),
        load(&ros_counters.scans),
        load(&ros_counters.scans_unplaced),
        load(&ros_counters.people),
        load(&ros_counters.tf),
        load(&ros_counters.poses),
        load(&ros_counters.rejected),
        load(&ros_counters.commands),
        load(&counters.warned),
        load(&counters.protective),
        load(&counters.yielded),
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An observation timeout of 0 (the robot would never move) or beyond an hour is refused.
    #[test]
    fn the_observation_timeout_is_bounded() {
        let parse = |ms: &str| {
            Args::try_parse_from(["gapfleet-agent", "--robot-id", "0", "--obs-timeout-ms", ms])
        };
        assert!(parse("0").is_err());
        assert!(parse("9").is_err());
        assert!(parse("3600001").is_err());
        assert_eq!(parse("500").expect("valid").obs_timeout_ms, 500);
    }

    /// `--ros` alone needs goals or a robot id; the ROS flags need `--ros`; goals parse as x,y.
    #[test]
    fn ros_flags_parse() {
        let parse = |args: &[&str]| Args::try_parse_from([&["gapfleet-agent"], args].concat());
        let fleet = parse(&[
            "--ros",
            "--robot-id",
            "2",
            "--namespace",
            "/robot2",
            "--stamped-cmd",
        ])
        .expect("fleet ROS mode");
        assert!(fleet.ros.ros && fleet.ros.stamped_cmd && fleet.robot_id == Some(2));
        let alone = parse(&["--ros", "--goal", "3,0", "--goal", "-1.5, 2"]).expect("alone");
        assert_eq!(alone.ros.goals.len(), 2);
        assert_eq!(alone.ros.goals[1], agent::math::Vec2::new(-1.5, 2.0));
        assert!(
            parse(&["--namespace", "/r"]).is_err(),
            "ROS flags need --ros"
        );
        assert!(parse(&["--ros", "--goal", "1"]).is_err());
        assert!(parse(&["--ros", "--goal", "1,nan"]).is_err());
        assert!(parse(&["--ros", "--distro", "iron", "--goal", "1,1"]).is_err());
    }

    /// People's radius reaches the ROS link (people_msgs has none); a radius must be physical.
    #[test]
    fn person_radius_reaches_the_ros_link() {
        let parse = |args: &[&str]| Args::try_parse_from([&["gapfleet-agent"], args].concat());
        let given = parse(&["--ros", "--robot-id", "0", "--person-radius", "0.35"]).expect("valid");
        assert_eq!(ros_config(&given.ros).person_radius, 0.35);
        let default = parse(&["--ros", "--robot-id", "0"]).expect("valid");
        assert_eq!(ros_config(&default.ros).person_radius, 0.3);
        for bad in ["0", "-0.3", "nan", "inf", "2.5", "wide"] {
            assert!(
                parse(&["--ros", "--robot-id", "0", "--person-radius", bad]).is_err(),
                "{bad}"
            );
        }
        assert!(
            parse(&["--robot-id", "0", "--person-radius", "0.35"]).is_err(),
            "needs --ros"
        );
    }
}
