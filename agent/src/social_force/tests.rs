use super::*;

const EPS: Real = 1e-12;

#[test]
fn desired_force_relaxes_towards_max_speed_along_goal_direction() {
    let p = SfParams::default().desired;
    // At rest, goal along +x, max speed 1.3: F = (1.3, 0) / 0.5.
    let f = desired_force(vec2(0.0, 0.0), vec2(0.0, 0.0), vec2(5.0, 0.0), 1.3, &p);
    assert!((f - vec2(2.6, 0.0)).norm() < EPS);
    // Moving sideways at 1 m/s: F = ((1.3, 0) − (0, 1)) / 0.5.
    let f = desired_force(vec2(0.0, 0.0), vec2(0.0, 1.0), vec2(5.0, 0.0), 1.3, &p);
    assert!((f - vec2(2.6, -2.0)).norm() < EPS);
    // Within the goal threshold it only brakes.
    let f = desired_force(vec2(0.0, 0.0), vec2(0.4, 0.0), vec2(0.1, 0.0), 1.3, &p);
    assert!((f - vec2(-0.8, 0.0)).norm() < EPS);
}

#[test]
fn social_force_hand_computed_head_on() {
    // a at origin, b 2 m ahead on +x, both still: D = λ·0 + e(a−b) = (−1, 0), ‖D‖ = 1,
    // B = γ = 0.35, θ = π − π = 0, so only the deceleration term acts:
    // f = exp(−2/0.35)·(−1, 0).
    let p = SfParams::default().social;
    let f = social_force_pair(
        vec2(0.0, 0.0),
        vec2(0.0, 0.0),
        vec2(2.0, 0.0),
        vec2(0.0, 0.0),
        &p,
    );
    let expected = vec2(-(-2.0f64 / 0.35).exp(), 0.0);
    assert!((f - expected).norm() < EPS, "{f:?} vs {expected:?}");
}

#[test]
fn social_force_hand_computed_with_angle() {
    // a at origin moving +x at 1 m/s, b at (2, 1) still. e = (a−b)/‖a−b‖ = (−2, −1)/√5;
    // D = λ(v_b − v_a) + e = 2·(−1, 0) + e; B = γ‖D‖; θ = atan2(D) − atan2(e).
    let p = SfParams::default().social;
    let e = vec2(-2.0, -1.0) / 5f64.sqrt();
    let d = vec2(-2.0, 0.0) + e;
    let t = d / d.norm();
    let b = 0.35 * d.norm();
    let theta = t.y.atan2(t.x) - e.y.atan2(e.x);
    let dist = 5f64.sqrt();
    let fv = (-dist / b - (3.0 * b * theta).powi(2)).exp();
    let fa = -theta.signum() * (-dist / b - (2.0 * b * theta).powi(2)).exp();
    let expected = t * fv + vec2(-t.y, t.x) * fa;
    let f = social_force_pair(
        vec2(0.0, 0.0),
        vec2(1.0, 0.0),
        vec2(2.0, 1.0),
        vec2(0.0, 0.0),
        &p,
    );
    assert!((f - expected).norm() < EPS);
    assert!(
        f.norm() > 1e-4,
        "the force must not vanish in this configuration"
    );
}

#[test]
fn obstacle_points_follow_pysocialforce_linspace() {
    // A 1 m line at resolution 10: int(10) = 10 points from start to end inclusive.
    let pts = ObstaclePoints::from_segments([(vec2(0.0, 0.0), vec2(1.0, 0.0))], 10.0);
    assert_eq!(pts.points().len(), 10);
    assert_eq!(pts.points()[0], vec2(0.0, 0.0));
    assert_eq!(pts.points()[9], vec2(1.0, 0.0));
    assert!((pts.points()[1].x - 1.0 / 9.0).abs() < EPS);
}

#[test]
fn obstacle_force_hand_computed_single_point() {
    // One point 1 m below: dist = 1 − 0.35 = 0.65 < 3.35, F = 10·exp(−0.65/0.2)·(0, 1).
    let p = SfParams::default().obstacle;
    let one = ObstaclePoints::from_points(vec![vec2(0.0, 0.0)]);
    let f = obstacle_force(vec2(0.0, 1.0), &one, 0.35, &p);
    assert!((f - vec2(0.0, 10.0 * (-0.65f64 / 0.2).exp())).norm() < EPS);
    // Out of range: nothing.
    let f = obstacle_force(vec2(0.0, 4.0), &one, 0.35, &p);
    assert_eq!(f, vec2(0.0, 0.0));
}

