use agent::igp::{IgpParams, IgpPlanner, IgpVariant};
use agent::model::{EgoState, Neighbour};
use std::path::Path;
use std::time::Instant;
use world_sim::dataset::Recording;
use world_sim::replay::{ReplayOptions, RunKind, median_speed, perceived, runs};

fn main() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("datasets/ETH/seq_eth");
    let rec = Recording::load(&dir).expect("seq_eth loads");
    let speed = median_speed(&rec);
    let params = IgpParams { preferred_speed: speed, max_speed: speed, ..IgpParams::default() };
    let options = ReplayOptions::default();
    let all = runs(&rec, RunKind::Partial, &options);
    let step = (all.len() / 24).max(1);
    for run in all.iter().step_by(step).take(24) {
        let track = rec.track(run.pedestrian).unwrap();
        let at = |t: f64| {
            let (position, velocity) = track.state_at(t).unwrap();
            let seen: Vec<Neighbour> = perceived(&rec, t, run.pedestrian, position, &options).collect();
            (EgoState { position, heading: velocity.y.atan2(velocity.x), velocity, yaw_rate: 0.0, radius: 0.3 }, seen)
        };
        let now = (run.t_start + 3.2).min(run.t_end);
        let mut line = String::new();
        for variant in [IgpVariant::Mixture, IgpVariant::Full] {
            let mut planner = IgpPlanner::new(variant, params);
            planner.set_destinations(&rec.destinations);
            for k in (1..=8).rev() {
                let t = now - k as f64 * 0.4;
                if t >= track.start() { let (e, s) = at(t); planner.plan(&e, &s, run.goal, 0.4); }
            }
            let (ego, seen) = at(now);
            let mut best = f64::INFINITY;
            let mut d = None;
            for _ in 0..5 { let mut p = planner.clone(); let t0 = Instant::now(); d = Some(p.plan(&ego, &seen, run.goal, 0.4)); best = best.min(t0.elapsed().as_secs_f64()*1e3); }
            let d = d.unwrap();
            line += &format!(" {:?}: {:.2} ms n={} sel={} ess={:.1} comb={} |", variant, best, seen.len(), d.selected.len(), d.ess, d.combinations);
        }
        println!("{line}");
    }
}
