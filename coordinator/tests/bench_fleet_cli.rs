//! `gapfleet bench fleet` on a small fleet: every observation is accounted for, and the report
//! says what the machine did meanwhile (CPU shares, the CPU-speed probe, and the round trips
//! that overlapped slow CPU).

mod common;

use common::gapfleet_json;

#[test]
fn bench_fleet_accounts_for_every_observation_and_the_machine() {
    let report = gapfleet_json(&[
        "bench",
        "fleet",
        "--agents",
        "4",
        "--seconds",
        "3",
        "--json",
    ]);
    let int = |key: &str| {
        report[key]
            .as_u64()
            .unwrap_or_else(|| panic!("{key}: {report}"))
    };
    let float = |key: &str| report[key].as_f64().unwrap_or(f64::NAN);

    assert_eq!(int("agents"), 4);
    // 3 s at 10 Hz (31 ticks at most) for 4 robots, less the ticks before the agents joined.
    let observations = int("observations");
    assert!(observations > 0 && observations <= 4 * 31, "{report}");
    assert_eq!(int("answered") + int("lost"), observations);
    assert!(int("answered") > 0, "{report}");
    let (p50, p99) = (float("round_trip_p50_ms"), float("round_trip_p99_ms"));
    assert!(p50 > 0.0 && p50 <= p99, "{report}");

    // The machine: shares of all cores' CPU time, and the probe's jobs.
    for key in [
        "process_cpu_percent",
        "steal_percent",
        "slow_cpu_time_percent",
    ] {
        let share = float(key);
        assert!((0.0..=100.0).contains(&share), "{key} = {share}");
    }
    let speed = &report["cpu_speed"];
    assert!(speed["samples"].as_u64().unwrap_or(0) > 0, "{report}");
    assert!(
        speed["worst_slowdown"].as_f64().unwrap_or(0.0) >= 1.0,
        "{report}"
    );
    // Round trips that overlapped slow CPU are a part of those answered; the p99 of the
    // others exists whenever some did not.
    let in_slow = int("round_trips_in_slow_cpu");
    assert!(in_slow <= int("answered"), "{report}");
    let clear = report["round_trip_p99_clear_ms"].as_f64();
    assert_eq!(clear.is_some(), in_slow < int("answered"), "{report}");
    if let Some(clear) = clear {
        assert!(clear > 0.0, "{report}");
    }
}
