//! `gapfleet bench world`: world steps per second with people walking and robots parked
//! (planners not included). The criterion benchmark `world-sim/benches/world_step.rs` times
//! the same step for regressions; this one sizes a deployment on the machine at hand.

use agent::model::Command;
use std::time::Instant;
use world_sim::scenario::Scenario;
use world_sim::world::World;

/// Steps before the timed ones, so that the crowd is moving and caches are warm.
const WARM_UP_STEPS: usize = 20;

/// What `bench world` measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct WorldBench {
    /// Scenario name as asked (`open-space`, a built-in or a file).
    pub scenario: String,
    /// People.
    pub humans: usize,
    /// People per m² (of the free floor, for a warehouse).
    pub density: f64,
    /// How walls push people (`points` or `field`).
    pub walls: &'static str,
    /// Steps timed.
    pub steps: usize,
    /// Median step (µs).
    pub median_us_per_step: f64,
    /// Mean step (µs).
    pub mean_us_per_step: f64,
    /// Steps per wall second.
    pub steps_per_s: f64,
    /// Building the world (s): its map, walls and crowd.
    pub set_up_s: f64,
}

/// Times `steps` world steps of `scenario` (an open space sized for its density, or a
/// warehouse) after `WARM_UP_STEPS`.
pub fn bench_world(name: &str, scenario: &Scenario, steps: usize) -> WorldBench {
    let set_up = Instant::now();
    let mut world = if scenario.open_space.is_some() {
        World::open_space(scenario)
    } else {
        World::from_scenario(scenario)
    };
    let set_up_s = set_up.elapsed().as_secs_f64();
    let park = vec![Command::STOP; world.robots.len()];
    for _ in 0..WARM_UP_STEPS {
        world.step(&park);
    }
    let mut times = Vec::with_capacity(steps);
    let started = Instant::now();
    for _ in 0..steps {
        let t = Instant::now();
        world.step(&park);
        times.push(t.elapsed().as_secs_f64() * 1e6);
    }
    let total = started.elapsed().as_secs_f64();
    times.sort_by(f64::total_cmp);
    let people = world.humans.crowd.len();
    // People per m² of floor: the open stage's as asked; a warehouse's over its free area.
    let density = world.site().map_or_else(
        || scenario.open_space.as_ref().map_or(f64::NAN, |o| o.density),
        |site| people as f64 / site.free_area(),
    );
    WorldBench {
        scenario: name.to_owned(),
        humans: people,
        density,
        walls: scenario.humans.walls.name(),
        steps,
        median_us_per_step: times.get(times.len() / 2).copied().unwrap_or(f64::NAN),
        mean_us_per_step: times.iter().sum::<f64>() / times.len().max(1) as f64,
        steps_per_s: steps as f64 / total,
        set_up_s,
    }
}
