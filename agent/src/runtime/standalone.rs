//! A ROS 2 robot driven by its agent alone, through a list of goals, without a coordinator
//! (`gapfleet-agent --ros` without `--robot-id`): the planner stack and the safety layer on
//! what [`super::ros::RosLink`] senses, at a fixed control period.

use super::ros::{RosConfig, RosError, RosLink};
use crate::math::{Real, Vec2};
use crate::model::Command;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::Duration;

/// A ROS 2 robot driven to a list of goals by the planner stack, without a coordinator.
#[derive(Debug, Clone)]
pub struct RosAgentConfig {
    /// How to find the robot.
    pub ros: RosConfig,
    /// Planner stack.
    pub planner: crate::planner::PlannerSpec,
    /// The safety layer's base limits (`None`: no layer).
    pub safety: Option<crate::safety::SafetyLimits>,
    /// The base's drive.
    pub base: crate::model::Base,
    /// Goals in the map frame, in order.
    pub goals: Vec<Vec2>,
    /// A goal is reached within this distance (m).
    pub goal_tolerance: Real,
    /// Control period.
    pub period: Duration,
    /// Walls and shelves in the map frame (empty: the scan is the only wall sensor).
    pub map: crate::map::StaticMap,
    /// How scan returns become bodies.
    pub scan: crate::scan::ScanParams,
    /// Return once the last goal is reached (else hold the robot stopped until shutdown).
    pub exit_at_last_goal: bool,
}

/// Drives the robot through `config.goals`, then holds it stopped, until `shutdown`. Returns
/// how many goals were reached.
pub async fn run_ros_agent(
    session: &zenoh::Session,
    config: RosAgentConfig,
    counters: Arc<super::AgentCounters>,
    shutdown: impl std::future::Future<Output = ()>,
) -> Result<usize, RosError> {
    use crate::guard::Guard;
    use crate::planner::{PlannerStack, PlanningInput};
    use crate::safety::Zone;

    let link = RosLink::declare(session, config.ros.clone(), counters.ros.clone()).await?;
    let mut stack = PlannerStack::new(config.planner);
    let mut guard = config
        .safety
        .map(|limits| Guard::new(limits).on_base(config.base));
    let mut next_goal = 0usize;
    let mut ticker = tokio::time::interval(config.period);
    ticker.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
    let mut moving = false;
    let mut waiting_logged = false;
    tokio::pin!(shutdown);
    loop {
        tokio::select! {
            () = &mut shutdown => break,
            _ = ticker.tick() => {}
        }
        let Some(sensed) = link.sensed() else {
            if !waiting_logged {
                tracing::info!(
                    "waiting for odometry (and map→odom on /tf when odometry is not in the map frame)"
                );
                waiting_logged = true;
            }
            if moving {
                // Odometry stopped: the robot's state is unknown, so it stops.
                link.drive(Command::STOP, 0.0).await;
                counters.safe_stops.fetch_add(1, Ordering::Relaxed);
                moving = false;
            }
            continue;
        };
        waiting_logged = false;
        counters.received.fetch_add(1, Ordering::Relaxed);
        while let Some(goal) = config.goals.get(next_goal)
            && (goal - sensed.ego.position).norm() < config.goal_tolerance
        {
            next_goal += 1;
            tracing::info!(
                "goal {next_goal} of {} reached at ({:.2}, {:.2})",
                config.goals.len(),
                sensed.ego.position.x,
                sensed.ego.position.y
            );
        }
        let Some(&goal) = config.goals.get(next_goal) else {
            if moving {
                link.drive(Command::STOP, sensed.ego.heading).await;
                moving = false;
            }
            if config.exit_at_last_goal {
                break;
            }
            continue;
        };
        let mut neighbours = sensed.people.clone();
        if let Some(scan) = &sensed.scan {
            neighbours.extend(crate::scan::unexplained_bodies(
                scan,
                &config.map,
                &sensed.people,
                &config.scan,
            ));
        }
        let input = PlanningInput {
            ego: &sensed.ego,
            neighbours: &neighbours,
            map: &config.map,
            goal,
            dt: config.period.as_secs_f64(),
            visibility: None,
            safety: None,
        };
        let command = match &mut guard {
            Some(guard) => {
                let (plan, guarded) = guard.plan(&mut stack, &input);
                match guarded.zone {
                    Zone::Clear => {}
                    Zone::Warning => _ = counters.warned.fetch_add(1, Ordering::Relaxed),
                    Zone::Protective => _ = counters.protective.fetch_add(1, Ordering::Relaxed),
                    Zone::Yield => _ = counters.yielded.fetch_add(1, Ordering::Relaxed),
                }
                plan.command
            }
            None => config
                .base
                .executable(stack.plan(&input).command, &sensed.ego),
        };
        counters.plans.fetch_add(1, Ordering::Relaxed);
        link.drive(command, sensed.ego.heading).await;
        moving = true;
    }
    link.drive(Command::STOP, 0.0).await;
    counters.safe_stops.fetch_add(1, Ordering::Relaxed);
    Ok(next_goal)
}
