//! The safety layer as a robot runs it under its planner stack: [`Guard`] prepares the layer's
//! [`SafeSet`] for the robot's situation, lets the stack plan inside it (planners rank or
//! restrict their candidates with [`SafeSet::admits`]), checks the command that comes out, and
//! counts what it changed.

use crate::math::{Real, Vec2};
use crate::model::{Base, Command, Neighbour};
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
    /// Every body perceived within the last [`SafetyParams::memory_time`]: as last perceived,
    /// and the seconds since.
    remembered: Vec<(Neighbour, Real)>,
    /// The remembered bodies not perceived now, walked on to where they would be.
    walked: Vec<Neighbour>,
    /// The ids perceived now, sorted (scratch).
    seen_ids: Vec<u64>,
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
            remembered: Vec::new(),
            walked: Vec::new(),
            seen_ids: Vec::new(),
        }
    }

    /// The guard for a robot on `base`: commands are made executable on it before the check.
    pub fn on_base(mut self, base: Base) -> Self {
        self.base = base;
        self
    }

    /// Marks the places on the robot's site where robots and people stop and turn (boxes,
    /// lower and upper corners), for [`SafetyParams::person_accel_away`]; `None`: none known.
    pub fn set_turn_places(&mut self, places: Option<Vec<(Vec2, Vec2)>>) {
        self.layer.set_turn_places(places);
    }

    /// The layer's parameters.
    pub fn params(&self) -> &SafetyParams {
        self.layer.params()
    }

    /// Runs the layer on `params` from the next command on: a site's setting, served with
    /// its map (`schemas::MapMsg::safety_layer`).
    pub fn set_params(&mut self, params: SafetyParams) {
        self.layer.set_params(params);
    }

    /// Commands the layer changed.
    pub fn changed(&self) -> u64 {
        self.warned + self.protective + self.yielded
    }

    /// What the robot may execute of the planner's `command`, planned on `input`; counted.
    pub fn check(&mut self, command: Command, input: &PlanningInput<'_>) -> Guarded {
        let limits = self.limits_for(input);
        self.recall(input);
        let set = self.layer.prepare_remembering(
            input.ego,
            &limits,
            input.neighbours,
            &self.walked,
            input.map,
        );
        let command = self.base.executable(command, input.ego);
        let guarded = set.guard(command);
        self.count(command, &guarded);
        guarded
    }

    /// One plan of `stack` inside the layer's safe set, and the checked command: the plan's
    /// command is replaced by what the robot may execute.
    pub fn plan(&mut self, stack: &mut PlannerStack, input: &PlanningInput<'_>) -> (Plan, Guarded) {
        let limits = self.limits_for(input);
        self.recall(input);
        let set: SafeSet<'_> = self.layer.prepare_remembering(
            input.ego,
            &limits,
            input.neighbours,
            &self.walked,
            input.map,
        );
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

    /// Brings the memory up to `input`'s perception (each call is one control period,
    /// `input.dt`, after the last) and fills `walked`: everyone perceived within the memory
    /// time and not now, moved on at their last perceived velocity.
    fn recall(&mut self, input: &PlanningInput<'_>) {
        let keep = self.layer.params().memory_time;
        self.walked.clear();
        if keep <= 0.0 {
            self.remembered.clear();
            return;
        }
        for (_, age) in &mut self.remembered {
            *age += input.dt;
        }
        let seen = input.neighbours;
        self.seen_ids.clear();
        self.seen_ids.extend(seen.iter().map(|n| n.id));
        self.seen_ids.sort_unstable();
        let ids = &self.seen_ids;
        self.remembered
            .retain(|(n, age)| *age <= keep && ids.binary_search(&n.id).is_err());
        self.walked.extend(self.remembered.iter().map(|(n, age)| {
            let mut walked = n.clone();
            walked.position += n.velocity * *age;
            walked
        }));
        // Kept without a robot's announced intent: the layer does not read it.
        self.remembered.extend(seen.iter().map(|n| {
            let mut kept = Neighbour::new(n.id, n.position, n.velocity, n.radius, n.kind);
            kept.yaw_rate = n.yaw_rate;
            (kept, 0.0)
        }));
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::StaticMap;
    use crate::math::vec2;
    use crate::model::{AgentKind, EgoState};

    fn ego() -> EgoState {
        EgoState {
            position: vec2(0.0, 0.0),
            heading: 0.0,
            velocity: vec2(1.0, 0.0),
            yaw_rate: 0.0,
            radius: 0.3,
        }
    }

    /// The zone the guard gives "drive on at 1 m/s" at each of `steps` plans, the person
    /// walking at the robot perceived only at the first.
    fn zones(memory_time: Real, ahead: Real, steps: usize) -> Vec<Zone> {
        let params = SafetyParams {
            memory_time,
            ..SafetyParams::default()
        };
        let mut guard = Guard::with_params(SafetyLimits::SIMULATED_ROBOT, params);
        let map = StaticMap::empty();
        let ego = ego();
        let person = Neighbour::new(7, vec2(ahead, 0.0), vec2(-1.3, 0.0), 0.35, AgentKind::Human);
        (0..steps)
            .map(|k| {
                let seen = if k == 0 { vec![person.clone()] } else { vec![] };
                let input = PlanningInput {
                    ego: &ego,
                    neighbours: &seen,
                    map: &map,
                    goal: vec2(10.0, 0.0),
                    dt: 0.1,
                    visibility: None,
                    safety: None,
                };
                guard.check(Command::Velocity(vec2(1.0, 0.0)), &input).zone
            })
            .collect()
    }

    #[test]
    fn a_person_hidden_a_moment_is_still_checked() {
        // 5 m ahead, walking at the robot at 1.3 m/s: clear of the fields when last seen,
        // within the warning field 0.5 s later.
        // Without memory the layer forgets the person the moment they are hidden.
        let forgetful = zones(0.0, 5.0, 10);
        assert!(forgetful.iter().all(|z| *z == Zone::Clear), "{forgetful:?}");
        // With it, the person walks on toward the robot, and the fields act.
        let mindful = zones(1.0, 5.0, 10);
        assert_eq!(mindful[0], Zone::Clear, "{mindful:?}");
        assert!(
            mindful[5..].iter().all(|z| *z == Zone::Warning),
            "{mindful:?}"
        );
    }

    #[test]
    fn a_body_unseen_longer_than_the_memory_time_is_forgotten() {
        // Kept 0.3 s, the person is gone before they would reach the warning field.
        let z = zones(0.3, 5.0, 10);
        assert!(z.iter().all(|z| *z == Zone::Clear), "{z:?}");
    }
}
