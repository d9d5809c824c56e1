//! The coordinator's fleet tick with 40 real robots (placed where their agents report them)
//! against the same tick with 40 simulated ones (driven by their commands): the world step,
//! task progress, the traffic monitor and policy, and dispatch, in the default warehouse with
//! its 40 people. Both replay the same 100 ticks of a pgp+orca run from 20 s in: the simulated
//! fleet the commands, the live fleet the states those commands produced.
//!
//! Target: the live tick no slower than the simulated one. The two are timed alternately in
//! one run (15 rounds of 100 ticks each, medians and their ratio printed first), then each
//! under criterion.
//!
//!     cargo bench -p world-sim --bench live_robots

use agent::math::{Real, Vec2};
use agent::model::Command;
use agent::planner::PlannerStack;
use criterion::{BatchSize, Criterion};
use std::time::{Duration, Instant};
use world_sim::episode::guards;
use world_sim::fleet::{Fleet, drive};
use world_sim::scenario::Scenario;
use world_sim::traffic_policy::PolicyParams;

const ROBOTS: usize = 40;
const TICKS: usize = 100;

/// A robot's reported state: position, heading, velocity, turn rate.
type Report = (Vec2, Real, Vec2, Real);

/// The fleet 20 s in, and the next [`TICKS`] ticks' commands and the states they produced.
fn recorded() -> (Fleet, Vec<Vec<Command>>, Vec<Vec<Report>>) {
    let mut s = Scenario::builtin("warehouse").expect("valid");
    s.set_fleet_size(Some(ROBOTS), None);
    s.validate("bench").expect("valid");
    let mut fleet = Fleet::new(&s).expect("a warehouse");
    fleet.set_traffic_policy(Some(PolicyParams::default()));
    let planner = "pgp+orca".parse().expect("known");
    let mut stacks: Vec<PlannerStack> = (0..ROBOTS)
        .map(|_| {
            let mut stack = PlannerStack::with_max_speed(planner, s.robot.max_speed);
            stack.set_record_fan(false);
            stack
        })
        .collect();
    let mut guards = guards(&s, ROBOTS);
    let mut commands = vec![Command::STOP; ROBOTS];
    for _ in 0..200 {
        drive(&mut fleet, &mut stacks, &mut guards, &mut commands);
    }
    let start = fleet.clone();
    let (mut all_commands, mut all_states) = (Vec::new(), Vec::new());
    for _ in 0..TICKS {
        drive(&mut fleet, &mut stacks, &mut guards, &mut commands);
        all_commands.push(commands.clone());
        all_states.push(
            fleet
                .world
                .robots
                .iter()
                .map(|r| {
                    let s = &r.state;
                    (s.position, s.heading, s.velocity, s.yaw_rate)
                })
                .collect(),
        );
    }
    (start, all_commands, all_states)
}

/// [`TICKS`] ticks of simulated robots.
fn simulated(mut fleet: Fleet, commands: &[Vec<Command>]) -> Fleet {
    for c in commands {
        fleet.step(c);
        fleet.dispatch();
    }
    fleet
}

/// [`TICKS`] ticks of real robots: each placed where it reported itself, then the step.
fn live(mut fleet: Fleet, states: &[Vec<Report>]) -> Fleet {
    let stop = vec![Command::STOP; ROBOTS];
    for tick in states {
        for (i, &(p, heading, v, w)) in tick.iter().enumerate() {
            fleet.place(i, p, heading, v, w);
        }
        fleet.step(&stop);
        fleet.dispatch();
    }
    fleet
}

fn median(mut times: Vec<Duration>) -> Duration {
    times.sort();
    times[times.len() / 2]
}

fn main() {
    let (start, commands, states) = recorded();
    let mut as_live = start.clone();
    for i in 0..ROBOTS {
        as_live.set_external(i, true);
    }
    let (mut sim_times, mut live_times) = (Vec::new(), Vec::new());
    for _ in 0..15 {
        let fleet = start.clone();
        let t = Instant::now();
        std::hint::black_box(simulated(fleet, &commands));
        sim_times.push(t.elapsed() / TICKS as u32);
        let fleet = as_live.clone();
        let t = Instant::now();
        std::hint::black_box(live(fleet, &states));
        live_times.push(t.elapsed() / TICKS as u32);
    }
    let (sim, liv) = (median(sim_times), median(live_times));
    println!(
        "alternated, 15 rounds of {TICKS} ticks, 40 robots: simulated {sim:?} per tick, live {liv:?} per tick, live/simulated {:.2}",
        liv.as_secs_f64() / sim.as_secs_f64()
    );
    let mut c = Criterion::default().configure_from_args();
    let mut g = c.benchmark_group("fleet-tick-40-robots");
    g.bench_function("simulated", |b| {
        b.iter_batched(
            || start.clone(),
            |f| simulated(f, &commands),
            BatchSize::LargeInput,
        )
    });
    g.bench_function("live", |b| {
        b.iter_batched(
            || as_live.clone(),
            |f| live(f, &states),
            BatchSize::LargeInput,
        )
    });
    g.finish();
    c.final_summary();
}
