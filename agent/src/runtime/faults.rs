//! Fault injection for tests, kept out of the agent's loop: a planner stack whose short-term
//! planner holds its thread longer on every plan, as a slow planner would
//! ([`super::AgentConfig::fault_plan_delay`]).

use crate::math::Vec2;
use crate::planner::{LocalPlan, LocalPlanner, PlannerStack, PlanningInput};
use std::time::Duration;

/// `stack` with every plan `delay` slower.
pub(super) fn slowed(stack: PlannerStack, delay: Duration) -> PlannerStack {
    stack.wrap_local(|inner| Box::new(Slowed { inner, delay }))
}

/// A short-term planner that blocks its thread `delay` after each plan.
#[derive(Debug)]
struct Slowed {
    inner: Box<dyn LocalPlanner>,
    delay: Duration,
}

impl LocalPlanner for Slowed {
    fn subgoal_distance(&self) -> crate::math::Real {
        self.inner.subgoal_distance()
    }

    fn plan(&mut self, input: &PlanningInput<'_>, target: Vec2) -> LocalPlan {
        let plan = self.inner.plan(input, target);
        // Blocking on purpose: a busy planner holds its thread.
        std::thread::sleep(self.delay);
        plan
    }

    fn set_destinations(&mut self, destinations: &[Vec2]) {
        self.inner.set_destinations(destinations);
    }
}
