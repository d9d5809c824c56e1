//! One robot's first seconds in an in-process fleet run (the traffic policy on, the layer as
//! the scenario says): each step its velocity, what the layer let through (the field that acted and the share of the planner's command kept), its goal, and the people within 2.5 m (where they
//! stand and how they walk, in the site's frame, relative to the robot).
//!
//!     cargo run --release -p world-sim --example robot_trace -- SITE ROBOTS SEED ROBOT \
//!         [SECONDS [PLANNER]]

use agent::model::Command;
use agent::planner::PlannerSpec;
use agent::safety::Zone;
use world_sim::fleet::{Fleet, plan_all, stacks};
use world_sim::scenario::Scenario;
use world_sim::traffic_policy::PolicyParams;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map_or("hallway-fleet", String::as_str);
    let robots: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(20);
    let seed: u64 = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(1);
    let watched: usize = args.get(3).and_then(|a| a.parse().ok()).unwrap_or(0);
    let seconds: f64 = args.get(4).and_then(|a| a.parse().ok()).unwrap_or(3.0);
    let planner: PlannerSpec = args
        .get(5)
        .map_or("pnp-right", String::as_str)
        .parse()
        .expect("a known planner");
    let mut scenario = Scenario::builtin(name).expect("a built-in fleet scenario");
    scenario.seed = seed;
    scenario.set_fleet_size(Some(robots), None);
    let mut fleet = Fleet::new(&scenario).expect("a fleet site");
    fleet.set_traffic_policy(Some(PolicyParams::default()));
    let mut stacks = stacks(&fleet, planner, scenario.robot.max_speed);
    let mut guards = world_sim::episode::fleet_guards(&scenario, &fleet);
    let mut commands = vec![Command::STOP; robots];
    for _ in 0..(seconds / fleet.world.dt).round() as u64 {
        fleet.dispatch();
        let mut seen = None;
        plan_all(
            &mut fleet,
            &mut stacks,
            &mut commands,
            |i, stack, input| match &mut guards[i] {
                Some(guard) => {
                    let (plan, guarded) = guard.plan(stack, input);
                    if i == watched {
                        seen = Some((guarded, guarded.zone, input.goal));
                    }
                    plan
                }
                None => stack.plan(input),
            },
        );
        let w = &fleet.world;
        let r = &w.robots[watched].state;
        let crowd = &w.humans.crowd;
        let near: Vec<String> = (0..crowd.len())
            .filter(|&h| (crowd.positions[h] - r.position).norm() < 2.5)
            .map(|h| {
                let d = crowd.positions[h] - r.position;
                let v = crowd.velocities[h];
                format!(
                    "p{h} at ({:+.2},{:+.2}) v ({:+.2},{:+.2})",
                    d.x, d.y, v.x, v.y
                )
            })
            .collect();
        if let Some((guarded, zone, goal)) = seen {
            let zone = match zone {
                Zone::Clear => "C",
                Zone::Warning => "W",
                Zone::Protective => "P",
                Zone::Yield => "Y",
            };
            println!(
                "t {:4.1} at ({:.2},{:.2}) v ({:+.2},{:+.2}) goal ({:.1},{:.1}) {zone} scale {:.2} -> {:?} | {}",
                w.time,
                r.position.x,
                r.position.y,
                r.velocity.x,
                r.velocity.y,
                goal.x,
                goal.y,
                guarded.scale,
                commands[watched],
                near.join("; ")
            );
        } else {
            println!("t {:4.1} no goal", w.time);
        }
        fleet.step(&commands);
    }
}
