//! Social Force against PySocialForce 1.1.2: replays the scenes of
//! `tests/reference/pysocialforce_fixtures.py` with our [`Crowd`] and compares every step.
//!
//! Both sides compute in f64 with the same formulas; they differ only in summation order
//! (numpy reduces arrays pairwise), so trajectories must agree to 1e-12 m over 15 s (measured:
//! ≤ 2e-15 m).

use agent::math::{Vec2, vec2};
use agent::obstacle_points::ObstaclePoints;
use agent::social_force::SfParams;
use serde::Deserialize;
use world_sim::crowd::{Crowd, Walls};

/// Largest allowed position difference (m) at any step.
const TOLERANCE_M: f64 = 1e-12;

#[derive(Deserialize)]
struct Fixture {
    step_width: f64,
    lambda_importance: f64,
    n: f64,
    initial: Vec<[f64; 6]>,
    groups: Vec<Vec<usize>>,
    obstacles: Vec<[f64; 4]>,
    positions: Vec<Vec<[f64; 2]>>,
}

fn replay(scene: &str, params: &str) -> f64 {
    let path = format!(
        "{}/tests/fixtures/pysf_{scene}_{params}.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let f: Fixture = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{path}: {e}"));

    let mut p = SfParams {
        step_width: f.step_width,
        ..SfParams::default()
    };
    p.social.lambda_importance = f.lambda_importance;
    p.social.n = f.n;
    // PySocialForce's obstacle tuples are (x1, x2, y1, y2).
    let obstacles = Walls::from(ObstaclePoints::from_segments(
        f.obstacles
            .iter()
            .map(|o| (vec2(o[0], o[2]), vec2(o[1], o[3]))),
        p.resolution,
    ));
    let column = |a: usize, b: usize| {
        f.initial
            .iter()
            .map(|r| vec2(r[a], r[b]))
            .collect::<Vec<Vec2>>()
    };
    let mut crowd = Crowd::new(
        column(0, 1),
        column(2, 3),
        column(4, 5),
        f.groups.clone(),
        &p,
    );
    let mut scratch = Vec::new();
    let mut worst: f64 = 0.0;
    for (step, expected) in f.positions.iter().enumerate() {
        if step > 0 {
            crowd.step(&obstacles, &p, &mut scratch);
        }
        for (ours, theirs) in crowd.positions.iter().zip(expected) {
            worst = worst.max((ours - vec2(theirs[0], theirs[1])).norm());
        }
    }
    let travelled: f64 = f
        .positions
        .windows(2)
        .map(|w| (vec2(w[1][0][0], w[1][0][1]) - vec2(w[0][0][0], w[0][0][1])).norm())
        .sum();
    println!(
        "{scene} ({params}): {} steps, agent 0 travelled {travelled:.2} m, max deviation {worst:.2e} m",
        f.positions.len() - 1
    );
    assert!(travelled > 5.0, "{scene}: the scene must actually move");
    worst
}

fn check(scene: &str) {
    for params in ["default", "table_i"] {
        let worst = replay(scene, params);
        assert!(
            worst <= TOLERANCE_M,
            "{scene} ({params}): deviates {worst} m from PySocialForce"
        );
    }
}

#[test]
fn head_on_pair_matches_pysocialforce() {
    check("head_on_pair");
}

#[test]
fn group_crossing_a_line_obstacle_matches_pysocialforce() {
    check("group_crossing_line");
}

#[test]
fn two_groups_passing_match_pysocialforce() {
    check("two_groups_passing");
}
