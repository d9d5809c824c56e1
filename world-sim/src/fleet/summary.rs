//! The fleet summary: the fleet-wide figures, computed in one place from the fleet.
//!
//! The coordinator's metrics frame on the wire, the dashboard's KPIs, the demo's summary and
//! every fleet study's rows are built from a [`FleetSummary`]; none of them aggregates the
//! per-robot metrics itself.
//!
//! - Rates over robots (collision rate, SVR, Social Force) are means over the robots; 0 for a
//!   fleet of none.
//! - Counts (tasks, near misses, contacts) and times (intimate time, people's delay) are
//!   sums over the robots.
//! - Fleet efficiency is [`crate::efficiency::efficiency`] of the summary's tasks, robots and
//!   time against the site's free flow, once that is known ([`FleetSummary::with_free_flow`]).

use super::Fleet;
use crate::efficiency::{FreeFlow, efficiency};
use crate::metrics::RobotMetrics;
use crate::stuck::StuckCauses;
use crate::traffic::TrafficTotals;
use agent::math::Real;

/// The fleet-wide figures at one moment of a run (the default: a fleet of none, before it
/// began).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FleetSummary {
    /// Robots in the fleet.
    pub robots: usize,
    /// Simulated seconds since the run began.
    pub seconds: Real,
    /// Tasks the fleet completed.
    pub tasks: u64,
    /// Mean over the robots of the share of moving steps with a body overlap.
    pub collision_rate: Real,
    /// Mean over the robots of the share of moving steps with someone within 1 m.
    pub svr: Real,
    /// Mean over the robots of the mean Social Force on the robot.
    pub social_force: Real,
    /// Smallest centre distance between any robot and any person (m; infinite before any
    /// person was seen).
    pub min_human_distance_m: Real,
    /// Robot-seconds with a person in a robot's intimate zone.
    pub intimate_robot_s: Real,
    /// Person-seconds of delay the robots caused (0 where it is not measured).
    pub human_delay_s: Real,
    /// Metres the robots drove.
    pub path_length_m: Real,
    /// Steps with a robot–robot near miss, summed over the robots.
    pub near_miss_steps: u64,
    /// Steps with a body overlap between robots, summed over the robots.
    pub robot_contact_steps: u64,
    /// Contacts with people the robots caused (onsets).
    pub robot_caused_contacts: u64,
    /// Contacts people caused, walking into robots (onsets).
    pub person_caused_contacts: u64,
    /// Robot–robot contacts (onsets).
    pub robot_robot_contacts: u64,
    /// Contacts with walls and shelves (onsets).
    pub wall_contacts: u64,
    /// Every contact of every cause.
    pub total_contacts: u64,
    /// Robots stuck now.
    pub stuck_robots: usize,
    /// Stuck robots, deadlocks and gridlocks so far.
    pub traffic: TrafficTotals,
    /// Stuck robot-seconds by what held the robot.
    pub stuck_causes: StuckCauses,
    /// What one robot alone does on the site, once known.
    pub free_flow: Option<FreeFlow>,
}

impl FleetSummary {
    /// The summary of `fleet` now, with no free flow.
    pub fn of(fleet: &Fleet) -> Self {
        Self::of_robots(fleet, |_| true)
    }

    /// The summary of the robots of `fleet` that `member` picks (say, those a process plays),
    /// now, with no free flow. Tasks, robot figures and stuck robots are theirs; the traffic
    /// totals and stuck causes stay the whole fleet's.
    pub fn of_robots(fleet: &Fleet, member: impl Fn(usize) -> bool) -> Self {
        let robots = || (0..fleet.robots()).filter(|&i| member(i));
        let metrics: Vec<RobotMetrics> = robots().map(|i| fleet.metrics(i)).collect();
        let stuck_robots = robots().filter(|&i| fleet.traffic.is_stuck(i)).count();
        Self::from_robots(
            &metrics,
            robots().map(|i| fleet.tasks_done[i]).sum(),
            fleet.world.time,
            stuck_robots,
            fleet.traffic.totals(),
            fleet.stuck_causes,
        )
    }

