//! Scenario tests for the planner stack: small closed-loop simulations with a minimal
//! kinematic model (holonomic bodies follow velocity commands, unicycles integrate (v, ω)).

use agent::map::StaticMap;
use agent::math::{Real, Vec2, angle_of, unit, vec2};
use agent::model::{AgentKind, Command, EgoState, Neighbour};
use agent::planner::{PlannerSpec, PlannerStack, PlanningInput};
use agent::social_force::{SfParams, capped_velocity, desired_force, social_force_pair};

const DT: Real = 0.1;
const RADIUS: Real = 0.3;
/// A robot has arrived within this distance of its goal (PySocialForce's arrival distance, at
/// which the SF planner stops).
const ARRIVAL: Real = 0.5;

struct Robot {
    state: EgoState,
    goal: Vec2,
    stack: PlannerStack,
}

fn apply(state: &mut EgoState, command: Command) {
    match command {
        Command::Velocity(v) => {
            state.velocity = v;
            if v.norm() > 1e-6 {
                state.heading = angle_of(&v);
            }
            state.yaw_rate = 0.0;
        }
        Command::Unicycle { speed, yaw_rate } => {
            state.heading += yaw_rate * DT;
            state.yaw_rate = yaw_rate;
            state.velocity = unit(state.heading) * speed;
        }
    }
    state.position += state.velocity * DT;
}

/// Runs robots until all reach their goals (within ARRIVAL) or `seconds` pass. Returns the
/// smallest centre distance seen and whether all arrived.
fn run(robots: &mut [Robot], map: &StaticMap, seconds: Real) -> (Real, bool) {
    let mut min_dist = Real::INFINITY;
    for _ in 0..(seconds / DT) as usize {
        let snapshot: Vec<EgoState> = robots.iter().map(|r| r.state).collect();
        let mut commands = Vec::new();
        for (i, r) in robots.iter_mut().enumerate() {
            let neighbours: Vec<Neighbour> = snapshot
                .iter()
                .enumerate()
                .filter(|(j, _)| *j != i)
                .map(|(j, s)| {
                    Neighbour::new(j as u64, s.position, s.velocity, RADIUS, AgentKind::Robot)
                })
                .collect();
            let arrived = (r.state.position - r.goal).norm() < ARRIVAL;
            let input = PlanningInput {
                ego: &r.state,
                neighbours: &neighbours,
                map,
                goal: r.goal,
                dt: DT,
                visibility: None,
                safety: None,
            };
            commands.push(if arrived {
                Command::STOP
            } else {
                r.stack.plan(&input).command
            });
        }
        for (r, c) in robots.iter_mut().zip(commands) {
            apply(&mut r.state, c);
        }
        for i in 0..robots.len() {
            for j in i + 1..robots.len() {
                min_dist =
                    min_dist.min((robots[i].state.position - robots[j].state.position).norm());
            }
        }
        if robots
            .iter()
            .all(|r| (r.state.position - r.goal).norm() < ARRIVAL)
        {
            return (min_dist, true);
        }
    }
    (min_dist, false)
}

fn robot(spec: PlannerSpec, start: Vec2, goal: Vec2) -> Robot {
    let heading = angle_of(&(goal - start));
    Robot {
        state: EgoState {
            position: start,
            heading,
            velocity: Vec2::zeros(),
            yaw_rate: 0.0,
            radius: RADIUS,
        },
        goal,
        stack: PlannerStack::new(spec),
    }
}

/// A Social Force pedestrian (PySocialForce defaults) who treats the robot as a pedestrian.
struct Person {
    position: Vec2,
    velocity: Vec2,
    goal: Vec2,
}

/// What a robot-meets-person run measured.
struct Encounter {
    /// Closest centre distance at any time.
    closest: Real,
    /// Closest centre distance while the robot moved (speed > 0.05 m/s).
    closest_while_moving: Real,
    arrived: bool,
}

