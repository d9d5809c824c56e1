//! `gapfleet bench fleet`: the fleet's observation → command round trip with N agents at the
//! simulation's 10 Hz, messages lost, and a raw Zenoh request/reply round trip measured in the
//! same run for comparison.

use super::BenchError;
use super::machine::{CpuSpeed, CpuSpeedProbe, CpuTimes, overlaps};
use crate::serve::RoundTrip;
use crate::serve::demo::{DemoOptions, Transport, run_demo};
use agent::planner::{LocalKind, PlannerSpec};
use agent::runtime::percentile;
use fleet_net::{Role, free_loopback_port, open_loopback};
use std::time::{Duration, Instant};

type Result<T> = std::result::Result<T, BenchError>;

/// What `bench fleet` measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FleetBench {
    /// Agents (one Zenoh session each, in this process).
    pub agents: usize,
    /// People in the world.
    pub humans: usize,
    /// Simulated seconds.
    pub seconds: f64,
    /// Wall seconds the coordinator took for them (= `seconds` when it keeps real time).
    pub wall_seconds: f64,
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
    /// The worst agent's planning-time p99 in its last heartbeat (µs): the planner's share.
    pub planner_p99_us: f64,
    /// Raw Zenoh get → reply round trip with an observation-sized payload, measured while the
    /// fleet runs (the same process, cores and moment), ms.
    pub raw_zenoh_p50_ms: f64,
    /// 99th percentile, ms.
    pub raw_zenoh_p99_ms: f64,
    /// Raw round trips timed while the fleet ran (one every 10 ms).
    pub raw_samples: usize,
    /// The same raw round trip on the idle machine after the run (2,000 back to back), ms.
    pub raw_idle_p50_ms: f64,
    /// 99th percentile, ms.
    pub raw_idle_p99_ms: f64,
    /// Payload size used for the raw round trips (bytes).
    pub raw_payload_bytes: usize,
    /// While the fleet ran: the share of the machine's CPU time (all cores) that this process
    /// used, % (Linux `/proc`; None elsewhere).
    pub process_cpu_percent: Option<f64>,
    /// While the fleet ran: the share of the machine's CPU time that the hypervisor reported
    /// stealing, %.
    pub steal_percent: Option<f64>,
    /// While the fleet ran: how fast the CPU itself ran (a fixed job timed every 5 ms in its
    /// own thread's CPU time; see [`super::machine`]). On a shared VM the host slows the CPU
    /// down at times without the steal counter showing it, and round-trip tails follow.
    pub cpu_speed: Option<CpuSpeed>,
    /// Share of the timed run covered by stretches in which the probe found the CPU slow, %.
    pub slow_cpu_time_percent: f64,
    /// Round trips that overlapped such a stretch (of those inside the probe's run, which
    /// began before the first observation and ended after the last command).
    pub round_trips_in_slow_cpu: u64,
    /// Round-trip p99 over the others, ms: what the fleet does while the CPU runs at its
    /// speed. A diagnostic, not the result: the result is [`FleetBench::round_trip_p99_ms`].
    pub round_trip_p99_clear_ms: Option<f64>,
}

