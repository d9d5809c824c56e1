use super::*;
use crate::map::Obstacle;
use crate::math::vec2;
use crate::model::AgentKind;

fn ego_at_origin() -> EgoState {
    EgoState {
        position: vec2(0.0, 0.0),
        heading: 0.0,
        velocity: vec2(1.0, 0.0),
        yaw_rate: 0.0,
        radius: 0.3,
    }
}

fn standing(id: u64, x: Real, y: Real) -> Neighbour {
    Neighbour::new(id, vec2(x, y), vec2(0.0, 0.0), 0.35, AgentKind::Human)
}

fn plan(neighbours: &[Neighbour], map: &StaticMap) -> PgpDecision {
    Pgp::new(PgpParams::default()).plan(&ego_at_origin(), neighbours, map, vec2(20.0, 0.0))
}

#[test]
fn fan_has_22_candidates_over_the_papers_angles() {
    let d = plan(&[], &StaticMap::empty());
    let fan = d.fan.expect("fan recorded by default");
    assert_eq!(fan.candidates.len(), 22);
    let degrees: Vec<i64> = fan
        .candidates
        .iter()
        .step_by(2)
        .map(|c| c.alpha.to_degrees().round() as i64)
        .collect();
    assert_eq!(
        degrees,
        vec![-80, -64, -48, -32, -16, 0, 16, 32, 48, 64, 80]
    );
    for c in &fan.candidates {
        assert_eq!(c.positions.len(), 33);
        assert_eq!(c.survival.len(), 33);
        assert!(
            c.survival.windows(2).all(|w| w[1] <= w[0]),
            "survival must not increase"
        );
    }
    assert!(
        (fan.pgp_goal - vec2(8.0, 0.0)).norm() < 1e-12,
        "d_goal = 8 m along the goal line"
    );
}

#[test]
fn open_space_goes_straight_with_subgoal_at_cca_distance() {
    let d = plan(&[], &StaticMap::empty());
    let fan = d.fan.expect("fan");
    assert_eq!(fan.candidates[fan.best].alpha, 0.0);
    assert!((d.subgoal - vec2(2.0, 0.0)).norm() < 1e-12);
    // Straight at 1 m/s with only p_escape: Σ_i exp(−0.01·i) · 1 for i = 1..=32.
    let expected: Real = (1..=32).map(|i| (-0.01 * i as Real).exp()).sum();
    assert!((fan.candidates[fan.best].expected_utility - expected).abs() < 1e-9);
    assert_eq!(d.trajectory.len(), 32);
    assert!((d.trajectory[31].position - vec2(8.0, 0.0)).norm() < 1e-9);
}

#[test]
fn turn_slowdown_halves_speed_for_the_turn_time() {
    // Heading backwards: every candidate needs > 30° of turn and starts at 0.5 m/s.
    let mut ego = ego_at_origin();
    ego.heading = std::f64::consts::PI;
    let d = Pgp::new(PgpParams::default()).plan(&ego, &[], &StaticMap::empty(), vec2(20.0, 0.0));
    let fan = d.fan.expect("fan");
    let straight = &fan.candidates[10];
    assert_eq!(straight.alpha, 0.0);
    // γ_turn = π, γ̇_max = 1 rad/s: 0.5 m/s for π s. After one step: 0.125 m.
    assert!((straight.positions[1].x - 0.125).abs() < 1e-12);
    let t_turn = std::f64::consts::PI;
    let at_8s = 0.5 * t_turn + (8.0 - t_turn);
    assert!((straight.positions[32].x - at_8s).abs() < 1e-9);
}

#[test]
fn picks_the_open_gap_in_a_wall_of_pedestrians() {
    // A wall of standing people across the goal line at x = 4, except a gap around y = 2.
    let mut crowd = Vec::new();
    let mut y = -7.0;
    let mut id = 0;
    while y <= 7.0 {
        if !(1.0..=2.9).contains(&y) {
            crowd.push(standing(id, 4.0, y));
            id += 1;
        }
        y += 0.6;
    }
    let d = plan(&crowd, &StaticMap::empty());
    let fan = d.fan.expect("fan");
    let best = &fan.candidates[fan.best];
    // Where the chosen candidate crosses the wall line.
    let crossing = best
        .positions
        .windows(2)
        .find(|w| w[0].x < 4.0 && w[1].x >= 4.0)
        .expect("crosses x = 4");
    assert!(
        (1.2..=2.7).contains(&crossing[1].y),
        "crosses at y = {}, not in the gap",
        crossing[1].y
    );
    assert!(
        best.alpha > 0.0 && d.subgoal.y > 0.5,
        "subgoal {:?} should lean towards the gap",
        d.subgoal
    );
    // It beats going straight into the wall.
    let straight = fan
        .candidates
        .iter()
        .find(|c| c.alpha == 0.0)
        .expect("straight candidate");
    assert!(best.expected_utility > straight.expected_utility + 1.0);
}