/// Robot with `spec` against a person walking the opposite way.
fn robot_meets_person(spec: PlannerSpec, lateral_offset: Real) -> Encounter {
    let sf = SfParams {
        step_width: DT,
        ..SfParams::default()
    };
    let person_radius = sf.agent_radius;
    let mut r = robot(spec, vec2(-5.0, 0.0), vec2(5.0, 0.0));
    let mut person = Person {
        position: vec2(5.0, lateral_offset),
        velocity: vec2(-1.0, 0.0),
        goal: vec2(-6.0, lateral_offset),
    };
    let max_speed = 1.0 * sf.max_speed_multiplier;
    let map = StaticMap::empty();
    let mut e = Encounter {
        closest: Real::INFINITY,
        closest_while_moving: Real::INFINITY,
        arrived: false,
    };
    for _ in 0..(40.0 / DT) as usize {
        let seen = [Neighbour::new(
            1,
            person.position,
            person.velocity,
            person_radius,
            AgentKind::Human,
        )];
        let input = PlanningInput {
            ego: &r.state,
            neighbours: &seen,
            map: &map,
            goal: r.goal,
            dt: DT,
            visibility: None,
            safety: None,
        };
        let command = r.stack.plan(&input).command;
        let force = desired_force(
            person.position,
            person.velocity,
            person.goal,
            max_speed,
            &sf.desired,
        ) + social_force_pair(
            person.position,
            person.velocity,
            r.state.position,
            r.state.velocity,
            &sf.social,
        ) * sf.social.factor;
        apply(&mut r.state, command);
        person.velocity = capped_velocity(person.velocity + force * DT, max_speed);
        person.position += person.velocity * DT;
        let d = (r.state.position - person.position).norm();
        e.closest = e.closest.min(d);
        if r.state.velocity.norm() > 0.05 {
            e.closest_while_moving = e.closest_while_moving.min(d);
        }
        if (r.state.position - r.goal).norm() < ARRIVAL {
            e.arrived = true;
            break;
        }
    }
    e
}

/// The PGP paper's collision criterion: a body overlap counts while the robot moves ("if an
/// agent is standing, it should not be responsible for avoiding collisions").
///
/// The lateral offsets are small but never exactly zero: a perfectly symmetric head-on meeting
/// is a degenerate equilibrium of the Social Force Model (the interaction angle is 0, so there
/// is no sideways force at all), which no real sensor reading reproduces.
///
/// The plain Social Force planner is the exception the paper reports: SF agents brush past
/// people (PySocialForce's own head-on pair passes at 0.565 m between centres, bodies of 0.7 m;
/// see tests/fixtures/pysf_head_on_pair_default.json), and PGP "drastically reduces" SF's
/// collisions. For SF we assert arrival and that PGP+SF passes wider than SF in the same
/// encounter.
#[test]
fn head_on_with_a_person_passes_without_collision_for_every_planner() {
    let contact = RADIUS + 0.35;
    for offset in [0.02, 0.1, -0.3] {
        let mut closest = std::collections::HashMap::new();
        for spec in PlannerSpec::STUDY {
            let e = robot_meets_person(spec, offset);
            println!(
                "{spec} vs person (offset {offset} m): closest {:.3} m, while moving {:.3} m, arrived {}",
                e.closest, e.closest_while_moving, e.arrived
            );
            assert!(e.arrived, "{spec}: the robot must reach its goal");
            if spec.to_string() != "sf" {
                assert!(
                    e.closest_while_moving >= contact,
                    "{spec}: collided while moving ({:.3} m)",
                    e.closest_while_moving
                );
            }
            closest.insert(spec.to_string(), e.closest_while_moving);
        }
        assert!(
            closest["pgp+sf"] > closest["sf"],
            "PGP must widen the SF agent's pass (offset {offset} m)"
        );
    }
}

#[test]
fn head_on_robot_pair_passes_for_reciprocal_planners() {
    // ORCA assumes the other side does half of the avoiding; two ORCA robots must pass.
    // (Two DWA robots, which predict each other linearly and do not assume reciprocity, can
    // yield to each other into a standoff: the freezing-robot problem.)
    for spec in ["orca", "pgp+orca"] {
        let spec: PlannerSpec = spec.parse().expect("known planner");
        let mut pair = [
            robot(spec, vec2(-5.0, 0.0), vec2(5.0, 0.05)),
            robot(spec, vec2(5.0, 0.05), vec2(-5.0, 0.0)),
        ];
        let (min_dist, arrived) = run(&mut pair, &StaticMap::empty(), 40.0);
        println!("{spec} pair: closest approach {min_dist:.3} m, arrived {arrived}");
        assert!(arrived, "{spec}: both robots must reach their goals");
        assert!(
            min_dist >= 2.0 * RADIUS,
            "{spec}: bodies overlapped (closest {min_dist:.3} m)"
        );
    }
}