/// Runs the fleet for `seconds` in real time with `agents` agents over `transport`, then the
/// raw round trip (plain TCP).
pub async fn bench_fleet(
    scenario: world_sim::scenario::Scenario,
    agents: usize,
    humans: usize,
    seconds: f64,
    transport: Transport,
) -> Result<FleetBench> {
    let (round_trips_tx, round_trips_rx) = std::sync::mpsc::channel();
    let options = DemoOptions {
        scenario,
        planner: PlannerSpec {
            pgp: true,
            local: LocalKind::Orca,
        },
        seconds,
        speed: 1.0,
        keys: schemas::Keys::new("bench").expect("a valid site name"),
        listen: None,
        transport,
        journal: None,
        share_intents: true,
        traffic_policy: Some(Default::default()),
        sinks: dashboards::Sinks::default(),
        round_trips: Some(round_trips_tx),
        ros: false,
    };
    // The raw probe runs beside the fleet until the fleet is done.
    let probe = RawProbe::open().await?;
    // The CPU-speed probe runs from before the first observation to after the last command.
    let speed = CpuSpeedProbe::start().map_err(BenchError::Probe)?;
    // It times round trips only once the coordinator ticks (its first status, after about a
    // second), not while a hundred sessions are being opened.
    let (ticking_tx, ticking_rx) = tokio::sync::watch::channel(false);
    let (stop_tx, stop_rx) = tokio::sync::watch::channel(false);
    let stopper = stop_tx.clone();
    let during = {
        let probe = probe.clone();
        tokio::spawn(async move {
            probe
                .run_paced(Duration::from_millis(10), ticking_rx, stop_rx)
                .await
        })
    };
    // It stops with the coordinator's final status, before the agents shut down. The first
    // status (about a wall second in) also dates the first tick, for the wall time.
    let started = Instant::now();
    let first_tick = std::sync::Arc::new(std::sync::OnceLock::<Instant>::new());
    let first_tick_seen = first_tick.clone();
    // CPU time counters from the first status to the last (the part of the run timed).
    let cpu = std::sync::Arc::new(std::sync::Mutex::new((None, None)));
    let cpu_seen = cpu.clone();
    let on_status = move |s: &crate::serve::Status, _: &world_sim::fleet::Fleet| {
        first_tick_seen.get_or_init(|| Instant::now() - Duration::from_secs_f64(s.sim_time));
        if s.tick > 0 {
            ticking_tx.send_if_modified(|t| !std::mem::replace(t, true));
        }
        if let Ok(mut c) = cpu_seen.lock() {
            let now = CpuTimes::now();
            c.0 = c.0.or(now);
            c.1 = now;
        }
        if s.sim_time >= seconds - 1e-9 {
            stop_tx.send_if_modified(|t| !std::mem::replace(t, true));
        }
    };
    let report = run_demo(options, std::future::pending(), on_status, |_| {}).await;
    let speed = speed.finish();
    let wall_seconds = first_tick.get().unwrap_or(&started).elapsed().as_secs_f64();
    let _ = stopper.send(true);
    let mut during = during.await??;
    let report = report?;
    let mut idle = probe.run_back_to_back(2000).await?;
    probe.close().await;
    if during.is_empty() {
        return Err(BenchError::NoReply("while the fleet ran"));
    }
    let cpu_speed = speed.summary();
    // Round trips split by whether the CPU may have run slow during them.
    let spans = speed.slow_spans();
    let window = speed.window();
    let timed = window
        .as_ref()
        .map_or(Duration::ZERO, |w| w.end.saturating_duration_since(w.start));
    let slow_time: Duration = spans.iter().map(|s| s.end - s.start).sum();
    let mut clear_us = Vec::new();
    let mut in_slow = 0_u64;
    let probed = |rt: &RoundTrip| {
        window
            .as_ref()
            .is_some_and(|w| w.start <= rt.published && rt.arrived <= w.end)
    };
    for rt in round_trips_rx.try_iter().filter(probed) {
        if overlaps(&spans, rt.published, rt.arrived) {
            in_slow += 1;
        } else {
            let us = rt
                .arrived
                .saturating_duration_since(rt.published)
                .as_micros();
            clear_us.push(us.min(u128::from(u32::MAX)) as u32);
        }
    }
    let s = &report.status;
    // A poisoned lock only means a status callback panicked; its counters are still whole.
    let counters = *cpu
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let shares = match counters {
        (Some(first), Some(last)) => first.shares(last),
        _ => None,
    };
    Ok(FleetBench {
        agents,
        humans,
        seconds,
        wall_seconds,
        observations: s.observations,
        answered: s.answered,
        lost: s.observations.saturating_sub(s.answered),
        round_trip_p50_ms: s.round_trip_ms.0,
        round_trip_p99_ms: s.round_trip_ms.1,
        planner_p99_us: s.planner_p99_us,
        raw_samples: during.len(),
        raw_zenoh_p50_ms: percentile(&mut during, 0.5) / 1000.0,
        raw_zenoh_p99_ms: percentile(&mut during, 0.99) / 1000.0,
        raw_idle_p50_ms: percentile(&mut idle, 0.5) / 1000.0,
        raw_idle_p99_ms: percentile(&mut idle, 0.99) / 1000.0,
        raw_payload_bytes: RAW_PAYLOAD_BYTES,
        process_cpu_percent: shares.map(|s| s.0),
        steal_percent: shares.map(|s| s.1),
        cpu_speed,
        slow_cpu_time_percent: if timed.is_zero() {
            0.0
        } else {
            100.0 * slow_time.as_secs_f64() / timed.as_secs_f64()
        },
        round_trips_in_slow_cpu: in_slow,
        round_trip_p99_clear_ms: (!clear_us.is_empty())
            .then(|| percentile(&mut clear_us, 0.99) / 1000.0),
    })
}

