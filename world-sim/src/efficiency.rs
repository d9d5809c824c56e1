//! Fleet efficiency: the work a fleet gets done against what its robots would do with the
//! floor to themselves.
//!
//! - A site's **free flow** is what one robot does there alone, with no people and no other
//!   robot: the same scenario (site, seed, so the same task stream), the same planner, safety
//!   layer and traffic policy, the same simulated time, run by the same code as the fleet
//!   ([`run_fleet_with`]). [`free_flow`] computes it once per process for each such setting
//!   and caches it.
//! - **Fleet efficiency** is the fleet's tasks per robot-minute over the free flow's tasks per
//!   minute ([`efficiency`]). 100 %: every robot worked as if it were alone; people, other
//!   robots, the traffic policy and the layer take it below.
//!
//! A run of 300 s is about five tasks for a robot alone, so one seed's figure moves in steps of
//! up to 20 %; studies report the mean over seeds.

use crate::fleet::{FleetOptions, NotAWarehouse, run_fleet_with};
use crate::scenario::Scenario;
use agent::math::Real;
use agent::planner::PlannerSpec;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// What one robot alone did on a site.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FreeFlow {
    /// Tasks it completed.
    pub tasks: u64,
    /// Simulated seconds it ran.
    pub seconds: Real,
}

impl FreeFlow {
    /// Tasks per minute.
    pub fn tasks_per_min(&self) -> Real {
        if self.seconds > 0.0 {
            self.tasks as Real * 60.0 / self.seconds
        } else {
            0.0
        }
    }
}

/// Fleet efficiency: `tasks` done by `robots` robots in `seconds`, per robot-minute, over the
/// free flow's tasks per minute. `None` when it cannot be told: no robots, no time, or a free
/// flow of no task (a site where one robot alone gets nothing done).
pub fn efficiency(tasks: u64, robots: usize, seconds: Real, free: &FreeFlow) -> Option<Real> {
    let free_rate = free.tasks_per_min();
    if robots == 0 || seconds <= 0.0 || free_rate <= 0.0 {
        return None;
    }
    let rate = tasks as Real * 60.0 / seconds / robots as Real;
    Some(rate / free_rate)
}

/// `scenario` with one robot and no people: the scenario of its free flow. `None` for a
/// scenario that is no fleet site.
pub fn alone(scenario: &Scenario) -> Option<Scenario> {
    let mut one = scenario.clone();
    one.set_fleet_size(Some(1), Some(0)).then_some(one)
}

type Cache = Mutex<HashMap<String, Arc<OnceLock<Result<FreeFlow, NotAWarehouse>>>>>;

/// The free flow of `scenario` (its robot and people counts are ignored) for `planner` over
/// `seconds`, with the traffic policy and intent sharing of `options`, from this process's
/// cache or run now. Concurrent callers asking for the same free flow wait for one run.
pub fn free_flow(
    scenario: &Scenario,
    planner: PlannerSpec,
    seconds: Real,
    options: FleetOptions,
) -> Result<FreeFlow, NotAWarehouse> {
    static CACHE: OnceLock<Cache> = OnceLock::new();
    let one = alone(scenario).ok_or_else(|| NotAWarehouse(scenario.name.clone()))?;
    let options = FleetOptions {
        human_impact_window_s: None,
        ..options
    };
    let key = format!("{one:?}|{planner}|{seconds}|{options:?}");
    let slot = {
        let mut cache = CACHE
            .get_or_init(Default::default)
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        cache.entry(key).or_default().clone()
    };
    slot.get_or_init(|| {
        let report = run_fleet_with(&one, planner, seconds, options)?;
        Ok(FreeFlow {
            tasks: report.total_tasks(),
            seconds: report.seconds,
        })
    })
    .clone()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn efficiency_is_per_robot_minute_over_the_free_flow() {
        let free = FreeFlow {
            tasks: 5,
            seconds: 300.0,
        };
        assert_eq!(free.tasks_per_min(), 1.0);
        // 8 robots, 36 tasks in 300 s: 0.9 per robot-minute.
        let e = efficiency(36, 8, 300.0, &free).expect("defined");
        assert!((e - 0.9).abs() < 1e-12, "{e}");
        // Over a shorter time the same rate is the same efficiency.
        let e = efficiency(18, 8, 150.0, &free).expect("defined");
        assert!((e - 0.9).abs() < 1e-12, "{e}");
        assert_eq!(efficiency(3, 0, 300.0, &free), None);
        let none = FreeFlow {
            tasks: 0,
            seconds: 300.0,
        };
        assert_eq!(efficiency(3, 2, 300.0, &none), None);
    }

    /// One robot alone in the default warehouse gets work done, and the cache hands the same
    /// figure back; a scenario that is no fleet site has no free flow.
    #[test]
    fn free_flow_of_the_default_warehouse() {
        let mut scenario = Scenario::builtin("warehouse").expect("built in");
        scenario.set_fleet_size(Some(4), Some(20));
        let options = FleetOptions {
            share_intents: true,
            policy: None,
            human_impact_window_s: None,
        };
        let planner: PlannerSpec = "pgp+orca".parse().expect("known");
        let free = free_flow(&scenario, planner, 120.0, options).expect("a warehouse");
        assert!(free.tasks >= 1, "{free:?}");
        assert_eq!(free_flow(&scenario, planner, 120.0, options), Ok(free));
        assert!(alone(&scenario).is_some());
        let hallway = Scenario::builtin("open-space").expect("built in");
        assert!(alone(&hallway).is_none());
    }
}
