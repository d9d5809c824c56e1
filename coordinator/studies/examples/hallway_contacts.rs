//! One run of the hallway study (`gapfleet study hallway`: the built-in hallway at a length,
//! its share of people walking at one speed, a 3 m/s robot, body occlusion and the safety
//! layer on) with every contact the robot causes explained: the person's track over the
//! second before, whether the robot saw them at each plan, what its layer did, and how hard
//! the person changed their motion (the acceleration the layer's swerve allowance a_h
//! must cover). A contact with someone the robot had not seen for over a second, or saw again
//! too late to stop for, is marked as hidden until too late (still robot-caused: the
//! robot could have slowed where it could not see).
//!
//!     cargo run --release -p studies --example hallway_contacts -- PLANNER LENGTH SPEED SEED \
//!         [LAYER]
//!
//! e.g. `orca 25 3 114`. LAYER changes the safety layer's parameters as `--safety-layer` does
//! (`memory_time=0`). The run is the study's, step for step: the same scenario
//! (`studies::hallway`) and the same plan each step as `world_sim::episode::run_episode` (`plan_robot`).

use agent::map::LocalMap;
use agent::math::{Real, Vec2};
use agent::planner::{PlannerSpec, PlannerStack};
use agent::safety::Zone;
use std::collections::VecDeque;
use studies::hallway::{HallwayStudy, hallway_scenario};
use world_sim::episode::{RobotPlan, guards, plan_robot};
use world_sim::metrics::{ContactCause, contact_cause};
use world_sim::world::World;

/// A person the robot has not seen for longer than this (s) is unknown to it when seen again:
/// the layer's default memory time, the rule of results/safety/REPORT.md ("People hidden from
/// the robot are not excused").
const UNSEEN_FOR_S: Real = 1.0;

/// One step of the person's history as the robot saw it.
#[derive(Debug, Clone, Copy)]
struct Seen {
    t: Real,
    velocity: Vec2,
    seen: bool,
    zone: Zone,
    robot_velocity: Vec2,
    gap: Real,
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 4 {
        return Err("usage: hallway_contacts PLANNER LENGTH SPEED SEED".into());
    }
    let planner: PlannerSpec = args[0].parse().map_err(|e| format!("{e}"))?;
    let length: Real = args[1].parse().map_err(|e| format!("length: {e}"))?;
    let speed: Real = args[2].parse().map_err(|e| format!("speed: {e}"))?;
    let seed: u64 = args[3].parse().map_err(|e| format!("seed: {e}"))?;
    let mut base = hallway_scenario(3.0, true).map_err(|e| e.to_string())?;
    if let Some(changes) = args.get(4) {
        base.robot.safety_layer = base.robot.safety_layer.with_overrides(changes)?;
    }
    let study = HallwayStudy {
        scenario: base,
        planners: vec![planner],
        lengths: vec![length],
        width_m: 4.0,
        speeds: vec![speed],
        first_seed: seed,
        seeds: 1,
    };
    let scenario = study.scenario_for(length, speed, seed);

    let mut world = World::from_scenario(&scenario);
    let mut stack = PlannerStack::with_max_speed(planner, scenario.robot.max_speed);
    stack.set_record_fan(false);
    let mut guard = guards(&scenario, 1).pop().flatten();
    let people = world.humans.crowd.len();
    let keep = (1.0 / scenario.dt_s).round() as usize + 1;
    let mut history: Vec<VecDeque<Seen>> = vec![VecDeque::new(); people];
    let mut touching = vec![false; people];
    let mut local = LocalMap::default();
    let (mut robot_caused, mut person_caused, mut hidden) = (0, 0, 0);
    // Per person: when the robot last saw them, and by when braking from the moment it saw
    // them again (after over a second unseen) would have stopped it.
    let mut last_seen = vec![Real::NEG_INFINITY; people];
    let mut stand_by = vec![Real::NEG_INFINITY; people];
    let unseen_for = UNSEEN_FOR_S + 1.5 * scenario.dt_s;
    let braking = scenario
        .robot
        .safety_limits(scenario.dt_s)
        .braking()
        .max(1e-9);
    let steps = (scenario.max_time_s / scenario.dt_s).round() as u64;
    let robot_radius = world.robots[0].state.radius;
    for _ in 0..steps {
        let robot = &world.robots[0];
        if (robot.goal - robot.state.position).norm() <= robot.spec.goal_tolerance_m {
            println!("t {:5.1} arrived", world.time);
            break;
        }
        let RobotPlan { ego, seen, guarded } =
            plan_robot(&mut world, 0, &mut stack, guard.as_mut(), &mut local);
        let (command, zone) = (guarded.command, guarded.zone);
        for n in seen.iter().filter(|n| (n.id as usize) < people) {
            let i = n.id as usize;
            if world.time - last_seen[i] > unseen_for {
                stand_by[i] = world.time + ego.velocity.norm() / braking;
            }
            last_seen[i] = world.time;
        }
        let crowd = &world.humans.crowd;
        for (i, h) in history.iter_mut().enumerate() {
            let p = crowd.positions[i];
            h.push_back(Seen {
                t: world.time,
                velocity: crowd.velocities[i],
                seen: seen.iter().any(|n| n.id == i as u64),
                zone,
                robot_velocity: ego.velocity,
                gap: (p - ego.position).norm() - robot_radius - world.humans.radius,
            });
            if h.len() > keep {
                h.pop_front();
            }
        }
        world.step(&[command]);
        let r = world.robots[0].state;
        for (i, was) in touching.iter_mut().enumerate() {
            let p = world.humans.crowd.positions[i];
            let now = (p - r.position).norm() < r.radius + world.humans.radius;
            if now && !*was {
                let cause = contact_cause(r.position, r.velocity, p);
                match cause {
                    ContactCause::Robot => robot_caused += 1,
                    ContactCause::Other => person_caused += 1,
                }
                if cause == ContactCause::Robot {
                    let line = (p - r.position).normalize();
                    // Unseen for over a second, or seen again too late to stop for.
                    let unseen = world.time - last_seen[i] > unseen_for || world.time < stand_by[i];
                    hidden += u64::from(unseen);
                    println!(
                        "t {:5.1} robot-caused contact{} with person {i}: robot {:.2} m/s, toward {:+.2}; person toward the robot {:+.2} m/s",
                        world.time,
                        if unseen {
                            " (hidden from the robot until too late to stop)"
                        } else {
                            ""
                        },
                        r.velocity.norm(),
                        r.velocity.dot(&line),
                        -world.humans.crowd.velocities[i].dot(&line),
                    );
                    let h: Vec<&Seen> = history[i].iter().collect();
                    for (k, s) in h.iter().enumerate() {
                        // The person's acceleration over this step.
                        let accel = h.get(k + 1).map_or(Real::NAN, |n| {
                            (n.velocity - s.velocity).norm() / (n.t - s.t)
                        });
                        println!(
                            "    t {:5.1} gap {:5.2} person v ({:+.2}, {:+.2}) accel {:5.2} seen {} | robot v ({:+.2}, {:+.2}) layer {:?}",
                            s.t,
                            s.gap,
                            s.velocity.x,
                            s.velocity.y,
                            accel,
                            s.seen,
                            s.robot_velocity.x,
                            s.robot_velocity.y,
                            s.zone,
                        );
                    }
                }
            }
            *was = now;
        }
    }
    println!(
        "{robot_caused} robot-caused ({hidden} with someone hidden from the robot until too late), {person_caused} person-caused contacts"
    );
    Ok(())
}
