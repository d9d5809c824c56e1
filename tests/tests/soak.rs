//! The soak's short versions (`gapfleet bench soak` runs the long one), as fast as the machine
//! allows: ten `pgp+orca` agents among 40 people (the shipped configuration: safety layer and
//! traffic policy on) over Zenoh for 4,000 ticks, and a hundred for 1,000 with both cores
//! saturated. No observation is lost (the demo lets the last tick's land before its agents go),
//! nothing is rejected, and every window reports.

use coordinator::bench::soak::{Soak, bench_soak};
use std::time::Duration;
use world_sim::scenario::Scenario;

/// `agents` agents planning with `planner` for `ticks` ticks of the large warehouse among
/// `humans` people, 2 s windows; checks that every tick ran and every agent was observed on each.
fn soak(agents: usize, humans: usize, planner: &str, ticks: u64) -> Soak {
    let mut scenario = Scenario::builtin("warehouse-large").expect("built in");
    assert!(scenario.set_fleet_size(Some(agents), Some(humans)));
    assert!(
        scenario.robot.safety,
        "the shipped configuration has the layer on"
    );
    let soak = gapfleet_tests::runtime()
        .block_on(bench_soak(
            scenario,
            planner.parse().expect("a planner"),
            agents,
            ticks,
            1000.0,
            Duration::from_secs(2),
            Duration::from_secs(600),
            std::future::pending(),
            |_| {},
        ))
        .expect("the soak runs");
    println!("{soak:#?}");
    assert_eq!(soak.ticks, ticks);
    assert_eq!(soak.observations, ticks * agents as u64);
    soak
}

#[test]
fn a_short_soak_loses_nothing() {
    let soak = soak(10, 40, "pgp+orca", 4000);
    assert_eq!(soak.lost, 0, "observations lost");
    assert_eq!(soak.rejected, 0);
    assert!(soak.tasks > 0, "the fleet worked through the soak");
    assert!(!soak.windows.is_empty());
    assert!(soak.windows.iter().all(|w| w.rss_mib > 0.0
        && w.anon_mib > 0.0
        && w.threads > 0
        && w.state_kib > 0.0
        && w.p99_ms.is_finite()));
}

/// A hundred agents keep both cores busy. When the fleet's publications were express, each took
/// a send batch of its own, an agent's third message in a row found none within Zenoh's 1 ms,
/// and observations were dropped: 47 in 10,000 ticks of `bench soak --planner dwa`.
#[test]
fn a_saturated_fleet_loses_nothing() {
    let soak = soak(100, 0, "dwa", 1000);
    assert_eq!(soak.lost, 0, "observations lost");
    assert_eq!(soak.missed, 0, "gaps seen by the agents");
    assert_eq!(soak.rejected, 0);
}
