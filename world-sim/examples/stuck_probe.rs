//! What stuck robots are doing: runs one fleet (policy on, layer as the scenario says) and,
//! every 5 s, prints each stuck robot's cause, place, speed, distance to the point it drives
//! to, the nearest person and robot, and its traffic constraint; each gridlock and deadlock
//! as it begins (its robots, where they stand, what holds each); then the totals by cause,
//! and the stuck time held by a person split by place and by whether the nearest person
//! heads through the robot (their goal lies beyond it: a standoff). Then where the time and
//! the metres of robots with a task went: a time budget by the policy's constraint and speed;
//! slow seconds by place, and next to a person by where that person is and how they walk;
//! metres driven against metres of progress along the route (its length left falling), split
//! by whether the safety layer held the command back (its protective check or a yield) and
//! whether a person was within 2 m.
//!
//!     cargo run --release -p world-sim --example stuck_probe -- warehouse-narrow 20 1 \
//!         [300 [ROBOT [PLANNER [PEOPLE [POLICY]]]]]
//!
//! The scenario is a built-in's name or a scenario file (`….toml`). With ROBOT, also that
//! robot's position, velocity, goal, waypoint and route left every second, and each time
//! the policy turns it round (`-` for none).
//! PLANNER defaults to `pgp+orca`, PEOPLE to the scenario's (`-`), POLICY (traffic-policy
//! parameters as `key=value,…`) to the defaults.

