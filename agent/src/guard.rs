//! The safety layer as a robot runs it under its planner stack: [`Guard`] prepares the layer's
//! [`SafeSet`] for the robot's situation, lets the stack plan inside it (planners rank or
//! restrict their candidates with [`SafeSet::admits`]), checks the command that comes out, and
//! counts what it changed.

use crate::math::Real;
use crate::model::{Base, Command};
use crate::planner::{Plan, PlannerStack, PlanningInput};
use crate::safety::{Guarded, SafeSet, SafetyLayer, SafetyLimits, SafetyParams, Zone};

/// The layer under one robot's planner: the base's limits (the control period is each plan's
/// `dt`) and how often, and how much, each field changed the planner's commands.
#[derive(Debug, Clone)]
pub struct Guard {
    layer: SafetyLayer,
    limits: SafetyLimits,
    base: Base,
    /// Commands checked.
    pub checked: u64,
    /// Commands the warning field slowed.
    pub warned: u64,
    /// Commands the protective field slowed further or stopped.
    pub protective: u64,
    /// Commands the yield replaced with a way out.
    pub yielded: u64,
    /// Sum over changed commands of how far the layer moved them (m/s: the velocity
    /// difference, or for unicycle commands the speed difference).
    pub change_sum: Real,
}

impl Guard {
    /// A guard for a base with `limits`, with the default parameters.
    pub fn new(limits: SafetyLimits) -> Self {
        Self::with_params(limits, SafetyParams::default())
    }

    /// A guard with the given parameters.
    pub fn with_params(limits: SafetyLimits, params: SafetyParams) -> Self {
        Self {
            layer: SafetyLayer::new(params),
            limits,
            base: Base::Holonomic,
            checked: 0,
            warned: 0,
            protective: 0,
            yielded: 0,
            change_sum: 0.0,
        }
    }

    /// The guard for a robot on `base`: commands are made executable on it before the check.
    pub fn on_base(mut self, base: Base) -> Self {
        self.base = base;
        self
    }

    /// The layer's parameters.
    pub fn params(&self) -> &SafetyParams {
        self.layer.params()
    }

    /// Commands the layer changed.
    pub fn changed(&self) -> u64 {
        self.warned + self.protective + self.yielded
    }

    /// What the robot may execute of the planner's `command`, planned on `input`; counted.
    pub fn check(&mut self, command: Command, input: &PlanningInput<'_>) -> Guarded {
        let limits = self.limits_for(input);
        let set = self
            .layer
            .prepare(input.ego, &limits, input.neighbours, input.map);
        let command = self.base.executable(command, input.ego);
        let guarded = set.guard(command);
        self.count(command, &guarded);
        guarded
    }

    /// One plan of `stack` inside the layer's safe set, and the checked command: the plan's
    /// command is replaced by what the robot may execute.
    pub fn plan(&mut self, stack: &mut PlannerStack, input: &PlanningInput<'_>) -> (Plan, Guarded) {
        let limits = self.limits_for(input);
        let set: SafeSet<'_> = self
            .layer
            .prepare(input.ego, &limits, input.neighbours, input.map);
        let within = PlanningInput {
            safety: Some(&set),
            ..*input
        };
        let mut plan = stack.plan(&within);
        plan.command = self.base.executable(plan.command, input.ego);
        let guarded = set.guard(plan.command);
        self.count(plan.command, &guarded);
        plan.command = guarded.command;
        (plan, guarded)
    }

    fn limits_for(&self, input: &PlanningInput<'_>) -> SafetyLimits {
        SafetyLimits {
            control_period: input.dt,
            ..self.limits
        }
    }

    fn count(&mut self, planned: Command, guarded: &Guarded) {
        self.checked += 1;
        match guarded.zone {
            Zone::Clear => return,
            Zone::Warning => self.warned += 1,
            Zone::Protective => self.protective += 1,
            Zone::Yield => self.yielded += 1,
        }
        self.change_sum += change(planned, guarded.command);
    }
}

/// How far the layer moved a command (m/s).
fn change(a: Command, b: Command) -> Real {
    match (a, b) {
        (Command::Velocity(x), Command::Velocity(y)) => (x - y).norm(),
        (Command::Unicycle { speed: s1, .. }, Command::Unicycle { speed: s2, .. }) => {
            (s1 - s2).abs()
        }
        // The layer keeps a command's kind; mixed kinds compare their speeds.
        (a, b) => (speed(a) - speed(b)).abs(),
    }
}

fn speed(c: Command) -> Real {
    match c {
        Command::Velocity(v) => v.norm(),
        Command::Unicycle { speed, .. } => speed.abs(),
    }
}