#[test]
fn passes_behind_a_crossing_pedestrian_like_fig_6() {
    // Paper Fig. 6: the person crosses the robot's path ahead of it, towards the robot's
    // right; PGP biases to the left, behind them. They reach the goal line at t = 3 s, when
    // the robot is 1 m short of their crossing point.
    let walker = |vy: Real| {
        vec![Neighbour::new(
            7,
            vec2(4.0, -3.0 * vy),
            vec2(0.0, vy),
            0.35,
            AgentKind::Human,
        )]
    };
    let to_right = plan(&walker(-1.0), &StaticMap::empty());
    assert!(
        to_right.subgoal.y > 0.1,
        "subgoal {:?} should be on the left",
        to_right.subgoal
    );
    let to_left = plan(&walker(1.0), &StaticMap::empty());
    assert!(
        to_left.subgoal.y < -0.1,
        "subgoal {:?} should be on the right",
        to_left.subgoal
    );
}

#[test]
fn a_shelf_on_the_goal_line_lowers_survival_of_the_straight_candidate() {
    let shelf = Obstacle::Polygon(vec![
        vec2(3.0, -0.5),
        vec2(5.0, -0.5),
        vec2(5.0, 0.5),
        vec2(3.0, 0.5),
    ]);
    let map = StaticMap::new(vec![shelf]).expect("valid shelf");
    let d = plan(&[], &map);
    let fan = d.fan.expect("fan");
    let straight = fan
        .candidates
        .iter()
        .find(|c| c.alpha == 0.0)
        .expect("straight");
    assert!(
        straight.survival[32] < 1e-3,
        "driving through a shelf must not survive"
    );
    assert_ne!(fan.candidates[fan.best].alpha, 0.0);
}

#[test]
fn shared_intent_changes_the_prediction_pgp_uses() {
    use crate::model::{SharedIntent, TrajectorySample};
    // A robot ahead, currently still, announcing it will drive to (4, 0) i.e. onto our line.
    let mut robot = Neighbour::new(1, vec2(4.0, 3.0), vec2(0.0, 0.0), 0.3, AgentKind::Robot);
    let still = plan(std::slice::from_ref(&robot), &StaticMap::empty());
    robot.intent = Some(SharedIntent {
        samples: (1..=16)
            .map(|i| {
                let t = i as Real * 0.25;
                TrajectorySample {
                    t,
                    position: vec2(4.0, (3.0 - t).max(0.0)),
                    sigma: 0.1666,
                }
            })
            .collect(),
    });
    let shared = plan(&[robot], &StaticMap::empty());
    let u = |d: &PgpDecision| {
        d.fan
            .as_ref()
            .map(|f| f.candidates[10].expected_utility)
            .expect("fan")
    };
    assert!(
        u(&shared) < u(&still),
        "the announced crossing must make the straight line riskier"
    );
}

#[test]
fn same_input_same_output() {
    let crowd: Vec<_> = (0..30)
        .map(|i| standing(i, 2.0 + (i % 6) as Real, -3.0 + (i / 6) as Real * 1.3))
        .collect();
    assert_eq!(
        plan(&crowd, &StaticMap::empty()),
        plan(&crowd, &StaticMap::empty())
    );
}

#[test]
fn risk_floor_culling_changes_no_decision_and_utilities_by_under_1e_6() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    for scene in 0..20 {
        let n = 5 + scene * 5;
        let half = (n as Real / 0.5).sqrt() / 2.0;
        let crowd: Vec<_> = (0..n)
            .map(|i| {
                let p = vec2(rng.random_range(-half..half), rng.random_range(-half..half));
                let v = crate::math::unit(rng.random_range(0.0..std::f64::consts::TAU))
                    * rng.random_range(0.0..1.3);
                Neighbour::new(i as u64, p, v, 0.35, AgentKind::Human)
            })
            .collect();
        let exact = Pgp::new(PgpParams {
            risk_floor: 0.0,
            ..PgpParams::default()
        })
        .plan(
            &ego_at_origin(),
            &crowd,
            &StaticMap::empty(),
            vec2(20.0, 0.0),
        );
        let culled = plan(&crowd, &StaticMap::empty());
        let (fe, fc) = (exact.fan.expect("fan"), culled.fan.expect("fan"));
        assert_eq!(
            fe.best, fc.best,
            "scene {scene}: culling changed the decision"
        );
        assert_eq!(exact.subgoal, culled.subgoal);
        for (a, b) in fe.candidates.iter().zip(&fc.candidates) {
            assert!(
                (a.expected_utility - b.expected_utility).abs() < 1e-6,
                "scene {scene}"
            );
        }
    }
}

