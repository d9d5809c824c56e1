//! What the safety layer did in hallway-study runs, and where the robot went: per run, the
//! plans by the layer's zone (clear, warning, protective, yield), the plans in which the robot
//! moved away from its goal (backing), and the plans it spent outside the hallway's walls
//! (behind its start, or beyond the side walls, which closed ends now prevent). Over all
//! runs: entries into personal space by how the person walked (standing, oncoming, the
//! robot's way) and by who closed the gap faster at the onset, and where across the hallway
//! the robot and the people within 5 m of it along the hallway were, in eighths of its width.
//!
//!     cargo run --release -p studies --example hallway_layer -- PLANNER LENGTH SPEEDS SEEDS
//!
//! e.g. `pnp-omni 100 2.5,3 101,102,103`. With `VERBOSE=1`, every 2 s of each run: the goal,
//! the robot, its command and zone, and the people within 3 m. The run is the study's, step
//! for step (`studies::hallway`, each step planned by `world_sim::episode::plan_robot` as in
//! `run_episode`).

use agent::map::LocalMap;
use agent::math::Real;
use agent::planner::{PlannerSpec, PlannerStack};
use agent::safety::{ACROSS_MIN_SPEED, Zone};
use studies::hallway::{HallwayStudy, hallway_scenario};
use world_sim::episode::{RobotPlan, guards, plan_robot};
use world_sim::world::World;

/// Plans per zone, backing and outside, in that order.
type Tally = [u64; 6];

