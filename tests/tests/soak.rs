//! The soak's short versions (`gapfleet bench soak` runs the long one), as fast as the machine
//! allows: ten agents over Zenoh for 4,000 ticks, and a hundred for 1,000 with both cores
//! saturated. No observation is lost (the demo lets the last tick's land before its agents go),
//! nothing is rejected, and every window reports.

use coordinator::bench::soak::bench_soak;
use std::time::Duration;
use world_sim::scenario::Scenario;

#[test]
fn a_short_soak_loses_nothing() {
    let mut scenario = Scenario::builtin("warehouse-large").expect("built in");
    assert!(scenario.set_fleet_size(Some(10), Some(0)));
    let rt = gapfleet_tests::runtime();
    let soak = rt
        .block_on(bench_soak(
            scenario,
            "pgp+orca".parse().expect("a planner"),
            10,
            4000,
            1000.0,
            Duration::from_secs(2),
            std::future::pending(),
            |_| {},
        ))
        .expect("the soak runs");
    println!("{soak:#?}");
    assert_eq!(soak.ticks, 4000);
    assert_eq!(soak.observations, 40_000);
    assert_eq!(soak.lost, 0, "observations lost");
    assert_eq!(soak.rejected, 0);
    assert!(!soak.windows.is_empty());
    assert!(
        soak.windows
            .iter()
            .all(|w| w.rss_mib > 0.0 && w.state_kib > 0.0 && w.p99_ms.is_finite())
    );
}

/// A hundred agents keep both cores busy. When the fleet's publications were express, each took
/// a send batch of its own, an agent's third message in a row found none within Zenoh's 1 ms,
/// and observations were dropped: 47 in 10,000 ticks of `bench soak --planner dwa`.
#[test]
fn a_saturated_fleet_loses_nothing() {
    let mut scenario = Scenario::builtin("warehouse-large").expect("built in");
    assert!(scenario.set_fleet_size(Some(100), Some(0)));
    let rt = gapfleet_tests::runtime();
    let soak = rt
        .block_on(bench_soak(
            scenario,
            "dwa".parse().expect("a planner"),
            100,
            1000,
            1000.0,
            Duration::from_secs(2),
            std::future::pending(),
            |_| {},
        ))
        .expect("the soak runs");
    println!("{soak:#?}");
    assert_eq!(soak.ticks, 1000);
    assert_eq!(soak.observations, 100_000);
    assert_eq!(soak.lost, 0, "observations lost");
    assert_eq!(soak.rejected, 0);
}