/// Regression: with the goal nearer than d_turned, every candidate's first segment overshot
/// it (the straight one into the wall behind a goal placed by a wall), so PGP preferred
/// sideways detours and the robot circled the goal (traced in the walled open-space study).
#[test]
fn near_the_goal_the_fan_shrinks_and_pgp_heads_straight_for_it() {
    let wall = Obstacle::Wall(vec2(1.6, -5.0), vec2(1.6, 5.0));
    let map = StaticMap::new(vec![wall]).expect("valid wall");
    let goal = vec2(0.6, 0.0);
    let d = Pgp::new(PgpParams::default()).plan(&ego_at_origin(), &[], &map, goal);
    let fan = d.fan.expect("fan");
    assert_eq!(fan.candidates[fan.best].alpha, 0.0);
    assert!(
        (d.subgoal - goal).norm() < 1e-12,
        "subgoal {:?} should be the goal",
        d.subgoal
    );
    let straight = &fan.candidates[10];
    assert!(
        straight.positions.iter().all(|p| p.x <= 0.6 + 1e-9),
        "the straight candidate must not overshoot"
    );
}

/// d_goal = T · v^max (Sec. III-B): the paper's 8 m at 1 m/s, and a faster robot's PGP goal
/// one horizon of its own top speed away (11.76 m at the 1.47 m/s of the ETH runs).
#[test]
fn d_goal_is_one_horizon_at_top_speed() {
    assert!((PgpParams::default().d_goal() - 8.0).abs() < 1e-12);
    let fast = PgpParams {
        v_max: 1.47,
        speed: 1.47,
        ..PgpParams::default()
    };
    assert!((fast.d_goal() - 11.76).abs() < 1e-12);
    let d = Pgp::new(fast).plan(&ego_at_origin(), &[], &StaticMap::empty(), vec2(20.0, 0.0));
    let fan = d.fan.expect("fan recorded by default");
    assert!(
        (fan.pgp_goal - vec2(11.76, 0.0)).norm() < 1e-12,
        "{:?}",
        fan.pgp_goal
    );
}

#[test]
fn a_goal_beyond_d_goal_keeps_the_papers_fan() {
    let d = plan(&[], &StaticMap::empty());
    let fan = d.fan.expect("fan");
    // α = 16°, no slow-down (< 30°): after 2.5 s at 1 m/s the candidate is at the paper's
    // P_out, d_turned = 2.5 m out along α.
    let c = &fan.candidates[12];
    assert!((c.alpha.to_degrees() - 16.0).abs() < 1e-9);
    let p_out = crate::math::rotate(&vec2(1.0, 0.0), c.alpha) * 2.5;
    assert!(
        (c.positions[10] - p_out).norm() < 1e-12,
        "{:?} vs {p_out:?}",
        c.positions[10]
    );
}

/// The step-major columns PGP predicts into hold, bit for bit, what `prediction::predict`
/// gives each neighbour, for straight, turning and announcing neighbours alike, and for a
/// planner reused with a different crowd.
#[test]
fn predicted_columns_are_each_neighbours_prediction() {
    use crate::model::{SharedIntent, TrajectorySample};
    let crowd = |shift: Real, count: u64| -> Vec<Neighbour> {
        (0..count)
            .map(|i| {
                let a = i as Real * 0.7 + shift;
                let mut nb = Neighbour::new(
                    i,
                    vec2(3.0 * a.cos(), 3.0 * a.sin()),
                    vec2(0.9 * (2.0 * a).sin(), 0.4 * a.cos()),
                    0.35,
                    AgentKind::Human,
                );
                match i % 4 {
                    1 => nb.yaw_rate = 0.3 * a.sin() + 0.05,
                    2 => {
                        nb.intent = Some(SharedIntent {
                            samples: (1..=6)
                                .map(|s| TrajectorySample {
                                    t: s as Real * 0.5,
                                    position: nb.position + vec2(0.0, 0.3 * s as Real),
                                    sigma: 0.2,
                                })
                                .collect(),
                        })
                    }
                    _ => {}
                }
                nb
            })
            .collect()
    };
    let mut pgp = Pgp::new(PgpParams::default());
    let (ego, map) = (ego_at_origin(), StaticMap::empty());
    for (shift, count) in [(0.0, 13), (1.3, 9), (2.1, 17)] {
        let neighbours = crowd(shift, count);
        pgp.plan(&ego, &neighbours, &map, vec2(20.0, 0.0));
        let (p, k_count) = (pgp.params.clone(), neighbours.len());
        for (k, nb) in neighbours.iter().enumerate() {
            let mut track = Track::default();
            crate::prediction::predict(nb, p.dt, p.steps, &p.sigma, &mut track);
            for (j, (q, &sigma)) in track.positions.iter().zip(&track.sigma).enumerate() {
                let at = j * k_count + k;
                assert_eq!(
                    (pgp.nb_x[at], pgp.nb_y[at], pgp.nb_sigma[at]),
                    (q.x, q.y, sigma),
                    "crowd {shift}, neighbour {k}, step {j}"
                );
            }
        }
    }
}
