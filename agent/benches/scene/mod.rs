//! The benchmark scene, shared by `benches/planners.rs` and `examples/plan_loop.rs`: a robot
//! at the origin heading +x at 0.8 m/s among people at 0.5 persons/m² (seeded).

use agent::math::{Real, unit, vec2};
use agent::model::{AgentKind, EgoState, Neighbour};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const DENSITY: Real = 0.5;

pub fn ego() -> EgoState {
    EgoState {
        position: vec2(0.0, 0.0),
        heading: 0.0,
        velocity: vec2(0.8, 0.0),
        yaw_rate: 0.0,
        radius: 0.3,
    }
}

/// `n` people in a square centred on the robot at `DENSITY`, none within 0.8 m of it.
pub fn crowd(n: usize, seed: u64) -> Vec<Neighbour> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let half = (n as Real / DENSITY).sqrt() / 2.0;
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let p = vec2(rng.random_range(-half..half), rng.random_range(-half..half));
        if p.norm() < 0.8 {
            continue;
        }
        let v = unit(rng.random_range(0.0..std::f64::consts::TAU)) * rng.random_range(0.5..1.3);
        out.push(Neighbour::new(
            out.len() as u64,
            p,
            v,
            0.35,
            AgentKind::Human,
        ));
    }
    out
}
