//! `gapfleet bench soak`: a fleet run for a long time as fast as the machine allows, watched for
//! what grows (resident memory), what drifts (the round trip's p99, window by window) and what
//! is lost (observations never answered).

use super::BenchError;
use crate::serve::RoundTrip;
use crate::serve::demo::{DemoOptions, Transport, run_demo};
use agent::planner::PlannerSpec;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

type Result<T> = std::result::Result<T, BenchError>;

/// One window of a soak.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SoakWindow {
    /// Wall seconds since the start, at the window's end.
    pub wall_s: f64,
    /// Ticks run by then.
    pub ticks: u64,
    /// Resident memory at the window's end (MiB; Linux `/proc`, 0 elsewhere).
    pub rss_mib: f64,
    /// Of it, anonymous memory (MiB): the allocator's heaps and arenas, thread stacks, Zenoh's
    /// buffers. What the rest is: the binary's and libraries' pages, read in as code runs.
    pub anon_mib: f64,
    /// Threads of the process at the window's end. A new thread may get an allocator arena
    /// of its own, which shows as a step in anonymous memory.
    pub threads: u32,
    /// What the simulation holds at the window's end: the size of the fleet's snapshot (KiB).
    /// Steady while the world's state does not grow, whatever the process's memory does.
    pub state_kib: f64,
    /// Round trips timed in the window.
    pub round_trips: usize,
    /// Their median (ms).
    pub p50_ms: f64,
    /// Their 99th percentile (ms).
    pub p99_ms: f64,
}

/// What `bench soak` measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Soak {
    /// Agents.
    pub agents: usize,
    /// Ticks run.
    pub ticks: u64,
    /// Simulated seconds per wall second asked for.
    pub speed: f64,
    /// Wall seconds.
    pub wall_s: f64,
    /// Observations published.
    pub observations: u64,
    /// Observations answered.
    pub answered: u64,
    /// Observations that never reached their agent (sent − received, summed over agents; the
    /// last tick's may still be on their way when the run ends).
    pub lost: u64,
    /// Of those lost, the ones an agent saw missing: gaps in the sequence numbers of those that
    /// arrived, each logged (rate-limited) with its robot as it is found.
    pub missed: u64,
    /// Observations an agent received but skipped for a newer one (it plans on the newest).
    pub superseded: u64,
    /// Ticks in which a robot with a task had no fresh command.
    pub stale_commands: u64,
    /// Messages rejected.
    pub rejected: u64,
    /// The windows.
    pub windows: Vec<SoakWindow>,
    /// Resident memory growth from the end of the first window to the end of the last, %.
    pub rss_growth_percent: f64,
    /// The run after its warm-up against the warm-up; `None` when no window closed after the
    /// warm-up ended.
    pub after_warm_up: Option<AfterWarmUp>,
    /// Tasks the fleet finished.
    pub tasks: u64,
    /// Contact onsets of every cause (with people, robots, walls; each robot counts its own).
    pub contacts: u64,
    /// Of them, contacts with people the robots caused.
    pub robot_caused_contacts: u64,
}

/// A soak after its warm-up against the warm-up. The warm-up is the run's first `warm_up` of
/// wall time (600 s from the command line): a rule fixed in advance, so that where it ends is
/// not picked after looking at the curve.
#[derive(Debug, Clone, serde::Serialize)]
pub struct AfterWarmUp {
    /// Wall seconds at the end of the window that closed the warm-up (the first to close at or
    /// after it).
    pub from_wall_s: f64,
    /// Resident memory then (MiB).
    pub rss_start_mib: f64,
    /// Resident memory at the end of the run (MiB).
    pub rss_end_mib: f64,
    /// The most resident memory of any window after the warm-up (MiB).
    pub rss_peak_mib: f64,
    /// Growth from the end of the warm-up to the end of the run, %.
    pub rss_growth_percent: f64,
    /// Growth from the end of the warm-up to the peak after it, %.
    pub rss_peak_growth_percent: f64,
    /// The median of the warm-up's windows' p99 (ms).
    pub p99_warm_up_ms: f64,
    /// The median of the later windows' p99 (ms).
    pub p99_after_ms: f64,
}

