//! Whether a fleet goes on working when some of its robots are lost mid-run (held where they
//! stand, as the coordinator holds a real robot whose reports stop): robots `LOST` (the last
//! ones) are held from each loss time in turn, and the tasks the others finish in the
//! `AFTER` seconds that follow are printed, one line per loss time, with the run's contacts
//! of every cause; then where each robot ends, what it is bound for and what the policy asks.
//!
//!     cargo run --release -p world-sim --example lost_robots -- SITE ROBOTS PEOPLE SEED \
//!         LOST AFTER FROM TO EVERY
//!
//! Loss times run from FROM to TO seconds in steps of EVERY; a line whose `after` is 0 is a
//! fleet the lost robots stopped.

use agent::math::Real;
use agent::model::Command;
use world_sim::fleet::{Fleet, drive, stacks};
use world_sim::scenario::Scenario;
use world_sim::traffic_policy::PolicyParams;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, default: &str| args.get(i).cloned().unwrap_or(default.to_owned());
    let name = arg(0, "warehouse");
    let robots: usize = arg(1, "4").parse().expect("robots");
    let people: usize = arg(2, "0").parse().expect("people");
    let seed: u64 = arg(3, "3").parse().expect("seed");
    let lost: usize = arg(4, "2").parse().expect("lost robots");
    let after: Real = arg(5, "150").parse().expect("seconds after");
    let from: Real = arg(6, "10").parse().expect("from");
    let to: Real = arg(7, "120").parse().expect("to");
    let every: Real = arg(8, "5").parse().expect("every");
    let mut scenario = Scenario::builtin(&name).expect("a built-in fleet scenario");
    scenario.seed = seed;
    scenario.set_fleet_size(Some(robots), Some(people));
    let mut at = from;
    while at <= to + 1e-9 {
        let mut fleet = Fleet::new(&scenario).expect("a fleet site");
        fleet.set_traffic_policy(Some(PolicyParams::default()));
        let mut stacks = stacks(
            &fleet,
            "pgp+orca".parse().expect("known"),
            scenario.robot.max_speed,
        );
        let mut guards = world_sim::episode::fleet_guards(&scenario, &fleet);
        let mut commands = vec![Command::STOP; robots];
        let dt = fleet.world.dt;
        for _ in 0..(at / dt).round() as u64 {
            drive(&mut fleet, &mut stacks, &mut guards, &mut commands);
        }
        let live = robots - lost;
        let before: u64 = (0..live).map(|i| fleet.tasks_done(i)).sum();
        for i in live..robots {
            fleet.set_held(i, true);
        }
        let mut first_after = None;
        let steps = (after / dt).round() as u64;
        for k in 0..steps {
            drive(&mut fleet, &mut stacks, &mut guards, &mut commands);
            let done: u64 = (0..live).map(|i| fleet.tasks_done(i)).sum();
            if first_after.is_none() && done > before {
                first_after = Some(k as Real * dt);
            }
        }
        let done: u64 = (0..live).map(|i| fleet.tasks_done(i)).sum();
        let first = first_after.map_or("never".to_owned(), |t| format!("{t:.0} s"));
        // Contacts over the whole run, every cause.
        let s = world_sim::fleet::FleetSummary::of(&fleet);
        println!(
            "{name} seed {seed}: robots {live}.. lost at {at:.0} s: {} tasks in the {after:.0} s after (first after {first}); contacts over the run: {} robot-caused, {} person-caused, {} robot-robot, {} wall, {} total",
            done - before,
            s.robot_caused_contacts,
            s.person_caused_contacts,
            s.robot_robot_contacts,
            s.wall_contacts,
            s.total_contacts
        );
        // Where each robot ends: its station, how far it is, what the policy asks of it.
        for i in 0..robots {
            let here = fleet.world.robots[i].state.position;
            let station = fleet.job(i).map(|j| j.station());
            let far = station.map(|s| (fleet.site().stations[s].position - here).norm());
            let constraint = fleet.traffic_policy().map(|p| p.constraint(i));
            println!(
                "  robot {i}{}: at ({:.1}, {:.1}), station {station:?} {far:.1?} m away, {constraint:?}",
                if i >= live { " (lost)" } else { "" },
                here.x,
                here.y
            );
        }
        at += every;
    }
}
