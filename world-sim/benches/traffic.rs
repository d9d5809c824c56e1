//! The coordinator's traffic step (issue 22): the traffic monitor (stuck robots, the wait-for
//! graph and its cycles) and the traffic policy (segment reservations, holds, station lines,
//! lanes, retreats) over 200 robots, after 20 s of a large narrow-aisle warehouse (20 rows in 6
//! blocks, 1.5 m aisles, 200 people, 200 robots planning with pgp+orca under the safety
//! layer); and again after 120 s, when robots have been stuck long enough for what holds
//! them and for gridlocks to be worked out at every step.
//!
//! Target: ≤ 1 ms median, both.
//!
//!     cargo bench -p world-sim --bench traffic

use agent::model::Command;
use agent::planner::PlannerStack;
use criterion::{Criterion, criterion_group, criterion_main};
use world_sim::episode::guards;
use world_sim::fleet::{Fleet, drive};
use world_sim::scenario::Scenario;
use world_sim::traffic_policy::PolicyParams;

/// The fleet after `ticks` steps.
fn fleet(ticks: usize) -> Fleet {
    let mut s = Scenario::builtin("warehouse-narrow").expect("valid");
    let w = s.warehouse.as_mut().expect("layout");
    (w.rows, w.blocks, w.docks, w.humans, w.robots) = (20, 6, 20, 200, 200);
    s.validate("bench").expect("valid");
    let mut fleet = Fleet::new(&s).expect("a warehouse");
    fleet.set_traffic_policy(Some(PolicyParams::default()));
    let n = fleet.robots();
    let planner = "pgp+orca".parse().expect("known");
    let mut stacks: Vec<PlannerStack> = (0..n)
        .map(|_| {
            let mut stack = PlannerStack::with_max_speed(planner, s.robot.max_speed);
            stack.set_record_fan(false);
            stack
        })
        .collect();
    let mut guards = guards(&s, n);
    let mut commands = vec![Command::STOP; n];
    for _ in 0..ticks {
        drive(&mut fleet, &mut stacks, &mut guards, &mut commands);
    }
    fleet
}

fn traffic(c: &mut Criterion) {
    let mut g = c.benchmark_group("traffic");
    let mut early = fleet(200);
    g.bench_function("step-200-robots", |b| b.iter(|| early.update_traffic()));
    let mut late = fleet(1200);
    let stuck = (0..late.robots())
        .filter(|&i| late.traffic().is_stuck(i))
        .count();
    eprintln!(
        "after 120 s: {stuck} robots stuck, {} in gridlocks",
        late.traffic()
            .gridlocked()
            .iter()
            .map(Vec::len)
            .sum::<usize>()
    );
    g.bench_function("step-200-robots-120s", |b| b.iter(|| late.update_traffic()));
    g.finish();
}

criterion_group!(benches, traffic);
criterion_main!(benches);
