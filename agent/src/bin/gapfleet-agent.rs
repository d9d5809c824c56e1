//! `gapfleet-agent`: one robot's planner stack as its own process on the fleet's Zenoh network.
//!
//! ```text
//! gapfleet-agent --robot-id 3 --planner pgp+orca --connect tcp/127.0.0.1:7447
//! ```
//! Runs until SIGINT or SIGTERM, then safe-stops its robot and withdraws its liveliness token.

use agent::planner::PlannerSpec;
use agent::runtime::net::{NetArgs, Role, config};
use agent::runtime::{AgentConfig, AgentCounters, run_agent};
use clap::Parser;
use std::sync::Arc;
use std::time::Duration;

/// One robot's on-board planner stack.
#[derive(Debug, Parser)]
#[command(version, about)]
struct Args {
    /// The robot this agent drives.
    #[arg(long)]
    robot_id: u32,
    /// Planner stack: dwa, orca, sf, foigp, igp-diag, igp-lin or mc, each optionally behind
    /// pgp+ (e.g. pgp+orca). The foIGP family does not see walls or shelves.
    #[arg(long, default_value = "pgp+orca")]
    planner: PlannerSpec,
    /// Site name (key prefix gapfleet/<site>).
    #[arg(long, default_value = "demo")]
    site: String,
    /// Safe-stop after this many milliseconds without observations, in [10, 3600000] (0 would
    /// stop the robot for good).
    #[arg(
        long,
        default_value_t = agent::runtime::DEFAULT_OBS_TIMEOUT.as_millis() as u64,
        value_parser = clap::value_parser!(u64).range(10..=3_600_000)
    )]
    obs_timeout_ms: u64,
    /// Publish PGP's candidate fan with every plan, for dashboards (…/robot/<id>/fan).
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
    net: NetArgs,
}

#[tokio::main(flavor = "multi_thread", worker_threads = 2)]
async fn main() -> anyhow::Result<()> {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| "info,zenoh=warn".into()),
        )
        .with_writer(std::io::stderr)
        .init();
    let args = Args::parse();
    if !args.planner.avoids_static_obstacles() {
        tracing::warn!(
            "{} does not see shelves or walls (the foIGP paper models people only)",
            args.planner
        );
    }
    let mut net = args.net.clone();
    if net.connect.is_empty() && net.zenoh_config.is_none() {
        net.connect.push("tcp/127.0.0.1:7447".to_owned());
    }
    let session = zenoh::open(config(&net, Role::Client)?)
        .await
        .map_err(|e| anyhow::anyhow!("cannot open the Zenoh session: {e}"))?;
    let mut agent_config = AgentConfig::new(args.robot_id, &args.site, args.planner);
    agent_config.obs_timeout = Duration::from_millis(args.obs_timeout_ms);
    agent_config.share_fan = args.share_fan;
    agent_config.fault_plan_delay = Duration::from_millis(args.fault_plan_delay_ms);
    if args.no_safety {
        agent_config.safety = None;
    }
    let counters = Arc::new(AgentCounters::default());
    run_agent(
        &session,
        agent_config,
        counters.clone(),
        agent::runtime::shutdown_signal(),
    )
    .await?;
    session
        .close()
        .await
        .map_err(|e| anyhow::anyhow!("closing the session: {e}"))?;
    eprintln!(
        "gapfleet-agent {}: {} plans, {} rejected messages",
        args.robot_id,
        counters.plans.load(std::sync::atomic::Ordering::Relaxed),
        counters.rejected.load(std::sync::atomic::Ordering::Relaxed)
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
}
