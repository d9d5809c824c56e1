//! A loop of planning steps in the benchmark scene (50 people), for instruction counts and
//! for timing two builds against each other on a noisy machine, where criterion's long runs
//! see different machine states:
//!
//!     cargo build --release -p agent --example plan_loop
//!     valgrind --tool=callgrind target/release/examples/plan_loop pgp+dwa 200
//!     target/release/examples/plan_loop pgp+dwa 5000 --time
//!
//! Prints the last command, so that two builds can be checked to decide the same.

#[path = "../benches/scene/mod.rs"]
mod scene;

use agent::map::StaticMap;
use agent::math::vec2;
use agent::planner::{PlannerSpec, PlannerStack, PlanningInput};
use std::hint::black_box;
use std::time::Instant;

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let spec: PlannerSpec = args
        .first()
        .map_or("pgp+dwa", String::as_str)
        .parse()
        .map_err(|e| format!("planner: {e}"))?;
    let plans: usize = match args.get(1) {
        Some(n) => n.parse().map_err(|e| format!("plans {n:?}: {e}"))?,
        None => 200,
    };
    if plans == 0 {
        return Err("plans must be at least 1".into());
    }
    let time = args.iter().any(|a| a == "--time");

    let map = StaticMap::empty();
    let ego = scene::ego();
    let people = scene::crowd(50, 7);
    let mut stack = PlannerStack::new(spec);
    let input = PlanningInput {
        ego: &ego,
        neighbours: &people,
        map: &map,
        goal: vec2(20.0, 0.0),
        dt: 0.1,
        visibility: None,
        safety: None,
    };
    let mut micros = Vec::with_capacity(plans);
    let mut last = None;
    for _ in 0..plans {
        let started = Instant::now();
        last = Some(black_box(stack.plan(black_box(&input))));
        micros.push(started.elapsed().as_secs_f64() * 1e6);
    }
    if time {
        micros.sort_by(f64::total_cmp);
        println!(
            "{spec}: {plans} plans, median {:.1} µs, p10 {:.1} µs",
            micros[plans / 2],
            micros[plans / 10]
        );
    }
    println!("last command: {:?}", last.map(|o| o.command));
    Ok(())
}
