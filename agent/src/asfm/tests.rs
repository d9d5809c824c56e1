use super::model::{repulsion, step};
use super::optimise::{Body, Scene};
use super::*;
use crate::asfm::ASFM_Q_PROCESS_NOISE;
use crate::model::AgentKind;

fn ego(position: Vec2, velocity: Vec2) -> EgoState {
    EgoState {
        position,
        heading: 0.0,
        velocity,
        yaw_rate: 0.0,
        radius: 0.0,
    }
}

#[test]
fn eq3_pushes_away_along_the_line_of_centres_and_decays_with_range() {
    let near = repulsion(vec2(1.0, 0.0), 0.0, 20.0, 2.0);
    assert!((near.x - 20.0 * (-0.5 as Real).exp()).abs() < 1e-12 && near.y == 0.0);
    let far = repulsion(vec2(0.0, -3.0), 0.0, 20.0, 2.0);
    assert!((far.y + 20.0 * (-1.5 as Real).exp()).abs() < 1e-12);
    // With bodies the decay runs over the gap between surfaces.
    let bodies = repulsion(vec2(1.0, 0.0), 0.6, 20.0, 2.0);
    assert!((bodies.x - 20.0 * (-0.2 as Real).exp()).abs() < 1e-12);
    assert_eq!(repulsion(vec2(0.0, 0.0), 0.0, 20.0, 2.0), vec2(0.0, 0.0));
}

#[test]
fn eq1_integrates_constant_acceleration_exactly() {
    let (r, v) = step(vec2(0.0, 0.0), vec2(1.0, 0.0), vec2(0.0, 2.0), 0.5);
    assert_eq!(r, vec2(0.5, 0.25));
    assert_eq!(v, vec2(1.0, 1.0));
}

fn person(id: u64, position: Vec2, velocity: Vec2) -> Neighbour {
    Neighbour::new(id, position, velocity, 0.0, AgentKind::Human)
}

/// A body walking +y at 1 m/s past a robot standing at the origin, observed exactly every
/// 0.1 s for `seconds`, avoiding the robot with strength `a_o` (Eqs. 1–4, its intended
/// velocity kept). Returns the planner's final Â_o.
fn estimate_after(a_o: Real, seconds: Real) -> Real {
    let p = AsfmParams::default();
    let mut planner = Asfm::new(p.clone());
    let robot = ego(vec2(0.0, 0.0), vec2(0.0, 0.0));
    let (mut o, mut v) = (vec2(0.8, -2.0), vec2(0.0, 1.0));
    let intended = v;
    let map = StaticMap::empty();
    for _ in 0..(seconds / p.dt).round() as usize {
        planner.step(&robot, &[person(7, o, v)], &map, vec2(0.0, 0.0), p.dt);
        let a = repulsion(o, 0.0, a_o, p.range) + (intended - v) / p.tau;
        (o, v) = step(o, v, a, p.dt);
    }
    planner.estimates().next().expect("tracked").1
}

#[test]
fn the_estimate_grows_for_a_body_that_avoids_and_stays_near_zero_for_one_that_does_not() {
    // Exact observations. Table II's Σ = 0.1·I makes each step weak evidence: after 3 s
    // Â_o is about 2 for A_o = 20 (results/anticipatory/REPORT.md).
    let avoids = estimate_after(20.0, 3.0);
    let ignores = estimate_after(0.0, 3.0);
    assert!(avoids > 1.5, "Â_o = {avoids} for A_o = 20");
    // The model explains a body that ignores the robot exactly: Â_o stays at the prior's 0.
    assert!(ignores.abs() < 1e-9, "Â_o = {ignores} for A_o = 0");
    // It grows: small at first (the prior leans to "does not avoid"), larger later.
    assert!(estimate_after(20.0, 0.3) < avoids);
}

