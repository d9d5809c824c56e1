//! What the machine did while a benchmark ran, so that its figures can be read: how much CPU
//! time this process used, how much the hypervisor reported stealing, and how fast the CPU
//! itself ran.
//!
//! The last one matters on shared VMs. There the host can slow a virtual CPU down for tens of
//! milliseconds at a time without the guest's steal counter showing it: a fixed job then takes
//! several times longer *in its own thread CPU time*. A latency tail measured during such
//! moments measures the host. [`CpuSpeedProbe`] counts them.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// CPU time counters in clock ticks: the whole machine's (every core, from `/proc/stat`), the
/// part of it the hypervisor reported stealing, and this process's.
#[derive(Debug, Clone, Copy)]
pub struct CpuTimes {
    machine: u64,
    steal: u64,
    process: u64,
}

impl CpuTimes {
    /// Now, on Linux; None where `/proc` is missing or unreadable.
    pub fn now() -> Option<Self> {
        let stat = std::fs::read_to_string("/proc/stat").ok()?;
        // `cpu  user nice system idle iowait irq softirq steal guest guest_nice`; guest time is
        // already counted in user and nice.
        let machine: Vec<u64> = stat
            .lines()
            .next()?
            .strip_prefix("cpu ")?
            .split_whitespace()
            .take(8)
            .map(|f| f.parse().ok())
            .collect::<Option<_>>()?;
        let own = std::fs::read_to_string("/proc/self/stat").ok()?;
        // Fields after the command name (which may hold spaces, hence the last ')') start at
        // field 3 of proc(5); utime and stime are fields 14 and 15.
        let after_name = own.get(own.rfind(')')? + 2..)?;
        let process = after_name
            .split_whitespace()
            .skip(11)
            .take(2)
            .map(|f| f.parse::<u64>().ok())
            .sum::<Option<u64>>()?;
        Some(Self {
            machine: machine.iter().sum(),
            steal: *machine.get(7)?,
            process,
        })
    }

    /// This process's and the hypervisor's steal shares of the machine's CPU time from `self`
    /// to `later`, in %.
    pub fn shares(self, later: Self) -> Option<(f64, f64)> {
        let machine = later.machine.checked_sub(self.machine).filter(|&t| t > 0)? as f64;
        let share = |a: u64, b: u64| 100.0 * b.saturating_sub(a) as f64 / machine;
        Some((
            share(self.process, later.process),
            share(self.steal, later.steal),
        ))
    }
}

/// Iterations of the probe's job: about 45 µs on the 2-core VM this was written on.
const JOB_ITERATIONS: u64 = 20_000;
/// Time between two jobs: the probe costs about 1 % of one core.
const PROBE_PERIOD: Duration = Duration::from_millis(5);
/// A job slower than this multiple of the nominal time counts as slow.
const SLOW_FACTOR: f64 = 2.0;

/// Times a fixed job of integer arithmetic every 5 ms on a thread of its own, in that
/// thread's CPU time. Time spent waiting for a core is not in that clock, so the benchmark's
/// own load hardly moves it; a job that takes several times its nominal time ran on a CPU
/// that was slowed down under it.
#[derive(Debug)]
pub struct CpuSpeedProbe {
    stop: Arc<AtomicBool>,
    /// Taken by [`CpuSpeedProbe::finish`].
    thread: Option<std::thread::JoinHandle<Vec<Job>>>,
}

/// One timed job: when it started and ended (wall clock) and the CPU time it took.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Job {
    /// Started.
    pub start: Instant,
    /// Ended.
    pub end: Instant,
    /// Its thread's CPU time, ns.
    pub cpu_ns: u64,
}

/// Every job a [`CpuSpeedProbe`] timed, in order.
#[derive(Debug, Clone, Default)]
pub struct CpuSpeedRecord {
    /// The jobs.
    pub jobs: Vec<Job>,
}

/// What a [`CpuSpeedProbe`] measured.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct CpuSpeed {
    /// Jobs timed.
    pub samples: usize,
    /// The job's nominal time (the 5th percentile of its CPU times), µs.
    pub nominal_us: f64,
    /// Share of jobs that took more than twice the nominal time, %.
    pub slow_percent: f64,
    /// The slowest job as a multiple of the nominal time.
    pub worst_slowdown: f64,
}

