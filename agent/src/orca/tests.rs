use super::*;
use crate::map::Obstacle;
use crate::math::vec2;
use proptest::prelude::*;

fn body(p: (f64, f64), v: (f64, f64), r: f64) -> Body<f64> {
    Body {
        position: V::new(p.0, p.1),
        velocity: V::new(v.0, v.1),
        radius: r,
        responsibility: 0.5,
    }
}

/// Smallest distance between two bodies moving at constant velocities over [0, horizon].
fn min_distance(a: &Body<f64>, va: V<f64>, b: &Body<f64>, vb: V<f64>, horizon: f64) -> f64 {
    let dp = b.position.to_vec2() - a.position.to_vec2();
    let dv = vb.to_vec2() - va.to_vec2();
    let t = if dv.norm_squared() > 0.0 {
        (-dp.dot(&dv) / dv.norm_squared()).clamp(0.0, horizon)
    } else {
        0.0
    };
    (dp + dv * t).norm()
}

#[test]
fn free_space_returns_the_preferred_velocity() {
    let mut orca = Orca::<f64>::new(OrcaParams::default());
    let v = orca.new_velocity(
        &body((0.0, 0.0), (0.0, 0.0), 0.3),
        V::new(0.6, 0.0),
        &[],
        &StaticMap::empty(),
    );
    assert_eq!(v, V::new(0.6, 0.0));
    // Longer than v_max: scaled onto the speed circle.
    let v = orca.new_velocity(
        &body((0.0, 0.0), (0.0, 0.0), 0.3),
        V::new(3.0, 4.0),
        &[],
        &StaticMap::empty(),
    );
    assert!((v.to_vec2() - vec2(0.6, 0.8)).norm() < 1e-12);
}

#[test]
fn only_the_nearest_five_within_four_metres_count() {
    let mut orca = Orca::<f64>::new(OrcaParams::default());
    let others: Vec<_> = (1..=8)
        .map(|i| body((i as f64 * 0.7, 0.0), (0.0, 0.0), 0.3))
        .collect();
    orca.new_velocity(
        &body((0.0, 0.0), (0.0, 0.0), 0.3),
        V::new(1.0, 0.0),
        &others,
        &StaticMap::empty(),
    );
    // 8 agents at 0.7 … 5.6 m: 5 are within 4 m and the cap is 5, so 5 lines.
    assert_eq!(orca.lines().len(), 5);
}

#[test]
fn a_wall_ahead_stops_motion_into_it() {
    let map =
        StaticMap::new(vec![Obstacle::Wall(vec2(1.0, -3.0), vec2(1.0, 3.0))]).expect("valid wall");
    let mut orca = Orca::<f64>::new(OrcaParams::default());
    let v = orca.new_velocity(
        &body((0.5, 0.0), (1.0, 0.0), 0.3),
        V::new(1.0, 0.0),
        &[],
        &map,
    );
    // 0.2 m of room: moving towards the wall faster than 0.2 m / 2.5 s is excluded.
    assert!(
        v.x <= 0.2 / 2.5 + 1e-9,
        "velocity {v:?} drives into the wall"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn speed_never_exceeds_v_max(
        agents in proptest::collection::vec(((-5.0..5.0f64, -5.0..5.0f64), (-1.0..1.0f64, -1.0..1.0f64)), 1..10),
        pref in (-3.0..3.0f64, -3.0..3.0f64),
    ) {
        let mut orca = Orca::<f64>::new(OrcaParams::default());
        let ego = body((0.0, 0.0), (0.3, 0.0), 0.3);
        let others: Vec<_> = agents.iter().map(|&(p, v)| body(p, v, 0.35)).collect();
        let v = orca.new_velocity(&ego, V::new(pref.0, pref.1), &others, &StaticMap::empty());
        prop_assert!(v.to_vec2().norm() <= 1.0 + 1e-9, "speed {}", v.to_vec2().norm());
    }

    #[test]
    fn pairs_are_collision_free_within_the_horizon(
        agents in proptest::collection::vec(((-4.0..4.0f64, -4.0..4.0f64), (-1.0..1.0f64, -1.0..1.0f64), (-1.0..1.0f64, -1.0..1.0f64)), 2..7),
    ) {
        let r = 0.3;
        let bodies: Vec<_> = agents.iter().map(|&(p, v, _)| body(p, v, r)).collect();
        // Start without overlap.
        for i in 0..bodies.len() {
            for j in i + 1..bodies.len() {
                prop_assume!((bodies[i].position.to_vec2() - bodies[j].position.to_vec2()).norm() > 2.0 * r + 1e-3);
            }
        }
        let params = OrcaParams { neighbor_dist: 100.0, max_neighbors: 10, ..OrcaParams::default() };
        let mut orca = Orca::<f64>::new(params);
        let mut new = Vec::new();
        for (i, b) in bodies.iter().enumerate() {
            let others: Vec<_> = bodies.iter().enumerate().filter(|(j, _)| *j != i).map(|(_, o)| *o).collect();
            let pref = agents[i].2;
            new.push(orca.new_velocity(b, V::new(pref.0, pref.1), &others, &StaticMap::empty()));
            // ORCA guarantees collision freedom only when every program is feasible.
            prop_assume!(orca.last_was_feasible());
        }
        for i in 0..bodies.len() {
            for j in i + 1..bodies.len() {
                let d = min_distance(&bodies[i], new[i], &bodies[j], new[j], params.time_horizon);
                prop_assert!(d >= 2.0 * r - 1e-6, "agents {i} and {j} come within {d} m");
            }
        }
    }
}
