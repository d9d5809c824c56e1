//! One run of a scenario with planners in the loop, in-process: the unit of batch
//! experiments. Every robot plans on what it perceives at every step.

use crate::impact::HumanImpact;
use crate::metrics::{MetricsRecorder, RobotMetrics};
use crate::scenario::Scenario;
use crate::world::World;
use agent::guard::Guard;
use agent::map::LocalMap;
use agent::model::{Command, EgoState, Neighbour};
use agent::planner::{PlannerSpec, PlannerStack, PlanningInput};
use agent::safety::{Guarded, Zone};

/// Windows of the human-impact measurement in episodes (s): short, so that few people change
/// goal within one and drop out of it; the last, partial window is counted too.
pub const EPISODE_IMPACT_WINDOW_S: agent::math::Real = 5.0;

/// One robot's plan at one step of an episode: what it perceived and what it may execute.
#[derive(Debug, Clone)]
pub struct RobotPlan {
    /// Its own state as observed.
    pub ego: EgoState,
    /// The bodies it perceived.
    pub seen: Vec<Neighbour>,
    /// Its command after its safety layer (clear, the planner's own, with the layer off).
    pub guarded: Guarded,
}

/// Robot `i`'s plan at this step, as every episode makes it: its observation and, with body
/// occlusion, its view, then its stack under its guard (the safety layer), or the stack alone
/// when the layer is off. The examples that follow one run (`episode_probe`,
/// `hallway_contacts`, `hallway_layer`) plan through this too, so they see the study's run.
pub fn plan_robot(
    world: &mut World,
    i: usize,
    stack: &mut PlannerStack,
    guard: Option<&mut Guard>,
    local: &mut LocalMap,
) -> RobotPlan {
    let (ego, seen) = world.observe(i);
    let profile = world.visibility(i, local);
    let input = PlanningInput {
        ego: &ego,
        neighbours: &seen,
        map: &world.map,
        goal: world.robots[i].goal,
        dt: world.dt,
        visibility: profile.as_ref(),
        safety: None,
    };
    let guarded = match guard {
        Some(g) => g.plan(stack, &input).1,
        None => Guarded {
            command: stack.plan(&input).command,
            zone: Zone::Clear,
            scale: 1.0,
        },
    };
    RobotPlan { ego, seen, guarded }
}

/// Runs a scenario with every robot using `planner` (under `agent::safety` unless the
/// scenario's `[robot] safety` is off) until all robots arrive or time runs out. Returns each
/// robot's metrics.
pub fn run_episode(scenario: &Scenario, planner: PlannerSpec) -> Vec<RobotMetrics> {
    run_episode_with(scenario, |_| {
        // Batch runs draw nothing: no fan recording. The planners drive at the robot's top
        // speed (their defaults are the scenarios' 1 m/s).
        let mut stack = PlannerStack::with_max_speed(planner, scenario.robot.max_speed);
        stack.set_record_fan(false);
        stack
    })
}

/// [`run_episode`] with each robot's stack made by `stack(robot index)` (planners with
/// parameters of their own, as the studies' sweeps use).
pub fn run_episode_with(
    scenario: &Scenario,
    stack: impl Fn(usize) -> PlannerStack,
) -> Vec<RobotMetrics> {
    let mut world = World::from_scenario(scenario);
    let mut stacks: Vec<PlannerStack> = (0..world.robots.len()).map(stack).collect();
    let mut guards = guards(scenario, world.robots.len());
    let mut recorders: Vec<MetricsRecorder> = (0..world.robots.len())
        .map(|i| MetricsRecorder::new(&world, i))
        .collect();
    let mut impact = HumanImpact::new(&world, EPISODE_IMPACT_WINDOW_S);
    let steps = (scenario.max_time_s / scenario.dt_s).round() as u64;
    let mut commands = vec![Command::STOP; world.robots.len()];
    let mut local = LocalMap::default();
    for _ in 0..steps {
        if recorders.iter().all(MetricsRecorder::arrived) {
            break;
        }
        for (i, (stack, guard)) in stacks.iter_mut().zip(&mut guards).enumerate() {
            commands[i] = if recorders[i].arrived() {
                Command::STOP
            } else {
                plan_robot(&mut world, i, stack, guard.as_mut(), &mut local)
                    .guarded
                    .command
            };
        }
        world.step(&commands);
        for r in &mut recorders {
            r.record(&world);
        }
        impact.record(&world);
    }
    impact.flush(&world);
    recorders
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let mut m = r.finish();
            (m.human_delay_s, m.human_extra_path_m) = impact.robot_totals(i);
            m.human_path_changes = impact.robot_path_changes(i);
            m
        })
        .collect()
}

/// One safety guard per robot when the scenario's robots run the layer, else none.
pub fn guards(scenario: &Scenario, robots: usize) -> Vec<Option<Guard>> {
    (0..robots)
        .map(|_| scenario.robot.guard(scenario.dt_s))
        .collect()
}

/// One safety guard per robot of `fleet` when the scenario's robots run the layer, each told
/// where people turn on the fleet's site (`World::turn_places`).
pub fn fleet_guards(scenario: &Scenario, fleet: &crate::fleet::Fleet) -> Vec<Option<Guard>> {
    let places = fleet.world.turn_places();
    let mut guards = guards(scenario, fleet.robots());
    for guard in guards.iter_mut().flatten() {
        guard.set_turn_places(places.clone());
    }
    guards
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_planner_crosses_a_sparse_stage() {
        let mut s = Scenario::builtin("open-space").expect("valid");
        s.open_space.as_mut().expect("layout").density = 0.1;
        for spec in PlannerSpec::STUDY {
            let m = run_episode(&s, spec)[0];
            assert!(m.success, "{spec}: {m:?}");
            assert!(
                m.path_length_m >= 9.0 && m.time_to_goal_s >= 9.0,
                "{spec}: {m:?}"
            );
        }
    }

    #[test]
    fn every_planner_drives_down_a_hallway_with_two_way_traffic() {
        // The planners as the papers run them; with the layer, below.
        let mut s = Scenario::builtin("hallway").expect("valid");
        s.robot.safety = false;
        for spec in PlannerSpec::STUDY {
            let m = run_episode(&s, spec)[0];
            println!("{spec}: {m:?}");
            assert!(m.success, "{spec}: did not reach the end: {m:?}");
            // Start and goal are 24 m apart; arriving means getting within 0.5 m.
            assert!(m.path_length_m >= 24.0 - 0.5, "{spec}: {m:?}");
        }
    }

    #[test]
    fn under_the_safety_layer_no_planner_drives_into_anyone_in_the_hallway() {
        let s = Scenario::builtin("hallway").expect("valid");
        assert!(s.robot.safety, "on by default");
        for spec in PlannerSpec::STUDY {
            let m = run_episode(&s, spec)[0];
            println!("{spec}: {m:?}");
            assert_eq!(m.robot_caused_contacts, 0, "{spec}: {m:?}");
            assert_eq!(m.wall_contacts, 0, "{spec}: {m:?}");
        }
        // The default stack still gets through the two-way traffic.
        let m = run_episode(&s, "pgp+orca".parse().expect("known"))[0];
        assert!(m.success, "{m:?}");
    }

    #[test]
    fn runs_are_deterministic() {
        let s = Scenario::builtin("open-space").expect("valid");
        let spec: PlannerSpec = "pgp+orca".parse().expect("known");
        let (a, b) = (run_episode(&s, spec), run_episode(&s, spec));
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
    }
}