impl CpuSpeedProbe {
    /// Starts timing jobs, until [`CpuSpeedProbe::finish`].
    pub fn start() -> std::io::Result<Self> {
        let stop = Arc::new(AtomicBool::new(false));
        let stopped = stop.clone();
        let thread = std::thread::Builder::new()
            .name("cpu-speed-probe".into())
            .spawn(move || {
                let mut jobs = Vec::new();
                let mut seed = 1_u64;
                loop {
                    std::thread::sleep(PROBE_PERIOD);
                    if stopped.load(Ordering::Acquire) {
                        break;
                    }
                    let start = Instant::now();
                    let cpu = thread_cpu_ns();
                    seed = std::hint::black_box(job(std::hint::black_box(seed)));
                    let cpu_ns = thread_cpu_ns().saturating_sub(cpu);
                    jobs.push(Job {
                        start,
                        end: Instant::now(),
                        cpu_ns,
                    });
                }
                jobs
            })?;
        Ok(Self {
            stop,
            thread: Some(thread),
        })
    }

    /// Stops (within one period) and hands over every job timed.
    pub fn finish(mut self) -> CpuSpeedRecord {
        self.stop.store(true, Ordering::Release);
        CpuSpeedRecord {
            jobs: self
                .thread
                .take()
                .and_then(|t| t.join().ok())
                .unwrap_or_default(),
        }
    }
}

impl Drop for CpuSpeedProbe {
    /// A probe dropped without [`CpuSpeedProbe::finish`] (an early error) stops too.
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
    }
}

impl CpuSpeedRecord {
    /// The jobs' nominal CPU time (their 5th percentile), ns; None when empty.
    fn nominal_ns(&self) -> Option<u64> {
        let mut sorted: Vec<u64> = self.jobs.iter().map(|j| j.cpu_ns).collect();
        sorted.sort_unstable();
        sorted.get(sorted.len() / 20).map(|&t| t.max(1))
    }

    fn is_slow(job: &Job, nominal_ns: u64) -> bool {
        job.cpu_ns as f64 > SLOW_FACTOR * nominal_ns as f64
    }

    /// From the first job's start to the last one's end; None when empty.
    pub fn window(&self) -> Option<std::ops::Range<Instant>> {
        Some(self.jobs.first()?.start..self.jobs.last()?.end)
    }

    /// Summary; None if no job was timed.
    pub fn summary(&self) -> Option<CpuSpeed> {
        let nominal = self.nominal_ns()?;
        let slow = self
            .jobs
            .iter()
            .filter(|j| Self::is_slow(j, nominal))
            .count();
        let worst = self.jobs.iter().map(|j| j.cpu_ns).max()?;
        Some(CpuSpeed {
            samples: self.jobs.len(),
            nominal_us: nominal as f64 / 1000.0,
            slow_percent: 100.0 * slow as f64 / self.jobs.len() as f64,
            worst_slowdown: worst as f64 / nominal as f64,
        })
    }

    /// The stretches of time in which the CPU may have run slow, in order and disjoint: each
    /// run of slow jobs, widened to the end of the fast job before it and the start of the
    /// fast job after it (the probe cannot tell when between them the slowdown began or
    /// ended).
    pub fn slow_spans(&self) -> Vec<std::ops::Range<Instant>> {
        let Some(nominal) = self.nominal_ns() else {
            return Vec::new();
        };
        let jobs = &self.jobs;
        let mut spans: Vec<std::ops::Range<Instant>> = Vec::new();
        let mut i = 0;
        while i < jobs.len() {
            if !Self::is_slow(&jobs[i], nominal) {
                i += 1;
                continue;
            }
            let first = i;
            while i < jobs.len() && Self::is_slow(&jobs[i], nominal) {
                i += 1;
            }
            let start = first
                .checked_sub(1)
                .map_or(jobs[first].start, |before| jobs[before].end);
            let end = jobs.get(i).map_or(jobs[i - 1].end, |after| after.start);
            spans.push(start..end);
        }
        spans
    }
}

/// Whether `from..to` overlaps one of `spans` (sorted and disjoint, as
/// [`CpuSpeedRecord::slow_spans`] gives them).
pub fn overlaps(spans: &[std::ops::Range<Instant>], from: Instant, to: Instant) -> bool {
    // The last span starting before `to` is the only candidate.
    let candidates = spans.partition_point(|s| s.start < to);
    candidates > 0 && spans[candidates - 1].end > from
}

/// The probe's job: a linear congruential generator with an xor-shift, in registers only, so
/// that neither caches nor memory make its time vary.
fn job(seed: u64) -> u64 {
    let mut x = seed | 1;
    for _ in 0..JOB_ITERATIONS {
        x = x
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        x ^= x >> 29;
    }
    x
}

