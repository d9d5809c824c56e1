//! Per-replan times of foIGP with mixtures (`foigp`) and with one GP per person (`foigp-1`) on
//! the foIGP benchmark's 24 recorded scenes (`benches/foigp.rs`: the robot in an ETH
//! pedestrian's place 3.2 s into a partial run, warmed on the 8 frames before), the two timed
//! in alternation, scene by scene, so that a drifting machine slows both alike. Prints each
//! scene's median of `repeats` timings, what the plan involved, and the medians over the
//! scenes (issue 25's target: foigp ≤ 5 ms median per replan).
//!
//!     cargo run --release -p world-sim --example foigp_replan_times [repeats]

use agent::igp::{IgpDecision, IgpVariant};
use std::time::Instant;

mod foigp_scenes;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn main() {
    let repeats: usize = std::env::args()
        .nth(1)
        .map(|a| a.parse().expect("repeats: a whole number"))
        .unwrap_or(15);
    let mixture = foigp_scenes::scenes(IgpVariant::Mixture, 24);
    let single = foigp_scenes::scenes(IgpVariant::Full, 24);
    let mut medians = [Vec::new(), Vec::new()];
    println!("scene | people | foigp ms (entered, combinations) | foigp-1 ms (entered)");
    for (scene, (m, o)) in mixture.iter().zip(&single).enumerate() {
        let warmed = [&m.planner, &o.planner];
        let (ego, seen, goal) = (&m.ego, &m.neighbours, m.goal);
        let mut times = [Vec::new(), Vec::new()];
        let mut last: [Option<IgpDecision>; 2] = [None, None];
        for _ in 0..repeats {
            for (i, planner) in warmed.iter().enumerate() {
                let mut p = (*planner).clone();
                let started = Instant::now();
                let d = p.plan(ego, seen, goal, 0.4);
                times[i].push(started.elapsed().as_secs_f64() * 1e3);
                last[i] = Some(d);
            }
        }
        let [mix, one] = [median(times[0].clone()), median(times[1].clone())];
        medians[0].push(mix);
        medians[1].push(one);
        let (m, o) = (
            last[0].as_ref().expect("timed"),
            last[1].as_ref().expect("timed"),
        );
        println!(
            "{scene:5} | {:6} | {mix:6.2} ({}, {}) | {one:6.2} ({})",
            seen.len(),
            m.selected.len(),
            m.combinations,
            o.selected.len()
        );
    }
    let (mix, one) = (median(medians[0].clone()), median(medians[1].clone()));
    println!(
        "median over the scenes: foigp {mix:.2} ms, foigp-1 {one:.2} ms, ratio {:.2}",
        mix / one
    );
}