fn list<T: std::str::FromStr>(text: &str, what: &str) -> Result<Vec<T>, String> {
    text.split(',')
        .map(|s| {
            s.parse()
                .map_err(|_| format!("{what}: `{s}` is not a number"))
        })
        .collect()
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 4 {
        return Err("usage: hallway_layer PLANNER LENGTH SPEEDS SEEDS".into());
    }
    let planner: PlannerSpec = args[0].parse().map_err(|e| format!("{e}"))?;
    let length: Real = args[1].parse().map_err(|e| format!("length: {e}"))?;
    let speeds: Vec<Real> = list(&args[2], "speeds")?;
    let seeds: Vec<u64> = list(&args[3], "seeds")?;
    let verbose = std::env::var_os("VERBOSE").is_some();
    let base = hallway_scenario(3.0, true).map_err(|e| e.to_string())?;
    let mut total: Tally = [0; 6];
    // Entries: standing / oncoming / same way, each person-led then robot-led.
    let mut entries = [0u64; 6];
    let mut ybins = [0u64; 8];
    let mut pbins = [0u64; 8];
    for &speed in &speeds {
        for &seed in &seeds {
            let study = HallwayStudy {
                scenario: base.clone(),
                planners: vec![planner],
                lengths: vec![length],
                width_m: 4.0,
                speeds: vec![speed],
                first_seed: seed,
                seeds: 1,
            };
            let scenario = study.scenario_for(length, speed, seed);
            let width = study.width_m;
            let mut world = World::from_scenario(&scenario);
            let mut stack = PlannerStack::with_max_speed(planner, scenario.robot.max_speed);
            stack.set_record_fan(false);
            let mut guard = guards(&scenario, 1)
                .pop()
                .flatten()
                .ok_or("the study's layer is on")?;
            let mut local = LocalMap::default();
            let steps = (scenario.max_time_s / scenario.dt_s).round() as u64;
            let mut tally: Tally = [0; 6];
            let n_people = world.humans.crowd.len();
            let mut inside = vec![false; n_people];
            for k in 0..steps {
                let goal = world.robots[0].goal;
                let robot = &world.robots[0];
                if (goal - robot.state.position).norm() <= robot.spec.goal_tolerance_m {
                    break;
                }
                let RobotPlan { ego, seen, guarded } =
                    plan_robot(&mut world, 0, &mut stack, Some(&mut guard), &mut local);
                tally[match guarded.zone {
                    Zone::Warning => 1,
                    Zone::Protective => 2,
                    Zone::Yield => 3,
                    _ => 0,
                }] += 1;
                if ego.velocity.dot(&(goal - ego.position).normalize()) < -0.05 {
                    tally[4] += 1;
                }
                let p = ego.position;
                // Which eighth of the hallway's width a point lies in.
                let eighth = |y: Real| (y / width * 8.0).floor().clamp(0.0, 7.0) as usize;
                ybins[eighth(p.y)] += 1;
                if p.x < 0.0 || p.x > length || p.y < 0.0 || p.y > width {
                    tally[5] += 1;
                }
                if verbose && k % 20 == 0 {
                    let near: Vec<String> = seen
                        .iter()
                        .filter(|n| (n.position - p).norm() < 3.0)
                        .map(|n| {
                            format!(
                                "({:.1},{:.1} v {:.1},{:.1})",
                                n.position.x, n.position.y, n.velocity.x, n.velocity.y
                            )
                        })
                        .collect();
                    println!(
                        "  t {:5.1} goal ({:.1},{:.1}) at ({:.2},{:.2}) v ({:+.2},{:+.2}) {:?} {:?} near {}",
                        world.time,
                        goal.x,
                        goal.y,
                        p.x,
                        p.y,
                        ego.velocity.x,
                        ego.velocity.y,
                        guarded.command,
                        guarded.zone,
                        near.join(" ")
                    );
                }
                // Entries into personal space (metrics::PERSONAL_SPACE_ENTRY_GAP), by who closed
                // the gap at the onset and how the person was walking.
                let crowd = &world.humans.crowd;
                let reach =
                    ego.radius + world.humans.radius + world_sim::metrics::PERSONAL_SPACE_ENTRY_GAP;
                let way_on = (goal - p).normalize();
                let people = crowd.positions.iter().zip(&crowd.velocities);
                for ((&q, &v), was) in people.zip(inside.iter_mut()) {
                    if (q.x - p.x).abs() < 5.0 {
                        pbins[eighth(q.y)] += 1;
                    }
                    let d = q - p;
                    let now = d.norm() < reach;
                    if now && !*was {
                        let u = d / d.norm();
                        let robot_closing = ego.velocity.dot(&u);
                        let person_closing = -v.dot(&u);
                        let way = if v.norm() < ACROSS_MIN_SPEED {
                            0
                        } else if v.dot(&way_on) < 0.0 {
                            1
                        } else {
                            2
                        };
                        let led = usize::from(robot_closing > person_closing);
                        entries[way * 2 + led] += 1;
                    }
                    *was = now;
                }
                world.step(&[guarded.command]);
            }
            let plans: u64 = tally[..4].iter().sum();
            println!(
                "speed {speed} seed {seed}: {:.1} s | clear {} warning {} protective {} yield {} | backing {} | outside the hallway {}",
                plans as Real * scenario.dt_s,
                tally[0],
                tally[1],
                tally[2],
                tally[3],
                tally[4],
                tally[5]
            );
            for (t, n) in total.iter_mut().zip(tally) {
                *t += n;
            }
        }
    }
    let plans = total[..4].iter().sum::<u64>().max(1) as Real;
    let share = |n: u64| 100.0 * n as Real / plans;
    println!(
        "all runs: {plans} plans | clear {:.0} % warning {:.0} % protective {:.0} % yield {:.0} % | backing {:.0} % | outside {:.1} %",
        share(total[0]),
        share(total[1]),
        share(total[2]),
        share(total[3]),
        share(total[4]),
        share(total[5])
    );
    println!(
        "personal-space entries: standing {} + {} | oncoming {} + {} | same way {} + {} (person-led + robot-led)",
        entries[0], entries[1], entries[2], entries[3], entries[4], entries[5]
    );
    println!("robot across the hallway (8 bins): {ybins:?}");
    println!("people within 5 m along, across the hallway: {pbins:?}");
    Ok(())
}