#[test]
fn the_posterior_starts_as_the_prior_and_stays_a_distribution() {
    let p = AsfmParams::default();
    let mut planner = Asfm::new(p.clone());
    let robot = ego(vec2(0.0, 0.0), vec2(0.0, 0.0));
    let map = StaticMap::empty();
    planner.step(
        &robot,
        &[person(1, vec2(1.0, -2.0), vec2(0.0, 1.0))],
        &map,
        vec2(5.0, 0.0),
        0.1,
    );
    let (samples, weights) = planner.posterior(1).expect("tracked");
    assert_eq!(samples.len(), p.samples);
    assert_eq!((samples[0], samples[p.samples - 1]), (-40.0, 40.0));
    assert!((weights.iter().sum::<Real>() - 1.0).abs() < 1e-12);
    // N(0, σ²) on a symmetric grid: mean 0; the weights' ratio is the normal's.
    assert!(planner.estimates().next().expect("tracked").1.abs() < 1e-12);
    let mid = p.samples / 2;
    let ratio = weights[mid + 10] / weights[mid];
    assert!((ratio - (-100.0 / (2.0 * 100.0) as Real).exp()).abs() < 1e-12);
}

#[test]
fn the_kalman_gain_follows_eqs_8_and_9() {
    // Without process noise (Eq. 9 as written), P_n = P0·R / (R + n·P0).
    let p = AsfmParams::default();
    let mut planner = Asfm::new(p.clone());
    let robot = ego(vec2(0.0, 0.0), vec2(0.0, 0.0));
    let map = StaticMap::empty();
    let far = |k: usize| vec2(50.0, k as Real * 0.1);
    for k in 0..6 {
        planner.step(
            &robot,
            &[person(3, far(k), vec2(0.0, 1.0))],
            &map,
            vec2(1.0, 0.0),
            0.1,
        );
    }
    let track = &planner.tracks[0];
    let expected = p.kalman_p0 * p.kalman_r / (p.kalman_r + 5.0 * p.kalman_p0);
    assert!((track.p - expected).abs() < 1e-15, "P = {}", track.p);
    // A body far from the robot walking exactly as observed: the filter follows it.
    let (r, v) = planner.filtered(3).expect("tracked");
    assert!((r - far(5)).norm() < 1e-9 && (v - vec2(0.0, 1.0)).norm() < 1e-6);
}

#[test]
fn the_long_cycle_runs_every_update_period() {
    let p = AsfmParams::default();
    let mut planner = Asfm::new(p.clone());
    let map = StaticMap::empty();
    let updated: Vec<bool> = (0..7)
        .map(|k| {
            let robot = ego(vec2(k as Real * 0.1, 0.0), vec2(1.0, 0.0));
            planner
                .step(&robot, &[], &map, vec2(10.0, 0.0), 0.1)
                .updated
        })
        .collect();
    assert_eq!(updated, [true, false, true, false, true, false, true]);
}

#[test]
fn in_the_open_the_desired_velocity_is_top_speed_toward_the_goal() {
    let p = AsfmParams::default();
    let mut planner = Asfm::new(p.clone());
    let robot = ego(vec2(0.0, 0.0), vec2(0.0, 0.0));
    let out = planner.step(&robot, &[], &StaticMap::empty(), vec2(10.0, 0.0), 0.1);
    // Within 0.2° of the goal's direction (the optimiser stops short of exact).
    let d = out.desired;
    assert!(d.x > 0.95 * p.v_max && (d.y / d.x).abs() < 0.0035, "{d:?}");
    // Eq. 11 with τ = Δt: the command is the desired velocity.
    assert!((out.command - out.desired).norm() < 1e-9);
    assert_eq!(out.trajectory.len(), p.horizon);
}

#[test]
fn the_optimised_velocities_keep_d_min_from_a_body_that_does_not_avoid() {
    // A body standing 2 m ahead, straight on the way to the goal.
    let p = AsfmParams::default();
    let mut planner = Asfm::with_estimation(p.clone(), Estimation::Fixed(0.0));
    let robot = ego(vec2(0.0, 0.0), vec2(1.0, 0.0));
    let body = person(2, vec2(2.0, 0.0), vec2(0.0, 0.0));
    let map = StaticMap::empty();
    planner.step(
        &robot,
        std::slice::from_ref(&body),
        &map,
        vec2(6.0, 0.0),
        0.1,
    );
    let solution = planner.last_solution().expect("optimised");
    let closest = solution
        .path
        .iter()
        .map(|q| (q - body.position).norm())
        .fold(Real::INFINITY, Real::min);
    assert!(closest > p.d_min, "passes within {closest} m");
    // It does better than the straight line it started from.
    let straight = Scene {
        robot: (robot.position, robot.velocity, 0.0),
        goal: vec2(6.0, 0.0),
        bodies: vec![Body {
            position: body.position,
            velocity: body.velocity,
            radius: 0.0,
            strength: 0.0,
            goal: None,
            intended: vec2(0.0, 0.0),
        }],
        walls: Vec::new(),
    };
    let start: Vec<Real> = (0..p.horizon)
        .flat_map(|_| {
            let u = optimise::unsquash(vec2(0.9 * p.v_max, 0.0), p.v_max);
            [u.x, u.y]
        })
        .collect();
    let j0 = optimise::Objective::new(&straight, &p)
        .terms(&start)
        .0
        .total();
    assert!(
        solution.terms.total() < j0,
        "{} ≥ {j0}",
        solution.terms.total()
    );
}

