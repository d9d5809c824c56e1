//! Follows one robot through one episode (the studies' open-space, hallway and laned runs),
//! every second: where it is, how fast and which way it drives, how far its goal is, what
//! its layer did, and the nearest people.
//!
//!     cargo run --release -p world-sim --example episode_probe -- SCENARIO PLANNER SEED \
//!         [DENSITY]
//!
//! SCENARIO is a built-in's name or a scenario file; DENSITY sets an open space's people per
//! m². Robot 0 is followed.

use agent::map::LocalMap;
use agent::math::Real;
use agent::model::Command;
use agent::planner::{PlannerSpec, PlannerStack};
use agent::safety::Zone;
use world_sim::episode::{RobotPlan, guards, plan_robot};
use world_sim::scenario::Scenario;
use world_sim::world::World;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map_or("open-space", String::as_str);
    let planner: PlannerSpec = args
        .get(1)
        .map_or("pgp+orca", String::as_str)
        .parse()
        .expect("a known planner");
    let seed: u64 = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(1);
    let mut scenario = Scenario::load(name)
        .expect("a built-in scenario or a scenario file")
        .0;
    scenario.seed = seed;
    if let (Some(d), Some(open)) = (
        args.get(3).and_then(|a| a.parse::<Real>().ok()),
        scenario.open_space.as_mut(),
    ) {
        open.density = d;
    }
    let mut world = World::from_scenario(&scenario);
    let mut stack = PlannerStack::with_max_speed(planner, scenario.robot.max_speed);
    stack.set_record_fan(false);
    let mut guard = guards(&scenario, 1).pop().flatten();
    let robots = world.robots.len();
    let mut local = LocalMap::default();
    let steps = (scenario.max_time_s / scenario.dt_s).round() as u64;
    let per_second = (1.0 / scenario.dt_s).round() as u64;
    let (mut changed, mut yielded) = (0u32, 0u32);
    for step in 0..steps {
        let goal = world.robots[0].goal;
        let robot = &world.robots[0];
        if (goal - robot.state.position).norm() <= robot.spec.goal_tolerance_m {
            println!("t {:5.1} arrived", world.time);
            return;
        }
        let RobotPlan { ego, seen, guarded } =
            plan_robot(&mut world, 0, &mut stack, guard.as_mut(), &mut local);
        if guard.is_some() {
            changed += u32::from(guarded.zone != Zone::Clear);
            yielded += u32::from(guarded.zone == Zone::Yield);
        }
        let command = guarded.command;
        let mut commands = vec![Command::STOP; robots];
        commands[0] = command;
        if step % per_second == 0 {
            let mut near: Vec<(Real, Real, Real)> = seen
                .iter()
                .map(|n| {
                    let d = n.position - ego.position;
                    let gap = d.norm() - n.radius - ego.radius;
                    // Bearing from the robot's way to the goal, and the person's speed
                    // toward the robot.
                    let to_goal = goal - ego.position;
                    let bearing = (to_goal.x * d.y - to_goal.y * d.x).atan2(to_goal.dot(&d));
                    let closing = -n.velocity.dot(&d) / d.norm().max(1e-9);
                    (gap, bearing.to_degrees(), closing)
                })
                .collect();
            near.sort_by(|a, b| a.0.total_cmp(&b.0));
            let near: Vec<String> = near
                .iter()
                .take(3)
                .map(|(g, b, c)| format!("{g:.2} m at {b:+4.0}° closing {c:+.2}"))
                .collect();
            let v = ego.velocity;
            let to_goal = goal - ego.position;
            println!(
                "t {:5.1} at ({:5.2}, {:5.2}) v {:.2} m/s toward goal {:+.2} | goal {:5.2} m | layer changed {changed} yielded {yielded} of the last {per_second} | {}",
                world.time,
                ego.position.x,
                ego.position.y,
                v.norm(),
                v.dot(&to_goal) / to_goal.norm().max(1e-9),
                to_goal.norm(),
                near.join("; ")
            );
            (changed, yielded) = (0, 0);
        }
        world.step(&commands);
    }
    println!("t {:5.1} out of time", world.time);
}
