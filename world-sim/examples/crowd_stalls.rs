//! How often simulated people stand still on the fleet sites, with and without giving up a
//! goal they have stalled short of (`humans.regoal_stalled_s`), against the recorded crowds'
//! figures (`results/people-stalls/recorded.py`): the share of person-time slower than
//! 0.1 m/s, and the share of 10 s windows in which a person moved less than 1 m. One robot
//! runs on each site (pgp+orca under its layer, the traffic policy on), as in the fleet
//! studies' one-robot cells.
//!
//!     cargo run --release -p world-sim --example crowd_stalls -- [SEEDS [SECONDS [TIMES]]]
//!
//! TIMES: the goal-giving-up times to compare with never, comma-separated (default `20`).

use agent::model::Command;
use agent::planner::PlannerSpec;
use world_sim::fleet::{Fleet, Stalls, drive, stacks};
use world_sim::scenario::Scenario;
use world_sim::traffic_policy::PolicyParams;

/// Person-steps slower than this are standing (m/s).
const STANDING: f64 = 0.1;
/// Windows of this many seconds in which a person moved less than `STALLED_M` (1 m) are
/// stalled.
const WINDOW_S: f64 = 10.0;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let seeds: u64 = args.first().and_then(|a| a.parse().ok()).unwrap_or(10);
    let seconds: f64 = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(300.0);
    let times: Vec<f64> = args
        .get(2)
        .map_or("20", String::as_str)
        .split(',')
        .map(|t| t.trim().parse().expect("TIMES: seconds, comma-separated"))
        .collect();
    println!(
        "| site | goal given up after | person-time < 0.1 m/s | 10 s windows moved < 1 m | mean speed (m/s) |"
    );
    println!("|---|---|---:|---:|---:|");
    for name in ["warehouse", "warehouse-narrow", "hallway-fleet"] {
        for regoal in std::iter::once(None).chain(times.iter().copied().map(Some)) {
            let (mut slow, mut steps, mut stalled, mut windows, mut speed) = (0, 0, 0, 0, 0.0);
            for seed in 1..=seeds {
                let mut scenario = Scenario::builtin(name).expect("built in");
                scenario.seed = seed;
                scenario.set_fleet_size(Some(1), None);
                scenario.humans.regoal_stalled_s = regoal;
                let c = run(&scenario, seconds);
                slow += c.0;
                steps += c.1;
                stalled += c.2;
                windows += c.3;
                speed += c.4;
            }
            let after = regoal.map_or("never".to_owned(), |t| format!("{t:.0} s"));
            println!(
                "| {name} | {after} | {:.1} % | {:.1} % | {:.2} |",
                100.0 * slow as f64 / steps as f64,
                100.0 * stalled as f64 / windows as f64,
                speed / steps as f64
            );
        }
    }
}

/// (slow person-steps, person-steps, stalled windows, windows, summed speed).
fn run(scenario: &Scenario, seconds: f64) -> (usize, usize, usize, usize, f64) {
    let planner: PlannerSpec = "pgp+orca".parse().expect("known");
    let mut fleet = Fleet::new(scenario).expect("a fleet site");
    fleet.set_traffic_policy(Some(PolicyParams::default()));
    let mut stacks = stacks(&fleet, planner, scenario.robot.max_speed);
    let mut guards = world_sim::episode::guards(scenario, fleet.robots());
    let mut commands = vec![Command::STOP; fleet.robots()];
    let steps = (seconds / fleet.world.dt).round() as u64;
    let mut stalls = Stalls::new(&fleet, WINDOW_S);
    let mut out = (0, 0, 0, 0, 0.0);
    for _ in 0..steps {
        drive(&mut fleet, &mut stacks, &mut guards, &mut commands);
        let crowd = &fleet.world.humans.crowd;
        for v in &crowd.velocities {
            out.0 += usize::from(v.norm() < STANDING);
            out.1 += 1;
            out.4 += v.norm();
        }
        if let Some(still) = stalls.record(&fleet) {
            out.2 += still.len();
            out.3 += fleet.world.humans.crowd.len();
        }
    }
    out
}
