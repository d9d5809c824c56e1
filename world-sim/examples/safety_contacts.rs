//! The demo's warehouse in-process, deterministic, with `agent::safety` under every robot's
//! planner (or without, `--no-safety`): prints every contact with a person as it begins, with
//! who caused it and what the robot knew, and the totals.
//!
//!     cargo run --release -p world-sim --example safety_contacts [seed] [seconds] [--no-safety]
//!         [--person-accel A] [--planner P]
//!
//! P is any planner name (default `pgp+orca`).

use agent::guard::Guard;
use agent::model::Command;
use agent::planner::PlannerStack;
use agent::safety::SafetyParams;
use world_sim::fleet::{Fleet, plan_all};
use world_sim::metrics::{ContactCause, contact_cause};
use world_sim::scenario::Scenario;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let seed: u64 = args.first().and_then(|a| a.parse().ok()).unwrap_or(1);
    let seconds: f64 = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(60.0);
    let safety = !args.iter().any(|a| a == "--no-safety");
    let person_accel: f64 = args
        .iter()
        .position(|a| a == "--person-accel")
        .and_then(|k| args.get(k + 1))
        .and_then(|a| a.parse().ok())
        .unwrap_or(SafetyParams::default().person_accel);
    let planner = args
        .iter()
        .position(|a| a == "--planner")
        .and_then(|k| args.get(k + 1))
        .map_or("pgp+orca", String::as_str);
    let mut scenario = Scenario::builtin("warehouse").expect("built-in");
    scenario.seed = seed;
    let mut fleet = Fleet::new(&scenario).expect("a warehouse");
    let n = fleet.robots();
    let robot = scenario.robot;
    let limits = robot.safety_limits(scenario.dt_s);
    let mut stacks: Vec<PlannerStack> = (0..n)
        .map(|_| PlannerStack::new(planner.parse().expect("a known planner")))
        .collect();
    let params = SafetyParams {
        person_accel,
        ..SafetyParams::default()
    };
    let mut guards = vec![Guard::with_params(limits, params); n];
    let mut commands = vec![Command::STOP; n];
    let people = fleet.world.humans.crowd.len();
    let mut touching = vec![vec![false; people]; n];
    let mut seen_last: Vec<Vec<u64>> = vec![Vec::new(); n];
    let (mut robot_caused, mut person_caused) = (0, 0);
    for _ in 0..(seconds / scenario.dt_s).round() as u64 {
        fleet.dispatch();
        for (i, seen) in seen_last.iter_mut().enumerate() {
            *seen = fleet.observe(i).1.iter().map(|b| b.id).collect();
        }
        plan_all(&mut fleet, &mut stacks, &mut commands, |i, stack, input| {
            if safety {
                guards[i].plan(stack, input).0
            } else {
                stack.plan(input)
            }
        });
        fleet.step(&commands);
        let w = &fleet.world;
        for (i, r) in w.robots.iter().enumerate() {
            for (h, touching) in touching[i].iter_mut().enumerate() {
                let p = w.humans.crowd.positions[h];
                let now = (p - r.state.position).norm() < r.state.radius + w.humans.radius;
                if now && !*touching {
                    let cause = contact_cause(r.state.position, r.state.velocity, p);
                    match cause {
                        ContactCause::Robot => robot_caused += 1,
                        ContactCause::Other => person_caused += 1,
                    }
                    let line = (p - r.state.position).normalize();
                    println!(
                        "t {:5.1} robot {i} person {h}: {cause:?}; robot speed {:.2}, toward {:+.2} m/s, person toward robot {:+.2} m/s; person seen at the last plan: {}; command {:?}",
                        w.time,
                        r.state.velocity.norm(),
                        r.state.velocity.dot(&line),
                        -w.humans.crowd.velocities[h].dot(&line),
                        seen_last[i].contains(&(h as u64)),
                        commands[i],
                    );
                }
                *touching = now;
            }
        }
    }
    println!(
        "seed {seed}, {seconds} s, safety {} (person_accel {person_accel}): {robot_caused} robot-caused, {person_caused} person-caused contacts with people, {} tasks",
        if safety { "on" } else { "off" },
        (0..n).map(|i| fleet.tasks_done(i)).sum::<u64>(),
    );
}