    fn from_robots(
        metrics: &[RobotMetrics],
        tasks: u64,
        seconds: Real,
        stuck_robots: usize,
        traffic: TrafficTotals,
        stuck_causes: StuckCauses,
    ) -> Self {
        let sum = |f: fn(&RobotMetrics) -> u64| -> u64 { metrics.iter().map(f).sum() };
        let total = |f: fn(&RobotMetrics) -> Real| -> Real { metrics.iter().map(f).sum() };
        let mean = |f: fn(&RobotMetrics) -> Real| -> Real {
            if metrics.is_empty() {
                0.0
            } else {
                total(f) / metrics.len() as Real
            }
        };
        Self {
            robots: metrics.len(),
            seconds,
            tasks,
            collision_rate: mean(|m| m.collision_rate),
            svr: mean(|m| m.svr),
            social_force: mean(|m| m.social_force),
            min_human_distance_m: metrics
                .iter()
                .map(|m| m.min_human_distance_m)
                .fold(Real::INFINITY, Real::min),
            intimate_robot_s: total(|m| m.intimate_time_s),
            human_delay_s: total(|m| m.human_delay_s),
            path_length_m: total(|m| m.path_length_m),
            near_miss_steps: sum(|m| m.robot_near_misses),
            robot_contact_steps: sum(|m| m.robot_contacts),
            robot_caused_contacts: sum(|m| m.robot_caused_contacts),
            person_caused_contacts: sum(|m| m.person_caused_contacts),
            robot_robot_contacts: sum(|m| m.robot_robot_contacts),
            wall_contacts: sum(|m| m.wall_contacts),
            total_contacts: sum(RobotMetrics::total_contacts),
            stuck_robots,
            traffic,
            stuck_causes,
            free_flow: None,
        }
    }

    /// The summary against the site's free flow `free` (for the efficiency).
    #[must_use]
    pub fn with_free_flow(self, free: Option<FreeFlow>) -> Self {
        Self {
            free_flow: free,
            ..self
        }
    }

    /// Tasks per simulated minute (0 before any time has passed).
    pub fn tasks_per_min(&self) -> Real {
        if self.seconds > 0.0 {
            self.tasks as Real * 60.0 / self.seconds
        } else {
            0.0
        }
    }

    /// Tasks per robot-minute (0 for a fleet of none).
    pub fn tasks_per_robot_min(&self) -> Real {
        self.tasks_per_min() / self.robots.max(1) as Real
    }

    /// Fleet efficiency against the free flow; `None` while the free flow is unknown or where
    /// it cannot be told (`crate::efficiency::efficiency`).
    pub fn efficiency(&self) -> Option<Real> {
        let free = self.free_flow.as_ref()?;
        efficiency(self.tasks, self.robots, self.seconds, free)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn robot(collision_rate: Real, min_human: Real, robot_caused: u64) -> RobotMetrics {
        RobotMetrics {
            collision_rate,
            min_human_distance_m: min_human,
            robot_caused_contacts: robot_caused,
            person_caused_contacts: 1,
            ..RobotMetrics::default()
        }
    }

    #[test]
    fn rates_are_means_counts_are_sums_and_the_minimum_is_over_everyone() {
        let robots = [robot(0.1, 2.0, 1), robot(0.3, 0.5, 0)];
        let s = FleetSummary::from_robots(
            &robots,
            6,
            120.0,
            1,
            TrafficTotals::default(),
            StuckCauses::default(),
        );
        assert!((s.collision_rate - 0.2).abs() < 1e-12);
        assert_eq!(s.min_human_distance_m, 0.5);
        assert_eq!((s.robot_caused_contacts, s.person_caused_contacts), (1, 2));
        assert_eq!(s.total_contacts, 3);
        assert_eq!(s.tasks_per_min(), 3.0);
        assert_eq!(s.tasks_per_robot_min(), 1.5);
        assert_eq!(s.efficiency(), None);
        let free = FreeFlow {
            tasks: 4,
            seconds: 120.0,
        };
        assert_eq!(s.with_free_flow(Some(free)).efficiency(), Some(0.75));
    }

    #[test]
    fn a_fleet_of_none_has_zero_rates_and_no_efficiency() {
        let s = FleetSummary::from_robots(
            &[],
            0,
            0.0,
            0,
            TrafficTotals::default(),
            StuckCauses::default(),
        );
        assert_eq!((s.collision_rate, s.tasks_per_min()), (0.0, 0.0));
        assert!(s.min_human_distance_m.is_infinite());
        let free = FreeFlow {
            tasks: 4,
            seconds: 120.0,
        };
        assert_eq!(s.with_free_flow(Some(free)).efficiency(), None);
    }
}