impl AfterWarmUp {
    /// Splits `windows` after the first that closes at or after `warm_up_s` wall seconds.
    pub fn of(windows: &[SoakWindow], warm_up_s: f64) -> Option<Self> {
        let cut = windows.iter().position(|w| w.wall_s >= warm_up_s)? + 1;
        let (warm_up, after) = windows.split_at(cut);
        let last = after.last()?;
        let median_p99 = |ws: &[SoakWindow]| {
            let mut p: Vec<f64> = ws.iter().map(|w| w.p99_ms).collect();
            p.sort_by(f64::total_cmp);
            p[(p.len() - 1) / 2]
        };
        let start = warm_up.last()?;
        let peak = after.iter().map(|w| w.rss_mib).fold(f64::MIN, f64::max);
        let growth = |to: f64| {
            if start.rss_mib > 0.0 {
                (to / start.rss_mib - 1.0) * 100.0
            } else {
                0.0
            }
        };
        Some(Self {
            from_wall_s: start.wall_s,
            rss_start_mib: start.rss_mib,
            rss_end_mib: last.rss_mib,
            rss_peak_mib: peak,
            rss_growth_percent: growth(last.rss_mib),
            rss_peak_growth_percent: growth(peak),
            p99_warm_up_ms: median_p99(warm_up),
            p99_after_ms: median_p99(after),
        })
    }
}

/// The process's memory, read from Linux `/proc`: resident and anonymous (MiB), and threads.
/// Zeros where there is no `/proc`.
pub fn memory() -> (f64, f64, u32) {
    let kib = |text: &str, key: &str| -> f64 {
        text.lines()
            .find_map(|l| l.strip_prefix(key)?.split_whitespace().next()?.parse().ok())
            .unwrap_or(0.0)
    };
    let rollup = std::fs::read_to_string("/proc/self/smaps_rollup").unwrap_or_default();
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let threads = kib(&status, "Threads:") as u32;
    let rss = match kib(&rollup, "Rss:") {
        0.0 => rss_mib(),
        kib => kib / 1024.0,
    };
    (rss, kib(&rollup, "Anonymous:") / 1024.0, threads)
}

/// Round trips of a window, counted in fixed buckets: the soak's own memory stays the same
/// however many round trips a window holds (a list of them grew with the load, and its growth
/// would be read as the fleet's).
#[derive(Debug, Clone)]
pub struct Histogram {
    /// Counts per [`Histogram::BUCKET_US`] bucket; the last also counts everything slower.
    counts: Vec<u32>,
    total: usize,
    max_us: u32,
}

impl Histogram {
    /// Bucket width (µs).
    pub const BUCKET_US: u32 = 10;
    /// Buckets: 10 µs each up to 1 s, the last open-ended.
    const BUCKETS: usize = 100_000;

    /// An empty histogram; its one allocation, made here.
    pub fn new() -> Self {
        Self {
            counts: vec![0; Self::BUCKETS],
            total: 0,
            max_us: 0,
        }
    }

    /// Counts a round trip of `us` microseconds.
    pub fn record(&mut self, us: u32) {
        let b = ((us / Self::BUCKET_US) as usize).min(Self::BUCKETS - 1);
        self.counts[b] = self.counts[b].saturating_add(1);
        self.total += 1;
        self.max_us = self.max_us.max(us);
    }

    /// Round trips counted.
    pub fn len(&self) -> usize {
        self.total
    }

    /// Whether none are counted.
    pub fn is_empty(&self) -> bool {
        self.total == 0
    }

    /// The nearest-rank quantile `q` ∈ (0, 1] (ms): the upper edge of its bucket (10 µs
    /// resolution), or the slowest round trip when it falls in the open-ended last bucket; 0
    /// when empty.
    pub fn quantile_ms(&self, q: f64) -> f64 {
        if self.total == 0 {
            return 0.0;
        }
        let rank = ((q * self.total as f64).ceil() as usize).clamp(1, self.total);
        let mut seen = 0usize;
        for (b, &c) in self.counts.iter().enumerate() {
            seen += c as usize;
            if seen >= rank {
                let edge = if b == Self::BUCKETS - 1 {
                    self.max_us
                } else {
                    (b as u32 + 1) * Self::BUCKET_US
                };
                return f64::from(edge.min(self.max_us)) / 1000.0;
            }
        }
        f64::from(self.max_us) / 1000.0
    }

    /// Empties it, keeping its memory.
    pub fn clear(&mut self) {
        self.counts.fill(0);
        self.total = 0;
        self.max_us = 0;
    }
}

impl Default for Histogram {
    fn default() -> Self {
        Self::new()
    }
}

