//! The soak's short version (`gapfleet bench soak` runs the long one): ten agents over Zenoh
//! for 4,000 ticks as fast as the machine allows. Nothing is rejected, at most the last tick's
//! observations are still in flight when the run ends, and every window reports.

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
    assert!(
        soak.lost <= 10,
        "observations lost beyond the last tick's: {}",
        soak.lost
    );
    assert_eq!(soak.rejected, 0);
    assert!(!soak.windows.is_empty());
    assert!(
        soak.windows
            .iter()
            .all(|w| w.rss_mib > 0.0 && w.state_kib > 0.0 && w.p99_ms.is_finite())
    );
}