/// A scene with every part of the rollout: a body with an intent and one with a goal, a wall
/// within reach and one whose nearest point is its end, a robot fast enough to be clamped.
fn gradient_scene() -> Scene {
    Scene {
        robot: (vec2(0.0, 0.0), vec2(1.2, 0.6), 0.3),
        goal: vec2(5.0, 1.0),
        bodies: vec![
            Body {
                position: vec2(1.5, 0.3),
                velocity: vec2(-0.8, 0.0),
                radius: 0.3,
                strength: 7.0,
                goal: None,
                intended: vec2(-1.0, 0.0),
            },
            Body {
                position: vec2(2.0, -1.0),
                velocity: vec2(0.0, 0.5),
                radius: 0.3,
                strength: 15.0,
                goal: Some(vec2(2.0, 3.0)),
                intended: vec2(0.0, 0.0),
            },
        ],
        walls: vec![
            (vec2(-5.0, -2.0), vec2(10.0, -2.0)),
            (vec2(-3.0, 1.6), vec2(-0.5, 1.6)),
        ],
    }
}

#[test]
fn the_adjoint_gradient_is_that_of_central_differences() {
    // The paper's parameters and `asfm-crowd`'s (another range, d_min, time-to-go and wall
    // strength).
    for p in [AsfmParams::default(), AsfmParams::crowd()] {
        adjoint_matches_central_differences(&p);
    }
}

fn adjoint_matches_central_differences(p: &AsfmParams) {
    use argmin::core::{CostFunction, Gradient};
    let scene = gradient_scene();
    let objective = optimise::Objective::new(&scene, p);
    for (case, offset) in [0.3, -0.9, 1.7].into_iter().enumerate() {
        let u: Vec<Real> = (0..2 * p.horizon)
            .map(|i| offset + 0.1 * (i % 5) as Real - 0.05 * (i % 3) as Real)
            .collect();
        let g = objective.gradient(&u).expect("finite");
        let scale = g.iter().fold(1.0, |m: Real, x| m.max(x.abs()));
        for j in 0..u.len() {
            let h = 1e-6;
            let mut plus = u.clone();
            plus[j] += h;
            let mut minus = u.clone();
            minus[j] -= h;
            let fd = (objective.cost(&plus).expect("finite")
                - objective.cost(&minus).expect("finite"))
                / (2.0 * h);
            assert!(
                (g[j] - fd).abs() <= 1e-6 * scale,
                "case {case}, component {j}: adjoint {} against {fd} (scale {scale})",
                g[j]
            );
        }
    }
}

#[test]
fn squash_and_unsquash_are_inverse_inside_the_disc() {
    for v in [vec2(0.0, 0.0), vec2(1.0, -0.5), vec2(-0.3, 1.4)] {
        let back = optimise::squash(optimise::unsquash(v, 1.5), 1.5);
        assert!((back - v).norm() < 1e-12, "{v:?} → {back:?}");
    }
    assert!(optimise::squash(vec2(1e6, 1e6), 1.5).norm() <= 1.5);
}