/// The grid-indexed obstacle force is bit-identical to the full scan, everywhere on a map with
/// many walls, including bodies outside the points' bounding box.
#[test]
fn indexed_obstacle_force_equals_the_full_scan_bit_for_bit() {
    let p = SfParams::default().obstacle;
    // A comb of 30 walls, 1.5 m apart.
    let segments: Vec<(Vec2, Vec2)> = (0..30)
        .map(|k| {
            (
                vec2(0.0, 1.5 * k as Real),
                vec2(20.0, 1.5 * k as Real + 0.3),
            )
        })
        .collect();
    let full = ObstaclePoints::from_segments(segments.clone(), 10.0);
    let radius = 0.35;
    let indexed = ObstaclePoints::from_segments(segments, 10.0).indexed(p.threshold + 2.0 * radius);
    let mut checked = 0;
    for ix in -20..=60 {
        for iy in -20..=110 {
            let pos = vec2(0.37 * ix as Real, 0.41 * iy as Real);
            let a = obstacle_force(pos, &full, radius, &p);
            let b = obstacle_force(pos, &indexed, radius, &p);
            assert_eq!(a.x.to_bits(), b.x.to_bits(), "at {pos:?}");
            assert_eq!(a.y.to_bits(), b.y.to_bits(), "at {pos:?}");
            checked += usize::from(a != vec2(0.0, 0.0));
        }
    }
    assert!(checked > 2000, "most probes feel a wall ({checked})");
    // A larger body than the grid was built for falls back to the full scan.
    let big = obstacle_force(vec2(5.0, 5.0), &indexed, 2.0, &p);
    assert_eq!(big, obstacle_force(vec2(5.0, 5.0), &full, 2.0, &p));
}

#[test]
fn group_forces_hand_computed_for_a_pair() {
    // Two members 2 m apart, both heading to +x goals 10 m away; no other forces by setting
    // their weights to zero.
    let mut p = SfParams::default();
    p.desired.factor = 0.0;
    p.social.factor = 0.0;
    p.obstacle.factor = 0.0;
    let crowd = Crowd::new(
        vec![vec2(0.0, 0.0), vec2(0.0, 2.0)],
        vec![vec2(1.0, 0.0), vec2(1.0, 0.0)],
        vec![vec2(10.0, 0.0), vec2(10.0, 2.0)],
        vec![vec![0, 1]],
        &p,
    );
    let mut f = Vec::new();
    crowd.forces(&ObstaclePoints::default(), &p, &mut f);
    // Coherence: com − p = (0, 1), threshold 0.5: softened = (tanh(0 − 0.5) + 1) / 2 (PySF
    // measures the distance as 0), weight 1. Repulsion: 2 m > 0.55, none. Gaze:
    // e·com_dir = 0, none.
    let expected = ((-0.5f64).tanh() + 1.0) / 2.0;
    assert!((f[0] - vec2(0.0, expected)).norm() < EPS);
    assert!((f[1] - vec2(0.0, -expected)).norm() < EPS);
}

#[test]
fn capped_velocity_scales_down_only() {
    assert!((capped_velocity(vec2(3.0, 4.0), 1.0) - vec2(0.6, 0.8)).norm() < EPS);
    assert_eq!(capped_velocity(vec2(0.3, 0.4), 1.0), vec2(0.3, 0.4));
    assert_eq!(capped_velocity(vec2(0.0, 0.0), 1.0), vec2(0.0, 0.0));
}

/// θ with one `atan2` equals PySocialForce's difference of two, unwrapped jumps included.
#[test]
fn interaction_angle_matches_the_difference_of_two_atan2() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let reference = |e: Vec2, i: Vec2| i.y.atan2(i.x) - e.y.atan2(e.x);
    let mut unwrapped = 0;
    let mut check = |e: Vec2, i: Vec2| {
        let (ours, theirs) = (pysf_theta(e, i), reference(e, i));
        assert!(
            (ours - theirs).abs() <= 4e-15,
            "e {e:?} i {i:?}: {ours} vs {theirs}"
        );
        unwrapped += usize::from(theirs.abs() > std::f64::consts::PI);
    };
    for _ in 0..200_000 {
        let a: Real = rng.random_range(-4.0..4.0);
        let b: Real = rng.random_range(-4.0..4.0);
        check(vec2(a.cos(), a.sin()), vec2(b.cos(), b.sin()));
    }
    // Axes, signed zeros, the zero vector and turns straddling the negative x axis.
    let special = [
        vec2(1.0, 0.0),
        vec2(-1.0, 0.0),
        vec2(-1.0, -0.0),
        vec2(0.0, 1.0),
        vec2(0.0, -1.0),
        vec2(0.0, 0.0),
        vec2(-1.0, 1e-17),
        vec2(-1.0, -1e-17),
        vec2(1.0, 1e-17),
    ];
    for e in special {
        for i in special {
            check(e, i);
        }
    }
    assert!(
        unwrapped > 10_000,
        "the jumps must be exercised ({unwrapped})"
    );
}
