//! Every robot-caused contact with a person in one in-process fleet run (the traffic policy on,
//! the layer as the scenario says, its parameters optionally changed), with what the person
//! did before it: how long ago their goal changed, and how far they strayed from each of their
//! motions of the last two seconds, as the acceleration 2·d/t² that would explain it (the
//! layer allows a person ½·a_h·t²).
//!
//!     cargo run --release -p world-sim --example fleet_contacts -- SITE ROBOTS SEED \
//!         [SECONDS [PLANNER [LAYER]]]
//!
//! SITE is a built-in fleet scenario or a scenario file (`….toml`); LAYER is the layer's parameters
//! to change, `key=value,…` (`person_accel=2`), or `off` for no layer. Each other contact with a
//! person (the person walked into the robot) gets a line too, `other`: where the robot stood
//! (aisle, cross-aisle, near a station, corridor), how fast it moved, whether it stood within 1.5 m
//! of a station and whether the person was walking to that station, and which of the layer's fields
//! acted on the robot's command that step and in the 2 s before (C clear, W warning, P protective,
//! Y yield, one letter a step); `results/person-caused/tally.py` adds them up. The last line has
//! the run's totals: robot-caused contacts, the other contacts with people, and tasks.

use agent::math::{Real, Vec2};
use agent::model::Command;
use agent::planner::PlannerSpec;
use std::collections::VecDeque;
use world_sim::fleet::{Fleet, drive, stacks};
use world_sim::metrics::{ContactCause, contact_cause};
use world_sim::scenario::Scenario;
use world_sim::stuck::Places;
use world_sim::traffic_policy::PolicyParams;

/// "At a station": a robot within this distance of one (m), about a body and a half.
const AT_STATION_M: Real = 1.5;