#[test]
fn observations_far_apart_are_predicted_in_model_steps() {
    // A person walking a circle (radius 5 m, 1.2 m/s) observed every 0.4 s, as ETH's frames
    // come, far from a robot standing still. One Eq. 1 step of 0.4 s under τ = 0.1 s would
    // overshoot the relaxation fourfold; in model steps the filter stays on the person and the
    // estimate stays near 0. (With Eq. 9 as written, no process noise, the gain falls as
    // 1/(n + 1) and the filter drifts off a person who turns: 11 m here after 24 s; `asfm-q`.)
    let p = AsfmParams {
        process_noise: ASFM_Q_PROCESS_NOISE,
        ..AsfmParams::default()
    };
    let mut planner = Asfm::new(p.clone());
    let robot = ego(vec2(-30.0, 0.0), vec2(0.0, 0.0));
    let map = StaticMap::empty();
    let (radius, speed) = (5.0, 1.2);
    let at = |t: Real| {
        let a = speed * t / radius;
        (
            vec2(radius * a.cos(), radius * a.sin()),
            vec2(-a.sin(), a.cos()) * speed,
        )
    };
    for k in 0..60 {
        let (r, v) = at(k as Real * 0.4);
        planner.step(&robot, &[person(4, r, v)], &map, vec2(-30.0, 5.0), 0.4);
    }
    let (filtered, _) = planner.filtered(4).expect("tracked");
    let truth = at(59.0 * 0.4).0;
    assert!((filtered - truth).norm() < 0.5, "{filtered:?} vs {truth:?}");
    let estimate = planner.estimates().next().expect("tracked").1;
    assert!(estimate.abs() < 2.0, "Â_o = {estimate}");
}

#[test]
fn the_crowd_time_to_go_falls_only_as_the_robot_nears_its_goal() {
    // The robot 5 m from its goal with nobody about, driving at `speed` toward it (> 0) or
    // away from it (< 0), as a fraction of v^max.
    let mut scene = gradient_scene();
    scene.bodies.clear();
    scene.walls.clear();
    scene.robot = (vec2(0.0, 0.0), vec2(0.0, 0.0), 0.3);
    scene.goal = vec2(5.0, 0.0);
    let time = |p: &AsfmParams, speed: Real| {
        let u = optimise::unsquash(vec2(speed * p.v_max, 0.0), p.v_max);
        let seq: Vec<Real> = (0..p.horizon).flat_map(|_| [u.x, u.y]).collect();
        optimise::Objective::new(&scene, p).terms(&seq).0.time
    };
    // Eq. 16 rates driving away fast better than driving away slowly …
    let paper = AsfmParams::default();
    assert!(time(&paper, -0.9) < time(&paper, -0.1));
    // … `asfm-crowd`'s time-to-go ranks by how near the horizon's end is.
    let crowd = AsfmParams::crowd();
    assert!(time(&crowd, 0.9) < time(&crowd, 0.1));
    assert!(time(&crowd, 0.1) < time(&crowd, -0.1));
    assert!(time(&crowd, -0.1) < time(&crowd, -0.9));
}

#[test]
fn the_crowd_filter_keeps_a_person_drawn_toward_the_robot_where_they_are_seen() {
    // A person standing 1 m from a robot that stands too, seen exactly every 0.1 s for 30 s,
    // the filter's model drawing them toward the robot (Â_o = −7). With Eq. 9 as written the
    // gain falls as 1/(n + 1) and the track follows the model onto the robot: a ghost the
    // optimiser would flee. `asfm-crowd`'s process noise keeps the gain up and the track on
    // the person.
    let seen = vec2(1.0, 0.0);
    let robot = ego(vec2(0.0, 0.0), vec2(0.0, 0.0));
    let map = StaticMap::empty();
    let track_after = |params: AsfmParams| {
        let dt = params.dt;
        let mut planner = Asfm::with_estimation(params, Estimation::Fixed(-7.0));
        for _ in 0..300 {
            planner.step(
                &robot,
                &[person(3, seen, vec2(0.0, 0.0))],
                &map,
                vec2(5.0, 5.0),
                dt,
            );
        }
        planner.filtered(3).expect("tracked").0
    };
    let crowd = track_after(AsfmParams::crowd());
    assert!(
        (crowd - seen).norm() < 0.05,
        "asfm-crowd's track at {crowd:?}"
    );
    let without_noise = track_after(AsfmParams {
        process_noise: 0.0,
        ..AsfmParams::crowd()
    });
    assert!(
        (without_noise - seen).norm() > 0.2,
        "without process noise the track stays at {without_noise:?}"
    );
}

