//! `gapfleet bench dashboard`: a coordinator tick with and without the Rerun dashboard
//! attached.

use super::BenchError;
use agent::runtime::percentile;
use std::time::Instant;

type Result<T> = std::result::Result<T, BenchError>;

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
    /// Median CPU time per tick of the simulating thread, without a dashboard (µs).
    pub without_cpu_us: f64,
    /// The same with the dashboard (µs): the part of the overhead that is work done on the
    /// tick's own thread; the rest is the dashboard's threads competing for the CPU.
    pub with_cpu_us: f64,
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
    use crate::serve::{Observer, Status, map_message, observation};
    use world_sim::fleet::Fleet;
    let time = |with: bool| -> Result<(f64, f64, u64)> {
        let mut fleet = Fleet::new(scenario)?;
        let map_version = map_message(&fleet, &scenario.robot.safety_layer).map_version;
        let park = vec![agent::model::Command::STOP; fleet.robots()];
        let mut observer = if with {
            let sinks = dashboards::Sinks {
                rrd: Some(rrd.to_path_buf()),
                ..Default::default()
            };
            Some(crate::serve::dashboard::DashboardObserver::start(
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
        let mut cpu_times = Vec::with_capacity(ticks);
        for tick in 0..ticks + 20 {
            let started = Instant::now();
            let cpu_started = super::machine::thread_cpu_ns();
            let mut events = fleet.step(&park);
            events.extend(fleet.dispatch());
            for i in 0..fleet.robots() {
                std::hint::black_box(schemas::encode(&observation(
                    &mut fleet,
                    i,
                    tick as u64,
                    map_version,
                )));
            }
            status.tick = tick as u64;
            status.sim_time = fleet.world.time;
            observer.tick(&fleet, &status, &events);
            if tick >= 20 {
                times.push(started.elapsed().as_micros().min(u32::MAX as u128) as u32);
                let cpu_us = super::machine::thread_cpu_ns().saturating_sub(cpu_started) / 1000;
                cpu_times.push(cpu_us.min(u64::from(u32::MAX)) as u32);
            }
        }
        let dropped = observer.map_or(0, |o| o.finish().dropped);
        Ok((
            percentile(&mut times, 0.5),
            percentile(&mut cpu_times, 0.5),
            dropped,
        ))
    };
    let (without_us, without_cpu_us, _) = time(false)?;
    let (with_us, with_cpu_us, dropped) = time(true)?;
    Ok(DashboardBench {
        robots: scenario.fleet_size().map_or(0, |f| f.0),
        humans: scenario.fleet_size().map_or(0, |f| f.1),
        ticks,
        without_us,
        with_us,
        overhead: (with_us - without_us) / without_us,
        without_cpu_us,
        with_cpu_us,
        dropped,
    })
}
