//! How people walk the hallway study's hallway with nobody else about (the robot parked far
//! outside it): their mean speed, how often a group turns back at an end (a new goal), and
//! the least and greatest x anyone reached. It measured that closing the hallway's ends left
//! people walking as before (results/hallway-layer-heldout/REPORT.md).
//!
//!     cargo run --release -p world-sim --example hallway_ends -- [LENGTH [SPEED]]
//!
//! The hallway study's hallway (4 m wide, 0.48 people per metre), seeds 1–10, 120 s each.
//! Defaults: 50 m, people at 1 m/s.

use agent::math::{Real, vec2};
use agent::model::Command;
use world_sim::scenario::Scenario;
use world_sim::world::World;

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let length: Real = args
        .first()
        .map_or(Ok(50.0), |a| a.parse())
        .map_err(|e| format!("length: {e}"))?;
    let speed: Real = args
        .get(1)
        .map_or(Ok(1.0), |a| a.parse())
        .map_err(|e| format!("speed: {e}"))?;
    let (mut speed_sum, mut samples, mut turns) = (0.0, 0u64, 0u64);
    let (mut lowest, mut highest) = (Real::INFINITY, Real::NEG_INFINITY);
    for seed in 1..=10 {
        let mut s = Scenario::builtin("hallway").map_err(|e| e.to_string())?;
        let hall = s
            .hallway
            .as_mut()
            .ok_or("the built-in hallway has a [hallway] table")?;
        hall.length_m = length;
        hall.width_m = 4.0;
        hall.humans = (length * 0.48).round() as usize;
        s.humans.speed = speed;
        s.seed = seed;
        let mut w = World::from_scenario(&s);
        w.robots[0].state.position = vec2(-500.0, -500.0);
        let mut heading: Vec<Real> = w.humans.crowd.goals.iter().map(|g| g.x).collect();
        for _ in 0..1200 {
            w.step(&[Command::STOP]);
            let crowd = &w.humans.crowd;
            for (i, goal_x) in heading.iter_mut().enumerate() {
                let p = crowd.positions[i];
                speed_sum += crowd.velocities[i].norm();
                samples += 1;
                lowest = lowest.min(p.x);
                highest = highest.max(p.x);
                if crowd.goals[i].x != *goal_x {
                    *goal_x = crowd.goals[i].x;
                    turns += 1;
                }
            }
        }
    }
    println!(
        "mean speed {:.4} m/s, new goals {turns}, x in [{lowest:.3}, {highest:.3}]",
        speed_sum / samples.max(1) as Real
    );
    Ok(())
}
