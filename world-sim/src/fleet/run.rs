//! A fleet run in-process: every robot plans on what it perceives, as its agent would, under
//! its safety layer; the batch studies' and tests' fleet, and what such a run produced.

use super::{Fleet, FleetSummary, NotAWarehouse};
use crate::metrics::RobotMetrics;
use crate::scenario::Scenario;
use crate::stuck::{StuckBreakdown, StuckCauses};
use crate::traffic::TrafficTotals;
use crate::traffic_policy::{PolicyParams, PolicyTotals, TrafficPolicy};
use agent::guard::Guard;
use agent::map::LocalMap;
use agent::math::{Real, Vec2};
use agent::model::Command;
use agent::planner::{Plan, PlannerSpec, PlannerStack, PlanningInput};
use agent::safety::Zone;

/// What an in-process fleet run produced.
#[derive(Debug, Clone, PartialEq)]
pub struct FleetReport {
    /// Simulated seconds.
    pub seconds: Real,
    /// Tasks completed per robot.
    pub tasks_done: Vec<u64>,
    /// Metrics per robot.
    pub robots: Vec<RobotMetrics>,
    /// Commands the safety layer's warning field slowed, per robot (0 without the layer).
    pub warned: Vec<u64>,
    /// Commands its protective field slowed further or stopped, per robot.
    pub protective: Vec<u64>,
    /// Commands its yield replaced with a way out, per robot.
    pub yielded: Vec<u64>,
    /// Commands it checked, per robot.
    pub checked: Vec<u64>,
    /// How far it moved the commands it changed, summed over the fleet (m/s).
    pub change_sum: Real,
    /// Stuck robots and deadlocks.
    pub traffic: TrafficTotals,
    /// What the traffic policy did, when on.
    pub policy: Option<PolicyTotals>,
    /// Times a robot pushed off its route got a new one.
    pub reroutes: u64,
    /// Stuck robot-seconds by place and by who stood next to the robot.
    pub stuck_where: StuckBreakdown,
    /// Stuck robot-seconds by what held the robot.
    pub stuck_causes: StuckCauses,
    /// The people's health as a crowd: the share of person-minutes (whole minutes of the
    /// run) in which a person moved less than [`STALLED_M`], i.e. stood where they were.
    /// People in these worlds always have somewhere to go, so a stalled person is stuck (in
    /// a jam, or short of a goal the walls keep them from), robots or not.
    pub people_stalled_share: Real,
    /// The fleet-wide figures at the end, with no free flow.
    pub summary: FleetSummary,
}

/// A person who moves less than this in a window of [`Stalls`] has stalled (m).
pub const STALLED_M: Real = 1.0;

/// One planner stack per robot of `fleet`, as its agent would run it: `planner` capped at
/// `max_speed`, fans not recorded, the people's destinations known where the world knows them.
pub fn stacks(fleet: &Fleet, planner: PlannerSpec, max_speed: Real) -> Vec<PlannerStack> {
    let destinations = fleet.world.people_destinations();
    (0..fleet.robots())
        .map(|_| {
            let mut stack = PlannerStack::with_max_speed(planner, max_speed);
            stack.set_record_fan(false);
            stack.set_destinations(&destinations);
            stack
        })
        .collect()
}

/// Counts people who stall: in consecutive windows of a fixed length, those who moved less
/// than [`STALLED_M`] from where the window began.
#[derive(Debug, Clone)]
pub struct Stalls {
    window: u64,
    steps: u64,
    start: Vec<Vec2>,
    stalled: usize,
    windows: usize,
}

impl Stalls {
    /// Windows of `window_s` simulated seconds from `fleet`'s present.
    pub fn new(fleet: &Fleet, window_s: Real) -> Self {
        Self {
            window: ((window_s / fleet.world.dt).round() as u64).max(1),
            steps: 0,
            start: fleet.world.humans.crowd.positions.clone(),
            stalled: 0,
            windows: 0,
        }
    }

    /// Takes the fleet after one more step; when that closes a window, returns the people
    /// (indices) who stalled in it.
    pub fn record(&mut self, fleet: &Fleet) -> Option<Vec<usize>> {
        self.steps += 1;
        if !self.steps.is_multiple_of(self.window) {
            return None;
        }
        let now = &fleet.world.humans.crowd.positions;
        let still: Vec<usize> = (0..now.len())
            .filter(|&h| (now[h] - self.start[h]).norm() < STALLED_M)
            .collect();
        self.stalled += still.len();
        self.windows += now.len();
        self.start.clone_from(now);
        Some(still)
    }

    /// The share of person-windows closed so far in which the person stalled (0 before any).
    pub fn share(&self) -> Real {
        if self.windows > 0 {
            self.stalled as Real / self.windows as Real
        } else {
            0.0
        }
    }
}

impl FleetReport {
    /// Tasks completed by the whole fleet.
    pub fn total_tasks(&self) -> u64 {
        self.tasks_done.iter().sum()
    }
}