use agent::model::Command;
use agent::planner::PlannerSpec;
use world_sim::fleet::{Fleet, Stalls, drive, stacks};
use world_sim::scenario::Scenario;
use world_sim::traffic::TrafficEvent;
use world_sim::traffic_policy::PolicyParams;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map_or("warehouse-narrow", String::as_str);
    let robots: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(20);
    let seed: u64 = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(1);
    let seconds: f64 = args.get(3).and_then(|a| a.parse().ok()).unwrap_or(300.0);
    // A robot to follow every second (the fifth argument).
    let watch: Option<usize> = args.get(4).and_then(|a| a.parse().ok());
    let planner: PlannerSpec = args
        .get(5)
        .map_or("pgp+orca", String::as_str)
        .parse()
        .expect("a known planner");
    let people: Option<usize> = args.get(6).and_then(|a| a.parse().ok());
    let mut scenario = Scenario::load(name)
        .expect("a built-in scenario or a scenario file")
        .0;
    scenario.seed = seed;
    scenario.set_fleet_size(Some(robots), people);
    let mut fleet = Fleet::new(&scenario).expect("a fleet site");
    let policy = PolicyParams::default()
        .with_overrides(args.get(7).map_or("", String::as_str))
        .expect("traffic-policy parameters as key=value,…");
    fleet.set_traffic_policy(Some(policy));
    let mut stacks = stacks(&fleet, planner, scenario.robot.max_speed);
    let mut guards = world_sim::episode::fleet_guards(&scenario, &fleet);
    let mut commands = vec![Command::STOP; robots];
    let steps = (seconds / fleet.world.dt).round() as u64;
    let mut stalls = Stalls::new(&fleet, 60.0);
    let mut standoff_s = [[0.0_f64; 4]; 2];
    // "Nothing visible" robot-seconds by place, split by speed: standing (< 0.1 m/s) or
    // driving (a detour that lengthened the route shows no progress while driving).
    let mut unseen_s = [[0.0_f64; 4]; 2];
    // Every robot-second: without a task, or by the policy's constraint (free or lane,
    // held for a segment, queued for a station, backing off or giving way) and speed
    // (standing < 0.1 m/s, slow < 0.7 m/s, fast).
    let mut budget = [[0.0_f64; 3]; 4];
    let mut idle_s = 0.0_f64;
    // Robot-seconds with a task below 0.7 m/s, by place, and of those with a person within
    // 2 m.
    let mut slow_s = [[0.0_f64; 4]; 2];
    // Of those with a person within 2 m, by where the nearest person is and how they walk
    // relative to the robot's way to its goal (ahead: within 60° of that way): ahead and
    // oncoming / walking its way / crossing / standing, or beside or behind; each split by
    // whether the safety layer held the robot's last command back.
    let mut slow_by_person = [[0.0_f64; 5]; 2];
    // Metres driven with a task, and robot-seconds with one.
    let mut driven_m = 0.0_f64;
    let mut task_s = 0.0_f64;
    // Progress along the route (its length left falling), routes lengthened by a re-route
    // (jumps up of over 1 m), and each robot's leg and length left at the last step.
    let mut progress_m = 0.0_f64;
    let mut rerouted_m = 0.0_f64;
    let mut last_leg: Vec<Option<(u64, f64)>> = vec![None; robots];
    // Metres driven and metres of progress, by [layer held back the command][a person within 2 m].
    let mut split_m = [[[0.0_f64; 2]; 2]; 2];
    let places = world_sim::stuck::Places::new(fleet.site());
    for k in 1..=steps {
        drive(&mut fleet, &mut stacks, &mut guards, &mut commands);
        if let (Some(i), Some(policy)) = (watch, fleet.traffic_policy())
            && let Some(exit) = policy.turned(i)
        {
            println!(
                "t {:5.1} robot {i} turned round to leave by cross-aisle {exit} (people turns so far: {})",
                fleet.world.time,
                policy.totals().people_turns
            );
        }
        if let Some(i) = watch
            && k % 10 == 0
        {
            let r = &fleet.world.robots[i];
            let crowd = &fleet.world.humans.crowd;
            let near: Vec<String> = (0..crowd.len())
                .filter(|&h| (crowd.positions[h] - r.state.position).norm() < 3.0)
                .map(|h| {
                    let (q, v, g) = (crowd.positions[h], crowd.velocities[h], crowd.goals[h]);
                    format!(
                        "#{h} ({:.1},{:.1} v {:.1},{:.1} goal {:.1},{:.1})",
                        q.x, q.y, v.x, v.y, g.x, g.y
                    )
                })
                .collect();
            println!("    people within 3 m: {}", near.join(" "));
            let robots_near: Vec<String> = fleet
                .world
                .robots
                .iter()
                .enumerate()
                .filter(|&(j, o)| j != i && (o.state.position - r.state.position).norm() < 3.0)
                .map(|(j, o)| {
                    let (q, v) = (o.state.position, o.state.velocity);
                    format!("R{j} ({:.1},{:.1} v {:.1},{:.1})", q.x, q.y, v.x, v.y)
                })
                .collect();
            println!("    robots within 3 m: {}", robots_near.join(" "));
            println!(
                "t {:5.1} robot {i} at ({:5.2},{:5.2}) v ({:5.2},{:5.2}) goal ({:5.2},{:5.2}) waypoint {:?} remaining {:.1} reroutes {}",
                fleet.world.time,
                r.state.position.x,
                r.state.position.y,
                r.state.velocity.x,
                r.state.velocity.y,
                r.goal.x,
                r.goal.y,
                fleet.job(i).and_then(|j| j.waypoint()).map(|w| (w.x, w.y)),
                fleet.job(i).map_or(0.0, |j| j.remaining(r.state.position)),
                fleet.reroutes(),
            );
        }
        for event in fleet.traffic_events() {
            let (kind, members) = match event {
                TrafficEvent::Gridlock { robots } => ("gridlock", robots),
                TrafficEvent::Deadlock { robots } => ("deadlock", robots),
                _ => continue,
            };
            let members: Vec<String> = members
                .iter()
                .map(|&j| {
                    let p = fleet.world.robots[j].state.position;
                    format!("R{j} ({:.1},{:.1}) {:?}", p.x, p.y, fleet.stuck_hold(j))
                })
                .collect();
            println!("t {:5.1} {kind}: {}", fleet.world.time, members.join(" "));
        }
        // Stuck robot-seconds held by a person, split by whether the nearest person within
        // 1.5 m heads through the robot (their goal lies beyond it: a standoff) or not.
        for i in 0..robots {
            if fleet.stuck_hold(i) != Some(world_sim::stuck::Hold::Person) {
                continue;
            }
            let p = fleet.world.robots[i].state.position;
            let crowd = &fleet.world.humans.crowd;
            let nearest = (0..crowd.len())
                .map(|h| (h, (crowd.positions[h] - p).norm()))
                .filter(|&(_, d)| d <= 1.5)
                .min_by(|a, b| a.1.total_cmp(&b.1));
            if let Some((h, _)) = nearest {
                let (q, g) = (crowd.positions[h], crowd.goals[h]);
                let through = (g - q).dot(&(p - q)) > 0.0 && (g - q).norm() > (p - q).norm();
                let place = places.of(p) as usize;
                standoff_s[usize::from(through)][place] += fleet.world.dt;
            }
        }
        for i in 0..robots {
            let r = &fleet.world.robots[i];
            if fleet.job(i).is_none() {
                idle_s += fleet.world.dt;
            } else {
                use world_sim::traffic_policy::Constraint;
                let kind = match fleet.traffic_policy().map(|t| t.constraint(i)) {
                    Some(Constraint::Hold { .. }) => 1,
                    Some(Constraint::Queue { .. }) => 2,
                    Some(Constraint::Retreat(_) | Constraint::GiveWay(_)) => 3,
                    _ => 0,
                };
                let v = r.state.velocity.norm();
                let p = r.state.position;
                // The nearest person within 2 m, and how far.
                let crowd = &fleet.world.humans.crowd;
                let nearest = (0..crowd.len())
                    .map(|h| (h, (crowd.positions[h] - p).norm()))
                    .filter(|&(_, d)| d <= 2.0)
                    .min_by(|a, b| a.1.total_cmp(&b.1));
                let near = nearest.is_some();
                driven_m += v * fleet.world.dt;
                task_s += fleet.world.dt;
                let job = fleet.job(i).expect("a task");
                let left = job.remaining(r.state.position);
                if let Some((leg, before)) = last_leg[i]
                    && leg == job.leg()
                {
                    let fell = before - left;
                    let cell = &mut split_m[usize::from(fleet.is_layer_held(i))][usize::from(near)];
                    cell[0] += v * fleet.world.dt;
                    if fell < -1.0 {
                        rerouted_m -= fell;
                    } else {
                        progress_m += fell;
                        cell[1] += fell;
                    }
                }
                last_leg[i] = Some((job.leg(), left));
                let pace = if v < 0.1 {
                    0
                } else if v < 0.7 {
                    1
                } else {
                    2
                };
                budget[kind][pace] += fleet.world.dt;
                if pace < 2 {
                    slow_s[usize::from(near)][places.of(p) as usize] += fleet.world.dt;
                    if let Some((h, d)) = nearest {
                        let way = (r.goal - p).try_normalize(1e-9).unwrap_or_default();
                        let to = (crowd.positions[h] - p) / d.max(1e-9);
                        let hv = crowd.velocities[h];
                        let kind = if to.dot(&way) < 0.5 {
                            4
                        } else if hv.norm() < 0.3 {
                            3
                        } else {
                            let along = hv.dot(&way) / hv.norm();
                            if along < -0.5 {
                                0
                            } else if along > 0.5 {
                                1
                            } else {
                                2
                            }
                        };
                        slow_by_person[usize::from(fleet.is_layer_held(i))][kind] += fleet.world.dt;
                    }
                }
            }
            if fleet.stuck_hold(i) == Some(world_sim::stuck::Hold::Planner) {
                let r = &fleet.world.robots[i];
                let driving = r.state.velocity.norm() >= 0.1;
                unseen_s[usize::from(driving)][places.of(r.state.position) as usize] +=
                    fleet.world.dt;
            }
        }
        if let Some(still) = stalls.record(&fleet) {
            // People who moved less than 1 m in the last minute.
            let crowd = &fleet.world.humans.crowd;
            let still: Vec<String> = still
                .iter()
                .map(|&h| {
                    let (q, g) = (crowd.positions[h], crowd.goals[h]);
                    format!("#{h} ({:.1},{:.1} goal {:.1},{:.1})", q.x, q.y, g.x, g.y)
                })
                .collect();
            println!(
                "t {:5.0} people who moved < 1 m in the last minute: {} {}",
                fleet.world.time,
                still.len(),
                still.join(" ")
            );
        }
        if k % 50 != 0 {
            continue;
        }
        for i in 0..robots {
            let Some(hold) = fleet.stuck_hold(i) else {
                continue;
            };
            let r = &fleet.world.robots[i];
            let p = r.state.position;
            let nearest = |qs: &mut dyn Iterator<Item = agent::math::Vec2>| {
                qs.map(|q| (q - p).norm()).fold(f64::INFINITY, f64::min)
            };
            let person = nearest(&mut fleet.world.humans.crowd.positions.iter().copied());
            let robot = nearest(
                &mut (0..robots)
                    .filter(|&j| j != i)
                    .map(|j| fleet.world.robots[j].state.position),
            );
            let constraint = fleet
                .traffic_policy()
                .map(|t| format!("{:?}", t.constraint(i)))
                .unwrap_or_default();
            println!(
                "t {:5.0} robot {i:2} {hold:?} at ({:5.1},{:5.1}) speed {:.2} to goal {:4.1} m layer {} person {:4.1} m robot {:4.1} m {constraint}",
                fleet.world.time,
                p.x,
                p.y,
                r.state.velocity.norm(),
                (r.goal - p).norm(),
                fleet.is_layer_held(i),
                person,
                robot,
            );
        }
    }
    let c = fleet.stuck_causes();
    println!(
        "tasks {} | stuck robot-s by cause: policy {:.0} person {:.0} robot {:.0} layer {:.0} planner {:.0} | gridlocks {}",
        (0..robots).map(|i| fleet.tasks_done(i)).sum::<u64>(),
        c.policy_s,
        c.person_s,
        c.robot_s,
        c.layer_s,
        c.planner_s,
        fleet.traffic().totals().gridlocks
    );
    println!(
        "held by a person, robot-s in aisle / cross-aisle / near a station / corridor: nearest person heading through the robot (a standoff) {:.0?}, otherwise {:.0?}",
        standoff_s[1], standoff_s[0]
    );
    println!(
        "nothing visible, robot-s in aisle / cross-aisle / near a station / corridor: standing {:.0?}, driving {:.0?}",
        unseen_s[0], unseen_s[1]
    );
    println!(
        "robot-s without a task {idle_s:.0}; with one, standing / slow / fast: free or lane {:.0?}, held for a segment {:.0?}, queued for a station {:.0?}, backing off or giving way {:.0?}",
        budget[0], budget[1], budget[2], budget[3]
    );
    println!(
        "robot-s with a task below 0.7 m/s, in aisle / cross-aisle / near a station / corridor: a person within 2 m {:.0?}, nobody {:.0?}",
        slow_s[1], slow_s[0]
    );
    let done: u64 = (0..robots).map(|i| fleet.tasks_done(i)).sum();
    println!(
        "with a task: {driven_m:.0} m driven, mean speed {:.2} m/s, {:.1} m per task done",
        driven_m / task_s.max(1e-9),
        driven_m / (done as f64).max(1.0)
    );
    println!(
        "of it {progress_m:.0} m along the route, {:.0} m not ({:.0} %); re-routes added {rerouted_m:.0} m",
        driven_m - progress_m,
        100.0 * (driven_m - progress_m) / driven_m.max(1e-9)
    );
    for (held, name) in [(0, "layer passed"), (1, "layer held back")] {
        for (near, who) in [(0, "nobody within 2 m"), (1, "a person within 2 m")] {
            let [d, p] = split_m[held][near];
            println!(
                "  {name}, {who}: driven {d:.0} m, progress {p:.0} m, not {:.0} m",
                d - p
            );
        }
    }
    println!(
        "of those next to a person, the nearest ahead oncoming / walking its way / crossing / standing, or beside or behind: layer held back the command {:.0?}, not {:.0?}",
        slow_by_person[1], slow_by_person[0]
    );
}