#[test]
fn restarts_take_the_robot_round_a_person_its_warm_start_runs_into() {
    // A person standing 1 m straight ahead who does not avoid the robot (Â_o = 0), the goal
    // beyond them, and a warm start straight at them at 0.95·v^max (the way that was open a
    // moment ago). From there the optimiser keeps driving straight at them; restarts start it
    // from a way round, whose J is lower, and it ends lower.
    let mut scene = gradient_scene();
    scene.walls.clear();
    scene.robot = (vec2(0.0, 0.0), vec2(1.0, 0.0), 0.3);
    scene.goal = vec2(6.0, 0.0);
    scene.bodies = vec![Body {
        position: vec2(1.6, 0.0),
        velocity: vec2(0.0, 0.0),
        radius: 0.3,
        strength: 0.0,
        goal: None,
        intended: vec2(0.0, 0.0),
    }];
    let crowd = AsfmParams::crowd();
    let ahead = vec![vec2(0.95 * crowd.v_max, 0.0); crowd.horizon];
    let with = optimise::optimise(&scene, &ahead, &crowd);
    let without = optimise::optimise(
        &scene,
        &ahead,
        &AsfmParams {
            restarts: false,
            ..crowd.clone()
        },
    );
    // Without: still straight on at top speed (the squash's gradient vanishes there).
    assert!(without.desired[0].y.abs() < 0.1, "{:?}", without.desired[0]);
    assert!(with.desired[0].y.abs() > 0.5, "{:?}", with.desired[0]);
    assert!(
        with.terms.total() < 0.7 * without.terms.total(),
        "{:?} against {:?}",
        with.terms,
        without.terms
    );
}

#[test]
fn the_crowd_robot_passes_a_person_walking_down_the_middle_of_an_aisle() {
    // A 2.5 m aisle between shelves, the robot (r 0.3 m, 1 m/s) driving +x to a goal 14 m on,
    // and a person (r 0.25 m) walking −x down the aisle's middle who does not avoid it
    // (Â_o = 0). Beside them there is room for the robot at d_min with 0.1 m to spare.
    // With the robot's A_r = 20 on the shelves (the paper's reading) it cannot go within
    // 0.35 m of them, so it backs away ahead of the person; with `asfm-crowd`'s wall strength
    // it passes. Positions are integrated as commanded; nobody is stopped by anybody.
    use crate::map::Obstacle;
    let map = StaticMap::new(vec![
        Obstacle::Wall(vec2(-20.0, -1.25), vec2(30.0, -1.25)),
        Obstacle::Wall(vec2(-20.0, 1.25), vec2(30.0, 1.25)),
    ])
    .expect("valid walls");
    let backed_off = |params: AsfmParams| {
        let dt = params.dt;
        let mut planner = Asfm::with_estimation(params, Estimation::Fixed(0.0));
        let mut robot = EgoState {
            radius: 0.3,
            ..ego(vec2(0.0, 0.0), vec2(0.0, 0.0))
        };
        let walker = vec2(-1.0, 0.0);
        let mut at = vec2(6.0, 0.0);
        let (mut furthest, mut back): (Real, Real) = (0.0, 0.0);
        for _ in 0..150 {
            let seen = Neighbour::new(9, at, walker, 0.25, AgentKind::Human);
            let out = planner.step(&robot, &[seen], &map, vec2(14.0, 0.0), dt);
            robot.velocity = out.command;
            robot.position += out.command * dt;
            at += walker * dt;
            furthest = furthest.max(robot.position.x);
            back = back.max(furthest - robot.position.x);
        }
        (back, robot.position.x)
    };
    let crowd = AsfmParams {
        v_max: 1.0,
        ..AsfmParams::crowd()
    };
    let (back, end) = backed_off(crowd.clone());
    assert!(
        back < 0.3 && end > 10.0,
        "asfm-crowd backed off {back} m, ended at x = {end}"
    );
    let (back, end) = backed_off(AsfmParams {
        wall_strength: None,
        ..crowd
    });
    assert!(
        back > 1.0,
        "with A_r on the shelves: backed off {back} m, ended at x = {end}"
    );
}