/// Every robot with a task plans in-process on what it perceives now, as its agent would: the
/// plan's intent goes into the fleet's table (robots later in the order see it this tick) and
/// its command into `commands`; a robot without a task gets [`Command::STOP`]. `plan` runs
/// robot `i`'s planner (`|_, stack, input| stack.plan(input)`); callers wrap it to time or
/// inspect plans.
pub fn plan_all(
    fleet: &mut Fleet,
    stacks: &mut [PlannerStack],
    commands: &mut [Command],
    mut plan: impl FnMut(usize, &mut PlannerStack, &PlanningInput<'_>) -> Plan,
) {
    let mut local = LocalMap::default();
    for (i, stack) in stacks.iter_mut().enumerate() {
        let Some(goal) = fleet.goal(i) else {
            commands[i] = Command::STOP;
            continue;
        };
        let (ego, seen) = fleet.observe(i);
        let profile = fleet.world.visibility(i, &mut local);
        let planned = plan(
            i,
            stack,
            &PlanningInput {
                ego: &ego,
                neighbours: &seen,
                map: fleet.robot_map(),
                goal,
                dt: fleet.world.dt,
                visibility: profile.as_ref(),
                safety: None,
            },
        );
        let now = fleet.world.time;
        fleet.set_intent(i, now, planned.intent.trajectory);
        commands[i] = planned.command;
    }
}

/// One in-process fleet step: dispatch, every robot plans (its command checked by its guard,
/// when it has one), the fleet steps.
pub fn drive(
    fleet: &mut Fleet,
    stacks: &mut [PlannerStack],
    guards: &mut [Option<Guard>],
    commands: &mut [Command],
) {
    fleet.dispatch();
    // Robots without a task, or without a layer, are not held by one.
    let mut held = vec![false; fleet.robots()];
    plan_all(
        fleet,
        stacks,
        commands,
        |i, stack, input| match &mut guards[i] {
            Some(guard) => {
                let (plan, guarded) = guard.plan(stack, input);
                held[i] = matches!(guarded.zone, Zone::Protective | Zone::Yield);
                plan
            }
            None => stack.plan(input),
        },
    );
    for (i, &held) in held.iter().enumerate() {
        fleet.set_layer_held(i, held);
    }
    fleet.step(commands);
}

/// Runs a warehouse for `seconds` with every robot planning in-process with `planner` (under
/// `agent::safety` unless the scenario's `[robot] safety` is off); `share_intents` switches
/// intent sharing between robots. No traffic policy.
pub fn run_fleet(
    scenario: &Scenario,
    planner: PlannerSpec,
    seconds: Real,
    share_intents: bool,
) -> Result<FleetReport, NotAWarehouse> {
    let options = FleetOptions {
        share_intents,
        policy: None,
        human_impact_window_s: None,
    };
    run_fleet_with(scenario, planner, seconds, options)
}

/// How an in-process fleet run is set up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FleetOptions {
    /// Whether observations carry other robots' intents.
    pub share_intents: bool,
    /// The traffic policy's parameters; `None`: no policy.
    pub policy: Option<PolicyParams>,
    /// Measure what the robots cost people in windows of this length (s; a shadow crowd, one
    /// more crowd step per step); `None`: not measured.
    pub human_impact_window_s: Option<Real>,
}

/// [`run_fleet`] with the traffic policy and intent sharing as `options` say.
pub fn run_fleet_with(
    scenario: &Scenario,
    planner: PlannerSpec,
    seconds: Real,
    options: FleetOptions,
) -> Result<FleetReport, NotAWarehouse> {
    let mut fleet = Fleet::new(scenario)?;
    fleet.share_intents = options.share_intents;
    fleet.set_traffic_policy(options.policy);
    if let Some(window) = options.human_impact_window_s {
        fleet.measure_human_impact(window);
    }
    let mut stacks = stacks(&fleet, planner, scenario.robot.max_speed);
    let mut guards = crate::episode::fleet_guards(scenario, &fleet);
    let steps = (seconds / fleet.world.dt).round() as u64;
    let mut commands = vec![Command::STOP; fleet.robots()];
    let mut stalls = Stalls::new(&fleet, 60.0);
    for _ in 0..steps {
        drive(&mut fleet, &mut stacks, &mut guards, &mut commands);
        stalls.record(&fleet);
    }
    Ok(FleetReport {
        seconds: fleet.world.time,
        tasks_done: fleet.tasks_done.clone(),
        robots: (0..fleet.robots()).map(|i| fleet.metrics(i)).collect(),
        warned: guards
            .iter()
            .map(|g| g.as_ref().map_or(0, |g| g.warned))
            .collect(),
        protective: guards
            .iter()
            .map(|g| g.as_ref().map_or(0, |g| g.protective))
            .collect(),
        yielded: guards
            .iter()
            .map(|g| g.as_ref().map_or(0, |g| g.yielded))
            .collect(),
        checked: guards
            .iter()
            .map(|g| g.as_ref().map_or(0, |g| g.checked))
            .collect(),
        change_sum: guards
            .iter()
            .map(|g| g.as_ref().map_or(0.0, |g| g.change_sum))
            .sum(),
        traffic: fleet.traffic.totals(),
        policy: fleet.policy.as_ref().map(TrafficPolicy::totals),
        reroutes: fleet.reroutes,
        stuck_where: fleet.stuck_where,
        stuck_causes: fleet.stuck_causes,
        people_stalled_share: stalls.share(),
        summary: FleetSummary::of(&fleet),
    })
}