/// Payload of the raw round trips: a typical observation's size.
const RAW_PAYLOAD_BYTES: usize = 1024;

/// Raw Zenoh request/reply on loopback: a client's get to a queryable on a router that echoes
/// the payload; the same two hops (router ⇄ client) as an observation and its command.
#[derive(Clone)]
struct RawProbe {
    router: zenoh::Session,
    client: zenoh::Session,
    echo: std::sync::Arc<tokio::task::JoinHandle<()>>,
}

impl RawProbe {
    async fn open() -> Result<Self> {
        let endpoint = format!(
            "tcp/127.0.0.1:{}",
            free_loopback_port().map_err(BenchError::Port)?
        );
        let router = open_loopback(Role::Router, &endpoint).await?;
        let client = open_loopback(Role::Client, &endpoint).await?;
        let queryable = router
            .declare_queryable("gapfleet/bench/echo")
            .await
            .map_err(BenchError::Raw)?;
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
        Ok(Self {
            router,
            client,
            echo: std::sync::Arc::new(echo),
        })
    }

    /// One get → reply, µs (None if no reply came within 1 s).
    async fn once(&self, payload: &[u8]) -> Result<Option<u32>> {
        let started = Instant::now();
        let replies = self
            .client
            .get("gapfleet/bench/echo")
            .payload(payload.to_vec())
            .timeout(Duration::from_secs(1))
            .await
            .map_err(BenchError::Raw)?;
        let mut got = false;
        while let Ok(reply) = replies.recv_async().await {
            got |= reply.result().is_ok();
        }
        Ok(got.then(|| started.elapsed().as_micros().min(u32::MAX as u128) as u32))
    }

    /// `count` round trips back to back.
    async fn run_back_to_back(&self, count: usize) -> Result<Vec<u32>> {
        let payload = vec![0x5a_u8; RAW_PAYLOAD_BYTES];
        let mut times = Vec::with_capacity(count);
        for _ in 0..count {
            times.extend(self.once(&payload).await?);
        }
        if times.is_empty() {
            return Err(BenchError::NoReply("on the idle machine"));
        }
        Ok(times)
    }

    /// One round trip every `period` from when `start` turns true until `stop` changes.
    async fn run_paced(
        &self,
        period: Duration,
        mut start: tokio::sync::watch::Receiver<bool>,
        mut stop: tokio::sync::watch::Receiver<bool>,
    ) -> Result<Vec<u32>> {
        let payload = vec![0x5a_u8; RAW_PAYLOAD_BYTES];
        let mut times = Vec::new();
        tokio::select! {
            _ = stop.changed() => return Ok(times),
            _ = start.wait_for(|s| *s) => {}
        }
        let mut ticker = tokio::time::interval(period);
        ticker.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
        loop {
            tokio::select! {
                _ = stop.changed() => break,
                _ = ticker.tick() => times.extend(self.once(&payload).await?),
            }
        }
        Ok(times)
    }

    async fn close(self) {
        self.echo.abort();
        let _ = self.client.close().await;
        let _ = self.router.close().await;
    }
}
