//! Every step in which two robots touch, in one seed of the intent-sharing study (the built-in
//! `warehouse`, 12 robots, 40 people, `pgp+orca`, 300 s; `run_fleet`'s loop), with both
//! robots' state, command, goal and PGP subgoal, and the people and robots within 3 m:
//!
//!     cargo run --release -p world-sim --example contact_episodes -- <seed> [on|off] [--no-safety]
//!
//! `on|off` switches intent sharing; the safety layer runs under every planner, as in the
//! study, unless `--no-safety` (how the study first ran). Written to look at
//! the contact episodes that decide the study's contact test (see
//! results/intent-sharing/REPORT.md); ends with the number of pair-steps in contact.
use agent::model::Command;
use agent::planner::PlannerStack;
use world_sim::fleet::{Fleet, plan_all};
use world_sim::scenario::Scenario;

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let seed: u64 = args
        .first()
        .map_or(Ok(53), |s| s.parse())
        .map_err(|e| format!("{e}"))?;
    let share = args.get(1).is_none_or(|s| s != "off");
    let safety = !args.iter().any(|a| a == "--no-safety");
    let robots = 12;
    let mut scenario = Scenario::builtin("warehouse").map_err(|e| e.to_string())?;
    scenario.seed = seed;
    let w = scenario.warehouse.as_mut().ok_or("no warehouse")?;
    w.robots = robots;
    w.humans = 40;
    scenario.robot.safety = safety;
    let mut fleet = Fleet::new(&scenario).map_err(|e| e.to_string())?;
    fleet.share_intents = share;
    let planner = "pgp+orca".parse().map_err(|e| format!("{e}"))?;
    let mut stacks: Vec<PlannerStack> = (0..robots).map(|_| PlannerStack::new(planner)).collect();
    let mut commands = vec![Command::STOP; robots];
    let mut subgoals = vec![None; robots];
    let mut guards = world_sim::episode::guards(&scenario, robots);
    let mut pair_steps = 0;
    for step in 0..3000 {
        fleet.dispatch();
        for (i, subgoal) in subgoals.iter_mut().enumerate() {
            if fleet.goal(i).is_none() {
                *subgoal = None;
            }
        }
        plan_all(&mut fleet, &mut stacks, &mut commands, |i, stack, input| {
            let plan = match &mut guards[i] {
                Some(guard) => guard.plan(stack, input).0,
                None => stack.plan(input),
            };
            subgoals[i] = Some(plan.intent.subgoal);
            plan
        });
        fleet.step(&commands);
        let r = &fleet.world.robots;
        for i in 0..r.len() {
            for j in i + 1..r.len() {
                let d = (r[i].state.position - r[j].state.position).norm();
                let gap = d - r[i].state.radius - r[j].state.radius;
                if gap < 0.0 {
                    pair_steps += 1;
                    let s = |k: usize| {
                        let st = &r[k].state;
                        format!(
                            "p=({:.2},{:.2}) v=({:.2},{:.2}) cmd={:?} goal={:?} sub={:?} job={:?} wall={:.2}",
                            st.position.x,
                            st.position.y,
                            st.velocity.x,
                            st.velocity.y,
                            commands[k],
                            fleet.goal(k).map(|g| (g.x * 100.0).round() / 100.0),
                            subgoals[k].map(|g: agent::math::Vec2| (
                                (g.x * 100.0).round() / 100.0,
                                (g.y * 100.0).round() / 100.0
                            )),
                            fleet.job(k).map(|j| j.stage),
                            fleet.world.map.distance(&st.position)
                        )
                    };
                    println!(
                        "step {step} t {:.1} pair {i}-{j} gap {gap:.3}\n   {i}: {}\n   {j}: {}",
                        fleet.world.time,
                        s(i),
                        s(j)
                    );
                    let c = &fleet.world.humans.crowd;
                    for h in 0..c.positions.len() {
                        let d = (c.positions[h] - r[i].state.position).norm();
                        if d < 3.0 {
                            println!(
                                "   human {h}: p=({:.2},{:.2}) v=({:.2},{:.2}) d={d:.2}",
                                c.positions[h].x,
                                c.positions[h].y,
                                c.velocities[h].x,
                                c.velocities[h].y
                            );
                        }
                    }
                    for k in 0..r.len() {
                        if k != i && k != j {
                            let d = (r[k].state.position - r[i].state.position).norm();
                            if d < 3.0 {
                                println!(
                                    "   robot {k}: p=({:.2},{:.2}) v=({:.2},{:.2}) d={d:.2}",
                                    r[k].state.position.x,
                                    r[k].state.position.y,
                                    r[k].state.velocity.x,
                                    r[k].state.velocity.y
                                );
                            }
                        }
                    }
                }
            }
        }
    }
    println!(
        "seed {seed}, sharing {}, safety {}: {pair_steps} pair-steps in contact",
        if share { "on" } else { "off" },
        if safety { "on" } else { "off" }
    );
    Ok(())
}
