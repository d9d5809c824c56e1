//! People in the hallway study's hallway with the robot parked far outside it: their mean
//! speed, how many reached an end and turned back, and the nearest any came to x = 0 or to
//! the far end (development probe for the closed ends).
use agent::math::vec2;
use agent::model::Command;
use world_sim::scenario::Scenario;
use world_sim::world::World;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let length: f64 = args.first().and_then(|a| a.parse().ok()).unwrap_or(50.0);
    let speed: f64 = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(1.0);
    let mut total = (0.0, 0u64, 0u64, f64::INFINITY, f64::NEG_INFINITY);
    for seed in 1..=10 {
        let mut s = Scenario::builtin("hallway").expect("valid");
        let h = s.hallway.as_mut().unwrap();
        h.length_m = length;
        h.width_m = 4.0;
        h.humans = (length * 0.48).round() as usize;
        s.humans.speed = speed;
        s.seed = seed;
        let mut w = World::from_scenario(&s);
        w.robots[0].state.position = vec2(-500.0, -500.0);
        let n = w.humans.crowd.len();
        let mut heading: Vec<f64> = (0..n).map(|i| w.humans.crowd.goals[i].x).collect();
        for _ in 0..1200 {
            w.step(&[Command::STOP]);
            for i in 0..n {
                let p = w.humans.crowd.positions[i];
                total.0 += w.humans.crowd.velocities[i].norm();
                total.1 += 1;
                total.3 = total.3.min(p.x);
                total.4 = total.4.max(p.x);
                if w.humans.crowd.goals[i].x != heading[i] {
                    heading[i] = w.humans.crowd.goals[i].x;
                    total.2 += 1;
                }
            }
        }
    }
    println!(
        "mean speed {:.4} m/s, goal changes {}, x in [{:.3}, {:.3}]",
        total.0 / total.1 as f64,
        total.2,
        total.3,
        total.4
    );
}
