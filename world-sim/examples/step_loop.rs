//! A loop of world steps in the built-in `warehouse-large` (1,000 people, 50 parked robots),
//! for instruction counts and for timing two builds against each other on a noisy machine:
//!
//!     cargo build --release -p world-sim --example step_loop
//!     valgrind --tool=callgrind target/release/examples/step_loop 20
//!     target/release/examples/step_loop 500 --time
//!     target/release/examples/step_loop 500 --time --field    # humans.walls = "field"
//!
//! Prints a checksum of every person's position after the loop (the bits, hashed), so that
//! two builds can be checked to move the crowd identically.

use agent::model::Command;
use std::hash::{DefaultHasher, Hash, Hasher};
use std::time::Instant;
use world_sim::scenario::{Scenario, WallModel};
use world_sim::world::World;

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let steps: usize = match args.first() {
        Some(n) => n.parse().map_err(|e| format!("steps {n:?}: {e}"))?,
        None => 20,
    };
    if steps == 0 {
        return Err("steps must be at least 1".into());
    }
    let time = args.iter().any(|a| a == "--time");
    let mut scenario = Scenario::builtin("warehouse-large").map_err(|e| e.to_string())?;
    if args.iter().any(|a| a == "--field") {
        scenario.humans.walls = WallModel::Field;
    }
    let built = Instant::now();
    let mut world = World::from_scenario(&scenario);
    let built = built.elapsed();
    let park = vec![Command::STOP; world.robots.len()];
    // As the criterion bench: 20 steps first, so that people are under way.
    for _ in 0..20 {
        world.step(&park);
    }
    let mut micros = Vec::with_capacity(steps);
    for _ in 0..steps {
        let started = Instant::now();
        world.step(std::hint::black_box(&park));
        micros.push(started.elapsed().as_secs_f64() * 1e6);
    }
    let mut hasher = DefaultHasher::new();
    for p in &world.humans.crowd.positions {
        p.x.to_bits().hash(&mut hasher);
        p.y.to_bits().hash(&mut hasher);
    }
    let mut line = format!("warehouse-large: {steps} steps");
    if time {
        micros.sort_by(f64::total_cmp);
        line += &format!(
            ", median {:.0} µs, p10 {:.0} µs (world built in {:.2} s)",
            micros[steps / 2],
            micros[steps / 10],
            built.as_secs_f64()
        );
    }
    println!("{line}, positions checksum {:016x}", hasher.finish());
    Ok(())
}