/// How many steps of people's motion are kept (2 s at 0.1 s).
const HISTORY_STEPS: usize = 20;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map_or("hallway-fleet", String::as_str);
    let robots: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(20);
    let seed: u64 = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(1);
    let seconds: Real = args.get(3).and_then(|a| a.parse().ok()).unwrap_or(300.0);
    let planner: PlannerSpec = args
        .get(4)
        .map_or("pgp+orca", String::as_str)
        .parse()
        .expect("a known planner");
    let mut scenario = Scenario::load(name)
        .expect("a built-in fleet scenario or a scenario file")
        .0;
    scenario.seed = seed;
    scenario.set_fleet_size(Some(robots), None);
    match args.get(5).map(String::as_str) {
        Some("off") => scenario.robot.safety = false,
        layer => {
            scenario.robot.safety_layer = scenario
                .robot
                .safety_layer
                .with_overrides(layer.unwrap_or(""))
                .expect("the layer's parameters as key=value,…");
        }
    }
    let mut fleet = Fleet::new(&scenario).expect("a fleet site");
    fleet.set_traffic_policy(Some(PolicyParams::default()));
    let mut stacks = stacks(&fleet, planner, scenario.robot.max_speed);
    let mut guards = world_sim::episode::fleet_guards(&scenario, &fleet);
    let mut commands = vec![Command::STOP; robots];
    let people = fleet.world.humans.crowd.len();
    let dt = fleet.world.dt;
    let mut touching = vec![vec![false; people]; robots];
    // People's positions and velocities after each step, newest last.
    let mut history: VecDeque<Vec<(Vec2, Vec2)>> = VecDeque::new();
    // Each person's goal, and when it last changed.
    let mut goals = fleet.world.humans.crowd.goals.clone();
    let mut goal_since = vec![Real::NEG_INFINITY; people];
    let (mut caused, mut other) = (0_u64, 0_u64);
    let places = Places::new(fleet.site());
    let mut zone_history = vec![String::new(); robots];
    for _ in 0..(seconds / dt).round() as u64 {
        let counts = |guards: &[Option<agent::guard::Guard>]| -> Vec<[u64; 3]> {
            guards
                .iter()
                .map(|g| {
                    g.as_ref()
                        .map_or([0; 3], |g| [g.warned, g.protective, g.yielded])
                })
                .collect()
        };
        let before = counts(&guards);
        drive(&mut fleet, &mut stacks, &mut guards, &mut commands);
        // Which field of the layer acted on each robot's command this step.
        let zones: Vec<&str> = counts(&guards)
            .iter()
            .zip(&before)
            .map(
                |(after, before)| match (0..3).find(|&k| after[k] > before[k]) {
                    Some(0) => "warning",
                    Some(1) => "protective",
                    Some(_) => "yield",
                    None => "clear",
                },
            )
            .collect();
        // Each robot's fields over the last 2 s, oldest first, one letter a step.
        for (history, zone) in zone_history.iter_mut().zip(&zones) {
            if history.len() == HISTORY_STEPS {
                history.remove(0);
            }
            history.push(zone.chars().next().unwrap_or('?').to_ascii_uppercase());
        }
        let w = &fleet.world;
        let crowd = &w.humans.crowd;
        for (h, goal) in crowd.goals.iter().enumerate() {
            if *goal != goals[h] {
                (goals[h], goal_since[h]) = (*goal, w.time);
            }
        }
        history.push_back(
            crowd
                .positions
                .iter()
                .zip(&crowd.velocities)
                .map(|(&p, &v)| (p, v))
                .collect(),
        );
        if history.len() > HISTORY_STEPS {
            history.pop_front();
        }
        for (i, r) in w.robots.iter().enumerate() {
            for (h, touching) in touching[i].iter_mut().enumerate() {
                let p = crowd.positions[h];
                let now = (p - r.state.position).norm() < r.state.radius + w.humans.radius;
                if now && !*touching {
                    if contact_cause(r.state.position, r.state.velocity, p) == ContactCause::Robot {
                        caused += 1;
                        let line = (p - r.state.position).normalize();
                        // The stray since each kept step (k steps back), as 2·d/t².
                        let strays: Vec<String> = (1..history.len())
                            .step_by(2)
                            .map(|k| {
                                let (p0, v0) = history[history.len() - 1 - k][h];
                                let t = k as Real * dt;
                                let stray = (p - (p0 + v0 * t)).norm();
                                format!("{t:.1} s: {:.1}", 2.0 * stray / (t * t))
                            })
                            .collect();
                        let nearest_person = (0..people)
                            .filter(|&o| o != h)
                            .map(|o| (crowd.positions[o] - p).norm())
                            .fold(Real::INFINITY, Real::min);
                        println!(
                            "t {:5.1} robot {i} person {h}: robot at {:.2?} speed {:.2}, toward the person {:+.2} m/s, command {:?}; person at {:.2?} speed {:.2}, toward the robot {:+.2} m/s, goal changed {:.1} s before, nearest other person {nearest_person:.2} m; stray as 2d/t² (m/s²) over {}",
                            w.time,
                            r.state.position,
                            r.state.velocity.norm(),
                            r.state.velocity.dot(&line),
                            commands[i],
                            p,
                            crowd.velocities[h].norm(),
                            -crowd.velocities[h].dot(&line),
                            w.time - goal_since[h],
                            strays.join(", ")
                        );
                    } else {
                        other += 1;
                        let at = r.state.position;
                        let place = format!("{:?}", places.of(at));
                        let speed = r.state.velocity.norm();
                        let station = fleet
                            .site()
                            .stations
                            .iter()
                            .map(|s| s.position)
                            .find(|s| (s - at).norm() <= AT_STATION_M);
                        let walking_to_it =
                            station.is_some_and(|s| (crowd.goals[h] - s).norm() <= AT_STATION_M);
                        // Where the person came from, in the robot's motion: ahead (cos > 0.5),
                        // behind (< -0.5) or beside; and whether they walked the robot's way.
                        let line = (p - at).normalize();
                        let side = match r.state.velocity.try_normalize(1e-9) {
                            Some(d) if d.dot(&line) > 0.5 => "ahead",
                            Some(d) if d.dot(&line) < -0.5 => "behind",
                            Some(_) => "beside",
                            None => "standing",
                        };
                        let same_way = r.state.velocity.dot(&crowd.velocities[h]) > 0.0;
                        println!(
                            "other t {:5.1} robot {i} person {h}: {place}, robot speed {speed:.2}, person speed {:.2}, the person {side}, walking the robot's way {same_way}, at a station {}, the person walking to it {walking_to_it}, the layer {} (last 2 s: {})",
                            w.time,
                            crowd.velocities[h].norm(),
                            station.is_some(),
                            zones[i],
                            zone_history[i]
                        );
                    }
                }
                *touching = now;
            }
        }
    }
    println!(
        "{name} seed {seed}: {caused} robot-caused, {other} other contacts with people, {} tasks",
        (0..robots).map(|i| fleet.tasks_done(i)).sum::<u64>()
    );
}