/// Resident memory of this process (MiB), from `/proc/self/statm`; 0 where there is none.
pub fn rss_mib() -> f64 {
    let pages = std::fs::read_to_string("/proc/self/statm")
        .ok()
        .and_then(|s| s.split_whitespace().nth(1)?.parse::<f64>().ok())
        .unwrap_or(0.0);
    // 4 KiB pages on the machines this runs on (x86-64 and aarch64 Linux defaults).
    pages * 4096.0 / (1024.0 * 1024.0)
}

/// Runs `agents` agents planning with `planner` in `scenario` for `ticks` ticks at `speed`,
/// one window every `window` of wall time, each shown to `on_window` as it closes. When
/// `shutdown` completes first (SIGINT, say), the soak stops there and reports the ticks it ran
/// (the last tick's observations may then still be in flight, and count as lost).
#[allow(clippy::too_many_arguments)]
pub async fn bench_soak(
    scenario: world_sim::scenario::Scenario,
    planner: PlannerSpec,
    agents: usize,
    ticks: u64,
    speed: f64,
    window: Duration,
    warm_up: Duration,
    shutdown: impl Future<Output = ()>,
    mut on_window: impl FnMut(&SoakWindow),
) -> Result<Soak> {
    let (round_trips_tx, round_trips_rx) = std::sync::mpsc::channel::<RoundTrip>();
    let dt = scenario.dt_s;
    let options = DemoOptions {
        scenario,
        planner,
        seconds: ticks as f64 * dt,
        speed,
        keys: schemas::Keys::new("soak").expect("a valid site name"),
        listen: None,
        transport: Transport::Tcp,
        journal: None,
        share_intents: true,
        traffic_policy: Some(Default::default()),
        sinks: dashboards::Sinks::default(),
        round_trips: Some(round_trips_tx),
        ros: false,
    };
    let started = Instant::now();
    let windows = Arc::new(Mutex::new(Vec::<SoakWindow>::new()));
    let pending = Arc::new(Mutex::new(Histogram::new()));
    // Round trips are gathered as they come and cut into windows by the status callback.
    let gather = {
        let pending = pending.clone();
        std::thread::spawn(move || {
            while let Ok(trip) = round_trips_rx.recv() {
                let us = trip
                    .arrived
                    .saturating_duration_since(trip.published)
                    .as_micros()
                    .min(u128::from(u32::MAX)) as u32;
                if let Ok(mut p) = pending.lock() {
                    p.record(us);
                }
            }
        })
    };
    let pending_end = pending.clone();
    let mut next_cut = started + window;
    let windows_in = windows.clone();
    let last_memory = Arc::new(Mutex::new((0.0f64, 0.0f64, 0u32)));
    let last_memory_in = last_memory.clone();
    let last_state = Arc::new(Mutex::new(0.0f64));
    let last_state_in = last_state.clone();
    let on_status = move |s: &crate::serve::Status, fleet: &world_sim::fleet::Fleet| {
        if let Ok(mut r) = last_memory_in.lock() {
            *r = memory();
        }
        if Instant::now() < next_cut {
            return;
        }
        let state_kib = fleet.snapshot().len() as f64 / 1024.0;
        if let Ok(mut k) = last_state_in.lock() {
            *k = state_kib;
        }
        next_cut += window;
        let (round_trips, p50_ms, p99_ms) = pending
            .lock()
            .map(|mut p| {
                let cut = (p.len(), p.quantile_ms(0.5), p.quantile_ms(0.99));
                p.clear();
                cut
            })
            .unwrap_or_default();
        let (rss_mib, anon_mib, threads) = memory();
        let w = SoakWindow {
            wall_s: started.elapsed().as_secs_f64(),
            ticks: s.tick,
            rss_mib,
            anon_mib,
            threads,
            state_kib,
            round_trips,
            p50_ms,
            p99_ms,
        };
        on_window(&w);
        if let Ok(mut ws) = windows_in.lock() {
            ws.push(w);
        }
    };
    let report = run_demo(options, shutdown, on_status, |_| {}).await?;
    let _ = gather.join();
    let mut windows = windows.lock().map(|w| w.clone()).unwrap_or_default();
    // The last (partial) window, with the memory the run held at its last status (by now
    // the sessions are closed).
    let trips = pending_end.lock().map(|p| p.clone()).unwrap_or_default();
    if !trips.is_empty() {
        let (rss_mib, anon_mib, threads) = last_memory.lock().map_or((0.0, 0.0, 0), |r| *r);
        windows.push(SoakWindow {
            wall_s: started.elapsed().as_secs_f64(),
            ticks: report.status.tick,
            rss_mib,
            anon_mib,
            threads,
            state_kib: last_state.lock().map_or(0.0, |k| *k),
            round_trips: trips.len(),
            p50_ms: trips.quantile_ms(0.5),
            p99_ms: trips.quantile_ms(0.99),
        });
    }
    let growth = match (windows.first(), windows.last()) {
        (Some(a), Some(b)) if a.rss_mib > 0.0 => (b.rss_mib / a.rss_mib - 1.0) * 100.0,
        _ => 0.0,
    };
    let s = &report.status;
    let sum = |f: fn(&agent::runtime::AgentCounters) -> &std::sync::atomic::AtomicU64| -> u64 {
        report
            .agents
            .iter()
            .map(|c| f(c).load(std::sync::atomic::Ordering::Relaxed))
            .sum()
    };
    let received = sum(|c| &c.received);
    Ok(Soak {
        agents,
        ticks: s.tick,
        speed,
        wall_s: started.elapsed().as_secs_f64(),
        observations: s.observations,
        answered: s.answered,
        lost: s.observations.saturating_sub(received),
        missed: sum(|c| &c.missed),
        superseded: sum(|c| &c.superseded),
        stale_commands: s.stale_commands,
        rejected: s.rejected,
        after_warm_up: AfterWarmUp::of(&windows, warm_up.as_secs_f64()),
        windows,
        rss_growth_percent: growth,
        tasks: report.summary.tasks,
        contacts: report.summary.total_contacts,
        robot_caused_contacts: report.summary.robot_caused_contacts,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn window(rss_mib: f64, p99_ms: f64) -> SoakWindow {
        SoakWindow {
            wall_s: 0.0,
            ticks: 0,
            rss_mib,
            anon_mib: rss_mib / 2.0,
            threads: 8,
            state_kib: 1.0,
            round_trips: 1,
            p50_ms: 1.0,
            p99_ms,
        }
    }

    #[test]
    fn the_warm_up_ends_with_the_window_that_closes_it() {
        let at = |wall_s, rss_mib, p99_ms| SoakWindow {
            wall_s,
            ..window(rss_mib, p99_ms)
        };
        // No window closes after 600 s.
        assert!(AfterWarmUp::of(&[at(300.0, 100.0, 1.0), at(600.0, 101.0, 1.0)], 600.0).is_none());
        let ws = [
            at(300.0, 100.0, 9.0),
            at(610.0, 120.0, 3.0), // closes the warm-up
            at(910.0, 126.0, 4.0),
            at(1210.0, 119.0, 8.0),
            at(1510.0, 123.0, 5.0),
        ];
        let a = AfterWarmUp::of(&ws, 600.0).expect("windows after the warm-up");
        assert_eq!(a.from_wall_s, 610.0);
        assert!((a.rss_growth_percent - 2.5).abs() < 1e-12);
        assert!((a.rss_peak_growth_percent - 5.0).abs() < 1e-12);
        assert_eq!(a.rss_peak_mib, 126.0);
        assert_eq!(a.p99_warm_up_ms, 3.0); // lower median of {9, 3}
        assert_eq!(a.p99_after_ms, 5.0); // median of {4, 8, 5}
    }

    #[test]
    fn the_histogram_gives_nearest_rank_quantiles_to_its_bucket() {
        let mut h = Histogram::new();
        assert_eq!(h.quantile_ms(0.99), 0.0);
        for us in 1..=1000 {
            h.record(us * 10); // 10 µs … 10 ms
        }
        assert_eq!(h.len(), 1000);
        assert!(
            (h.quantile_ms(0.5) - 5.0).abs() < 0.011,
            "{}",
            h.quantile_ms(0.5)
        );
        assert!(
            (h.quantile_ms(0.99) - 9.9).abs() < 0.011,
            "{}",
            h.quantile_ms(0.99)
        );
        // Past a second: the slowest round trip itself.
        h.record(3_000_000);
        assert_eq!(h.quantile_ms(1.0), 3000.0);
        h.clear();
        assert!(h.is_empty());
        assert_eq!(h.counts.len(), Histogram::BUCKETS);
    }

    #[test]
    fn memory_is_read_from_proc() {
        let (rss, anon, threads) = memory();
        if std::path::Path::new("/proc/self/smaps_rollup").exists() {
            assert!(rss > 0.0 && anon > 0.0 && anon <= rss, "{rss} {anon}");
            assert!(threads >= 1);
        }
    }
}
