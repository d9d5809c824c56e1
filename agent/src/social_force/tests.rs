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

/// The pair's shared arithmetic gives both one-sided forces bit for bit, the θ jumps
/// included, where the reaction is not minus the action.
#[test]
fn mutual_forces_are_the_one_sided_force_both_ways() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let p = SfParams::default().social;
    let mut asymmetric = 0;
    for _ in 0..100_000 {
        let mut v = || vec2(rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0));
        let (pa, va, pb, vb) = (v(), v() * 0.5, v(), v() * 0.5);
        let (on_a, on_b) = mutual_social_forces(pa, va, pb, vb, &p);
        assert_eq!(on_a, social_force_pair(pa, va, pb, vb, &p));
        assert_eq!(
            on_b,
            social_force_pair(pb, vb, pa, va, &p),
            "{pa} {va} {pb} {vb}"
        );
        asymmetric += usize::from(on_b != -on_a);
    }
    assert!(
        asymmetric > 1_000,
        "θ jumps must be exercised ({asymmetric})"
    );
}