/// CPU time of the calling thread (ns).
pub(crate) fn thread_cpu_ns() -> u64 {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::ThreadCPUTime);
    (t.tv_sec.max(0) as u64) * 1_000_000_000 + t.tv_nsec.max(0) as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Jobs 5 ms apart taking `cpu_us` of CPU each.
    fn record(cpu_us: &[u64]) -> (Instant, CpuSpeedRecord) {
        let t0 = Instant::now();
        let jobs = cpu_us
            .iter()
            .enumerate()
            .map(|(i, &us)| {
                let start = t0 + Duration::from_millis(5 * i as u64);
                Job {
                    start,
                    end: start + Duration::from_micros(us),
                    cpu_ns: us * 1000,
                }
            })
            .collect();
        (t0, CpuSpeedRecord { jobs })
    }

    #[test]
    fn summary_counts_jobs_over_twice_the_nominal_time() {
        // 95 jobs at 50 µs, 3 at 120 µs (2.4x: slow), 2 at 90 µs (1.8x: not slow).
        let mut times = vec![50_u64; 95];
        times.extend([120; 3]);
        times.extend([90; 2]);
        let (_, r) = record(&times);
        let s = r.summary().expect("jobs were timed");
        assert_eq!(s.samples, 100);
        assert_eq!(s.nominal_us, 50.0);
        assert!((s.slow_percent - 3.0).abs() < 1e-12, "{s:?}");
        assert!((s.worst_slowdown - 2.4).abs() < 1e-12, "{s:?}");
        assert_eq!(CpuSpeedRecord::default().summary(), None);
    }

    #[test]
    fn slow_spans_reach_from_the_fast_job_before_to_the_fast_job_after() {
        // Jobs at 0, 5, …, 45 ms; 10 and 15 ms are slow, and so is the last one.
        let mut cpu = vec![50_u64; 10];
        cpu[2] = 400;
        cpu[3] = 300;
        cpu[9] = 200;
        let (t0, r) = record(&cpu);
        let ms = |m: u64| t0 + Duration::from_micros(m);
        let spans = r.slow_spans();
        // From the end of the job at 5 ms to the start of the job at 20 ms; from the end of
        // the job at 40 ms to the end of the last one.
        assert_eq!(spans, vec![ms(5_050)..ms(20_000), ms(40_050)..ms(45_200)]);
        assert!(overlaps(&spans, ms(19_000), ms(25_000)));
        assert!(overlaps(&spans, ms(0), ms(6_000)));
        assert!(!overlaps(&spans, ms(20_000), ms(40_000)));
        assert!(!overlaps(&spans, ms(0), ms(5_050)));
        assert!(overlaps(&spans, ms(45_000), ms(50_000)));
        assert!(!overlaps(&spans, ms(45_200), ms(50_000)));
        assert!(CpuSpeedRecord::default().slow_spans().is_empty());
    }

    #[test]
    fn probe_times_a_job_every_period_until_finished() {
        let probe = CpuSpeedProbe::start().expect("thread");
        std::thread::sleep(Duration::from_millis(200));
        let record = probe.finish();
        let s = record.summary().expect("some jobs in 200 ms");
        // At most one job per 5 ms period (plus the one in progress), in order.
        assert!(s.samples >= 1 && s.samples <= 41, "{s:?}");
        assert!(record.jobs.windows(2).all(|w| w[0].end <= w[1].start));
        assert!(s.nominal_us > 0.0 && s.worst_slowdown >= 1.0, "{s:?}");
    }

    #[test]
    fn machine_counters_move_forward() {
        let Some(first) = CpuTimes::now() else {
            return; // not Linux
        };
        // Burn some CPU so that this process's share is above zero.
        let mut x = 0_u64;
        for _ in 0..2000 {
            x = x.wrapping_add(std::hint::black_box(job(x)));
        }
        std::hint::black_box(x);
        std::thread::sleep(Duration::from_millis(300));
        let later = CpuTimes::now().expect("read once, readable again");
        let (process, steal) = first.shares(later).expect("ticks passed");
        // The process can use at most every core, i.e. 100 %; the two counters are whole clock
        // ticks from different sources, so over this short window either may be a tick or
        // two off (a few % of ~80 ticks).
        assert!(process > 0.0 && process <= 105.0, "{process}");
        assert!((0.0..=100.0).contains(&steal), "{steal}");
    }
}
