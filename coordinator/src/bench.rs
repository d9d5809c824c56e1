//! `gapfleet bench fleet`: the fleet's observation → command round trip with N agents at the
//! simulation's 10 Hz, messages lost, and a raw Zenoh request/reply round trip measured in the
//! same run for comparison.

use crate::demo::{DemoOptions, run_demo};
use agent::runtime::net::{Role, free_loopback_port, open_loopback};
use agent::runtime::percentile;
use anyhow::Result;
use std::time::{Duration, Instant};

/// What `bench fleet` measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FleetBench {
    /// Agents (one Zenoh session each, in this process).
    pub agents: usize,
    /// People in the world.
    pub humans: usize,
    /// Simulated (= wall) seconds.
    pub seconds: f64,
    /// Observations published.
    pub observations: u64,
    /// Observations answered by a command.
    pub answered: u64,
    /// Observations never answered.
    pub lost: u64,
    /// Observation → command round trip, ms.
    pub round_trip_p50_ms: f64,
    /// 99th percentile, ms.
    pub round_trip_p99_ms: f64,
    /// Raw Zenoh get → reply round trip with an observation-sized payload, ms.
    pub raw_zenoh_p50_ms: f64,
    /// 99th percentile, ms.
    pub raw_zenoh_p99_ms: f64,
    /// Payload size used for the raw round trip (bytes).
    pub raw_payload_bytes: usize,
}

/// Runs the fleet for `seconds` in real time with `agents` agents, then the raw round trip.
pub async fn bench_fleet(
    scenario: world_sim::scenario::Scenario,
    agents: usize,
    humans: usize,
    seconds: f64,
) -> Result<FleetBench> {
    let options = DemoOptions {
        scenario,
        planner: "pgp+orca".parse()?,
        seconds,
        speed: 1.0,
        site: "bench".to_owned(),
        listen: None,
        share_intents: true,
        sinks: dashboards::Sinks::default(),
    };
    let report = run_demo(options, std::future::pending(), |_| {}, |_| {}).await?;
    let s = &report.status;
    let (raw_p50, raw_p99, bytes) = raw_round_trip(2000).await?;
    Ok(FleetBench {
        agents,
        humans,
        seconds,
        observations: s.observations,
        answered: s.answered,
        lost: s.observations.saturating_sub(s.answered),
        round_trip_p50_ms: s.round_trip_ms.0,
        round_trip_p99_ms: s.round_trip_ms.1,
        raw_zenoh_p50_ms: raw_p50,
        raw_zenoh_p99_ms: raw_p99,
        raw_payload_bytes: bytes,
    })
}

/// `count` sequential gets from a client to a queryable on a router, on loopback, each carrying
/// and returning a payload the size of a typical observation (1 KiB).
async fn raw_round_trip(count: usize) -> Result<(f64, f64, usize)> {
    let endpoint = format!("tcp/127.0.0.1:{}", free_loopback_port()?);
    let zerr = |e: zenoh::Error| anyhow::anyhow!("raw round trip: {e}");
    let router = open_loopback(Role::Router, &endpoint).await?;
    let client = open_loopback(Role::Client, &endpoint).await?;
    let payload = vec![0x5a_u8; 1024];
    let queryable = router
        .declare_queryable("gapfleet/bench/echo")
        .await
        .map_err(zerr)?;
    let echo = tokio::spawn(async move {
        while let Ok(query) = queryable.recv_async().await {
            let body = query
                .payload()
                .map(|p| p.to_bytes().into_owned())
                .unwrap_or_default();
            let _ = query.reply(query.key_expr().clone(), body).await;
        }
    });
    // Let the queryable's declaration reach the client.
    tokio::time::sleep(Duration::from_millis(200)).await;
    let mut times = Vec::with_capacity(count);
    for _ in 0..count {
        let started = Instant::now();
        let replies = client
            .get("gapfleet/bench/echo")
            .payload(payload.clone())
            .timeout(Duration::from_secs(1))
            .await
            .map_err(zerr)?;
        let mut got = false;
        while let Ok(reply) = replies.recv_async().await {
            got |= reply.result().is_ok();
        }
        if got {
            times.push(started.elapsed().as_micros().min(u32::MAX as u128) as u32);
        }
    }
    echo.abort();
    let _ = client.close().await;
    let _ = router.close().await;
    anyhow::ensure!(!times.is_empty(), "no raw reply came back");
    Ok((
        percentile(&mut times, 0.5) / 1000.0,
        percentile(&mut times, 0.99) / 1000.0,
        payload.len(),
    ))
}

/// What `bench dashboard` measured: a coordinator tick (world step, task progress and every
/// robot's observation) with and without the Rerun dashboard attached.
#[derive(Debug, Clone, serde::Serialize)]
pub struct DashboardBench {
    /// Robots.
    pub robots: usize,
    /// People.
    pub humans: usize,
    /// Ticks timed per variant.
    pub ticks: usize,
    /// Median tick without a dashboard (µs).
    pub without_us: f64,
    /// Median tick with the dashboard recording to an .rrd file (µs).
    pub with_us: f64,
    /// (with − without) / without.
    pub overhead: f64,
    /// Frames the dashboard dropped (its thread fell behind).
    pub dropped: u64,
}

/// Times `ticks` coordinator ticks of `scenario` without, then with, a dashboard writing to
/// `rrd`. Robots are parked so both variants do identical simulation work.
pub fn bench_dashboard(
    scenario: &world_sim::scenario::Scenario,
    ticks: usize,
    rrd: &std::path::Path,
) -> Result<DashboardBench> {
    use crate::server::{Observer, Status, observation};
    use world_sim::fleet::Fleet;
    let time = |with: bool| -> Result<(f64, u64)> {
        let mut fleet = Fleet::new(scenario)?;
        let park = vec![agent::model::Command::STOP; fleet.robots()];
        let mut observer = if with {
            let sinks = dashboards::Sinks {
                rrd: Some(rrd.to_path_buf()),
                ..Default::default()
            };
            Some(crate::dashboard::DashboardObserver::start(
                &fleet, &sinks, "parked",
            )?)
        } else {
            None
        };
        let mut status = Status {
            robots: fleet.robots(),
            ..Status::default()
        };
        let mut times = Vec::with_capacity(ticks);
        for tick in 0..ticks + 20 {
            let started = Instant::now();
            let mut events = fleet.step(&park);
            events.extend(fleet.dispatch());
            for i in 0..fleet.robots() {
                std::hint::black_box(schemas::encode(&observation(&mut fleet, i, tick as u64)));
            }
            status.tick = tick as u64;
            status.sim_time = fleet.world.time;
            observer.tick(&fleet, &status, &events);
            if tick >= 20 {
                times.push(started.elapsed().as_micros().min(u32::MAX as u128) as u32);
            }
        }
        let dropped = observer.map_or(0, |o| o.finish().dropped);
        Ok((percentile(&mut times, 0.5), dropped))
    };
    let (without_us, _) = time(false)?;
    let (with_us, dropped) = time(true)?;
    Ok(DashboardBench {
        robots: scenario.warehouse.map_or(0, |w| w.robots),
        humans: scenario.warehouse.map_or(0, |w| w.humans),
        ticks,
        without_us,
        with_us,
        overhead: (with_us - without_us) / without_us,
        dropped,
    })
}
