use super::risk::{first_contact, loss};
use super::*;
use crate::map::Obstacle;
use crate::math::unit;
use crate::model::AgentKind;

proptest::proptest! {
    /// The goal terms' sort keys order as `total_cmp` does, signs, zeros, infinities and
    /// NaNs included.
    #[test]
    fn sort_keys_order_as_total_cmp(a in proptest::num::f64::ANY, b in proptest::num::f64::ANY) {
        proptest::prop_assert_eq!(ordered(a).cmp(&ordered(b)), a.total_cmp(&b));
        proptest::prop_assert_eq!(ordered(a).cmp(&ordered(-a)), a.total_cmp(&-a));
    }

    /// Ordering only the worst ⌈tail⌉ losses gives CVaR bit for bit as ordering them all.
    #[test]
    fn cvar_orders_only_the_tail_it_takes(
        losses in proptest::collection::vec(
            proptest::prop_oneof![proptest::strategy::Just(0.0), 0.0..2.0f64],
            1..80,
        ),
        alpha in proptest::prop_oneof![
            proptest::strategy::Just(0.0),
            proptest::strategy::Just(0.9),
            proptest::strategy::Just(1.0 - 1.5 / 8.0),
            0.0..1.0f64,
        ],
    ) {
        let mut all = losses.clone();
        let n = all.len();
        let tail = ((1.0 - alpha) * n as Real).max(1e-12);
        all.sort_unstable_by(|a, b| b.total_cmp(a));
        let (mut mass, mut sum) = (tail, 0.0);
        for &l in &all {
            if mass <= 0.0 || l == 0.0 {
                break;
            }
            let w = mass.min(1.0);
            sum += w * l;
            mass -= w;
        }
        let want = if all.iter().all(|&l| l == 0.0) { 0.0 } else { sum / tail };
        let mut ours = losses;
        proptest::prop_assert_eq!(cvar(&mut ours, alpha).to_bits(), want.to_bits());
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(48))]
    /// Cutting candidates short (by the best total so far, and by a risk budget inside a
    /// body's samples), scoring the last plan's choice first and sharing siblings' braking
    /// paths change no decision: a planner
    /// that has just planned another crowd decides, bit for bit, as one scoring every
    /// candidate in full.
    #[test]
    fn cutting_candidates_short_changes_no_decision(
        crowd in proptest::collection::vec(
            (-2.0..14.0f64, -1.1..1.1f64, -1.8..1.8f64, -0.3..0.3f64),
            0..20,
        ),
        speed in 0.0..3.0f64,
        variant in 0usize..7,
    ) {
        let params = [
            PnpParams::peeking(true),
            PnpParams::agile(true),
            PnpParams::paper(true),
            PnpParams::reactive(true),
            PnpParams::fine(false),
            PnpParams::omni(true),
            PnpParams::side_brake(true),
        ][variant]
            .clone();
        let people: Vec<Neighbour> = crowd
            .iter()
            .enumerate()
            .filter(|(_, (x, y, ..))| x.hypot(*y) > 0.7)
            .map(|(i, &(x, y, vx, vy))| person(i as u64, vec2(x, y), vec2(vx, vy)))
            .collect();
        let e = ego(vec2(0.0, 0.0), 0.0, speed);
        let goal = vec2(50.0, 0.0);
        let mut full = hallway_robot(params.clone());
        full.exhaustive = true;
        let want = full.plan(&e, &people, &hallway(), goal, None);
        let mut warm = hallway_robot(params);
        let before = ego(vec2(0.0, 0.5), 0.3, 3.0 - speed);
        warm.plan(&before, &people[people.len() / 2..], &hallway(), goal, None);
        let got = warm.plan(&e, &people, &hallway(), goal, None);
        proptest::prop_assert_eq!(got, want);
    }
}

fn ego(position: Vec2, heading: Real, speed: Real) -> EgoState {
    EgoState {
        position,
        heading,
        velocity: unit(heading) * speed,
        yaw_rate: 0.0,
        radius: 0.3,
    }
}

fn person(id: u64, position: Vec2, velocity: Vec2) -> Neighbour {
    Neighbour::new(id, position, velocity, 0.3, AgentKind::Human)
}

/// A hallway 3 m wide along +x: walls at y = ±1.5 from x = −10 to 100.
fn hallway() -> StaticMap {
    StaticMap::new(vec![
        Obstacle::Wall(vec2(-10.0, -1.5), vec2(100.0, -1.5)),
        Obstacle::Wall(vec2(-10.0, 1.5), vec2(100.0, 1.5)),
    ])
    .expect("valid walls")
}

/// The hallway's 3 m/s robot planning with `params`.
fn hallway_robot(params: PnpParams) -> Pnp {
    Pnp::new(PnpParams {
        v_max: 3.0,
        a_max: 2.0,
        ..params
    })
}

fn fast(peek: bool) -> Pnp {
    hallway_robot(PnpParams::peeking(peek))
}

#[test]
fn cvar_is_the_mean_of_the_worst_tail() {
    // 0/1 losses: k of n collide, CVaR_α = min(1, k / (n·(1 − α))).
    for n in [1usize, 16, 64] {
        for k in 0..=n {
            for alpha in [0.0, 0.5, 0.9, 0.95] {
                let mut losses: Vec<Real> = (0..n).map(|i| if i < k { 1.0 } else { 0.0 }).collect();
                let want = (k as Real / (n as Real * (1.0 - alpha))).min(1.0);
                assert!(
                    (cvar(&mut losses, alpha) - want).abs() < 1e-12,
                    "{k}/{n} at {alpha}"
                );
            }
        }
    }
    // Graded: the worst 25 % of [0.2, 0.9, 0.5, 0.1, 0.4, 0.0, 0.3, 0.8] is {0.9, 0.8}.
    let mut losses = vec![0.2, 0.9, 0.5, 0.1, 0.4, 0.0, 0.3, 0.8];
    assert!((cvar(&mut losses, 0.75) - 0.85).abs() < 1e-12);
    // A tail of 1.5 samples: (0.9 + 0.5·0.8) / 1.5.
    let mut losses = vec![0.2, 0.9, 0.5, 0.1, 0.4, 0.0, 0.3, 0.8];
    assert!((cvar(&mut losses, 1.0 - 1.5 / 8.0) - 1.3 / 1.5).abs() < 1e-12);
    // α = 0: the mean.
    let mut losses = vec![0.2, 0.9, 0.5, 0.1];
    assert!((cvar(&mut losses, 0.0) - 0.425).abs() < 1e-12);
}

#[test]
fn sooner_and_harder_collisions_cost_more() {
    // A body standing 2 m ahead: met at once by a fast path, later by a slow one.
    let stand = |x: Real| -> Vec<Vec2> { (0..=12).map(|_| vec2(x, 0.0)).collect() };
    let other = stand(2.0);
    let path =
        |v: Real| -> Vec<Vec2> { (0..=12).map(|k| vec2(v * 0.25 * k as Real, 0.0)).collect() };
    let fast = first_contact(&path(3.0), 0.6, |k| other[k]).expect("meets");
    let slow = first_contact(&path(1.0), 0.6, |k| other[k]).expect("meets");
    // Contact at 1.4 m: 1.4 / 0.75 and 1.4 / 0.25 steps, closing 0.75 and 0.25 m per step.
    assert!((fast.at - 1.4 / 0.75).abs() < 1e-9 && (fast.closing - 0.75).abs() < 1e-12);
    assert!((slow.at - 1.4 / 0.25).abs() < 1e-9 && (slow.closing - 0.25).abs() < 1e-12);
    let closing = Scoring {
        reference: 4.6 * 0.25,
        severity: Severity::Closing,
    };
    let driving = Scoring {
        severity: Severity::Driving,
        ..closing
    };
    assert!(loss(Some(fast), 12, closing) > loss(Some(slow), 12, closing));
    assert_eq!(first_contact(&path(0.0), 0.6, |k| other[k]), None);
    assert_eq!(loss(None, 12, closing), 0.0);
    // A standing robot walked into at 0.5 m/s loses less than one driving 3 m/s into a
    // standing person at the same moment.
    let walker: Vec<Vec2> = (0..=12)
        .map(|k| vec2(1.0 - 0.5 * 0.25 * k as Real, 0.0))
        .collect();
    let hit = first_contact(&path(0.0), 0.6, |k| walker[k]).expect("walks in");
    assert!((hit.closing - 0.125).abs() < 1e-12);
    // Scored by the robot's own speed toward them, the standing robot loses nothing.
    assert_eq!(hit.driving, 0.0);
    assert_eq!(loss(Some(hit), 12, driving), 0.0);
    assert!((fast.driving - 0.75).abs() < 1e-12);
    assert!(loss(Some(hit), 12, closing) < loss(Some(fast), 12, closing));
}

#[test]
fn with_nothing_around_it_drives_straight_at_top_speed() {
    let mut pnp = fast(true);
    let d = pnp.plan(
        &ego(vec2(0.0, 0.0), 0.0, 3.0),
        &[],
        &StaticMap::empty(),
        vec2(50.0, 0.0),
        None,
    );
    assert_eq!(
        d.command,
        Command::Unicycle {
            speed: 3.0,
            yaw_rate: 0.0
        }
    );
    assert_eq!((d.cost.collision, d.cost.peek, d.edges), (0.0, 0.0, 0));
    // 12 samples 0.25 s (0.75 m) apart, to t_f = 3 s.
    assert_eq!(d.trajectory.len(), 12);
    assert!((d.trajectory[11].t - 3.0).abs() < 1e-9);
    assert!((d.trajectory[11].position.x - 9.0).abs() < 1e-9);
}

#[test]
fn paths_keep_the_bases_limits() {
    let mut pnp = fast(true);
    let e = ego(vec2(0.0, 0.0), 0.3, 1.0);
    pnp.plan(&e, &[], &StaticMap::empty(), vec2(50.0, 0.0), None);
    let n = 12;
    let dt = 0.25;
    // The farthest a path can reach: from 1 m/s at 2 m/s² up to 3 m/s, in 50 ms steps that
    // set the speed, then move (as the simulated base does).
    let (mut v, mut reach) = (1.0, 0.0);
    for _ in 0..60 {
        v = Real::min(v + 2.0 * 0.05, 3.0);
        reach += v * 0.05;
    }
    for path in (0..pnp.candidates()).map(|c| pnp.candidates.path(c, n)) {
        let chords: Vec<Real> = path.windows(2).map(|w| (w[1] - w[0]).norm()).collect();
        assert!(chords.iter().all(|&c| c <= 3.0 * dt + 1e-9));
        // The first 0.25 s: within 1 ± 0.5 m/s.
        assert!(
            (chords[0] / dt - 1.0).abs() <= 0.5 + 1e-9,
            "{}",
            chords[0] / dt
        );
        assert!(chords.iter().sum::<Real>() <= reach + 1e-9);
    }
}

#[test]
fn it_keeps_off_walls_and_people() {
    // A wall across the way 4 m ahead.
    let wall = StaticMap::new(vec![Obstacle::Wall(vec2(4.0, -5.0), vec2(4.0, 5.0))]).unwrap();
    let mut pnp = fast(true);
    let d = pnp.plan(
        &ego(vec2(0.0, 0.0), 0.0, 1.0),
        &[],
        &wall,
        vec2(50.0, 0.0),
        None,
    );
    assert_eq!(d.cost.collision, 0.0, "{d:?}");
    assert!(d.trajectory.iter().all(|s| s.position.x < 4.0 - 0.3));
    // A person walking head-on.
    let mut pnp = fast(true);
    let d = pnp.plan(
        &ego(vec2(0.0, 0.0), 0.0, 2.0),
        &[person(1, vec2(6.0, 0.0), vec2(-1.5, 0.0))],
        &StaticMap::empty(),
        vec2(50.0, 0.0),
        None,
    );
    assert_eq!(d.cost.collision, 0.0, "{d:?}");
}

#[test]
fn the_same_input_gives_the_same_bits() {
    let e = ego(vec2(0.0, 0.0), 0.0, 2.0);
    let people = [
        person(1, vec2(2.0, 0.0), vec2(0.5, 0.0)),
        person(2, vec2(8.0, 0.8), vec2(-1.2, 0.0)),
    ];
    let a = fast(true).plan(&e, &people, &hallway(), vec2(50.0, 0.0), None);
    let mut pnp = fast(true);
    pnp.plan(&e, &people[..1], &hallway(), vec2(50.0, 0.0), None);
    let b = pnp.plan(&e, &people, &hallway(), vec2(50.0, 0.0), None);
    assert_eq!(a, b);
}

#[test]
fn behind_a_slow_person_the_hidden_space_ahead_of_them_has_a_price() {
    // The robot follows a person walking 0.5 m/s 2 m ahead in a 3 m hallway.
    let e = ego(vec2(0.0, 0.0), 0.0, 0.5);
    let people = [person(1, vec2(2.0, 0.0), vec2(0.5, 0.0))];
    let on = fast(true).plan(&e, &people, &hallway(), vec2(50.0, 0.0), None);
    let off = fast(false).plan(&e, &people, &hallway(), vec2(50.0, 0.0), None);
    assert!(on.edges >= 2, "the person casts a shadow: {on:?}");
    eprintln!("on {on:?}\noff {off:?}");
    // Without peeking the robot takes no peeking risk at all, and goes no farther.
    assert_eq!(off.cost.peek, 0.0, "{off:?}");
    assert!(off.cost.goal >= on.cost.goal, "{on:?} {off:?}");
}

#[test]
fn shared_first_segments_give_the_same_paths_as_rolling_each_candidate_out_alone() {
    let mut pnp = fast(true);
    let e = EgoState {
        yaw_rate: 0.4,
        ..ego(vec2(1.0, -0.5), 0.3, 1.2)
    };
    pnp.plan(&e, &[], &StaticMap::empty(), vec2(50.0, 0.0), None);
    let p = pnp.params().clone();
    let (n, substeps, h) = (12, 5, 0.05);
    for (c, primitive) in pnp.candidates.primitives.iter().enumerate() {
        let (mut position, mut heading) = (e.position, e.heading);
        let (mut v, mut w) = (e.velocity.dot(&unit(e.heading)), e.yaw_rate);
        let mut path = vec![position];
        for k in 0..n {
            let (fv, fw) = primitive[k / (n / primitive.len())];
            for _ in 0..substeps {
                v += (fv * p.v_max - v).clamp(-p.a_max * h, p.a_max * h);
                w += (fw * p.omega_max - w).clamp(-p.yaw_accel_max * h, p.yaw_accel_max * h);
                heading += w * h;
                position += unit(heading) * (v * h);
            }
            path.push(position);
        }
        assert_eq!(pnp.candidates.path(c, n), &path[..], "candidate {c}");
    }
}

#[test]
fn social_force_predictions_give_way_to_the_robot_and_constant_velocity_ones_do_not() {
    // A person walking head-on at a standing robot, 2.5 m away, slightly off its line.
    let e = ego(vec2(0.0, 0.0), 0.0, 0.0);
    let walker = [person(1, vec2(2.5, 0.05), vec2(-1.0, 0.0))];
    let closest = |prediction: Prediction| {
        let mut pnp = Pnp::new(PnpParams {
            prediction,
            ..PnpParams::default()
        });
        pnp.plan(&e, &walker, &StaticMap::empty(), vec2(50.0, 0.0), None);
        let track = &pnp.predicted[0].track;
        assert_eq!(track.positions.len(), 13);
        assert_eq!(track.sigma.len(), 13);
        track
            .positions
            .iter()
            .map(|p| p.norm())
            .fold(Real::INFINITY, Real::min)
    };
    // Constant velocity walks straight through the robot; Social Force steps around it.
    assert!(closest(Prediction::ConstantVelocity) < 0.1);
    let sf = closest(Prediction::SocialForce);
    assert!(sf > 0.3, "{sf}");
}

#[test]
fn reactive_predictions_answer_each_candidate() {
    // A person walking head-on at the robot along its line, 5 m away.
    let e = ego(vec2(0.0, 0.0), 0.0, 2.0);
    let walker = [person(1, vec2(5.0, 0.05), vec2(-1.0, 0.0))];
    let mut pnp = hallway_robot(PnpParams::reactive(true));
    pnp.plan(&e, &walker, &StaticMap::empty(), vec2(50.0, 0.0), None);
    let n = 12;
    // The shared rollout, without the robot: a lone person walks straight on.
    let base = pnp.predicted[0].clone();
    assert!(
        base.track
            .positions
            .iter()
            .all(|p| (p.y - 0.05).abs() < 1e-12)
    );
    assert!((base.track.positions[n].x - 2.0).abs() < 1e-9);
    let closest = |track: &[Vec2], path: &[Vec2]| {
        track
            .iter()
            .zip(path)
            .map(|(a, b)| (a - b).norm())
            .fold(Real::INFINITY, Real::min)
    };
    // Against each candidate, the person steps aside from where that candidate puts the robot:
    // for the candidate driving straight at them at top speed they keep farther from the
    // robot than their track without it, and farther than from a robot that stops.
    let straight = pnp
        .candidates
        .primitives
        .iter()
        .position(|c| c == &vec![(1.0, 0.0), (1.0, 0.0)])
        .expect("the straight candidate");
    let stop = pnp
        .candidates
        .primitives
        .iter()
        .position(|c| c == &vec![(0.0, 0.0), (0.0, 0.0)])
        .expect("the stopping candidate");
    let path_of = |c: usize| pnp.candidates.path(c, n).to_vec();
    let mut reacting = Predicted::default();
    let mut sideways = |c: usize| {
        let path = path_of(c);
        pnp.reaction.respond(0, &path, &base, &mut reacting);
        assert_eq!(reacting.track.positions.len(), n + 1);
        assert_eq!(reacting.track.sigma, base.track.sigma);
        let gap = closest(&reacting.track.positions, &path);
        assert!(gap > closest(&base.track.positions, &path), "candidate {c}");
        reacting.track.positions[n].y
    };
    let (y_straight, y_stop) = (sideways(straight), sideways(stop));
    assert!(y_straight > 0.05 && y_stop > 0.05, "{y_straight} {y_stop}");
    assert_ne!(y_straight, y_stop);
    // A robot among the neighbours does not react.
    let robot = Neighbour::new(2, vec2(4.0, -1.0), vec2(-1.0, 0.0), 0.3, AgentKind::Robot);
    pnp.plan(
        &e,
        &[walker[0].clone(), robot],
        &StaticMap::empty(),
        vec2(50.0, 0.0),
        None,
    );
    assert!(pnp.reaction.reacts(0) && !pnp.reaction.reacts(1));
}

#[test]
fn the_papers_variant_scores_any_contact_alike() {
    let p = PnpParams::paper(true);
    assert_eq!(
        (p.severity, p.clearance, p.progress_weight, p.arrival),
        (Severity::Indicator, 0.0, 0.0, false)
    );
    let other: Vec<Vec2> = (0..=12).map(|_| vec2(2.0, 0.0)).collect();
    let path =
        |v: Real| -> Vec<Vec2> { (0..=12).map(|k| vec2(v * 0.25 * k as Real, 0.0)).collect() };
    let scoring = Scoring {
        reference: 4.6 * 0.25,
        severity: Severity::Indicator,
    };
    let fast = first_contact(&path(3.0), 0.6, |k| other[k]);
    let slow = first_contact(&path(1.0), 0.6, |k| other[k]);
    assert_eq!(loss(fast, 12, scoring), 1.0);
    assert_eq!(loss(slow, 12, scoring), 1.0);
    assert_eq!(loss(None, 12, scoring), 0.0);
}

#[test]
fn the_layer_is_asked_about_the_speeds_the_robot_would_drive() {
    // A judge that lets through 1 m/s at most, refuses above 2 m/s: a 3 m/s robot with
    // nothing around it drives the fastest speed let through, 1 m/s.
    let judge = |c: Command| match c {
        Command::Unicycle { speed, .. } if speed <= 1.0 + 1e-9 => Admission::Passes,
        Command::Unicycle { speed, .. } if speed <= 2.0 + 1e-9 => Admission::Admitted,
        _ => Admission::Refused,
    };
    let e = ego(vec2(0.0, 0.0), 0.0, 1.0);
    let plan = |judge: &dyn Fn(Command) -> Admission| {
        fast(true).plan_within(
            &e,
            &[],
            &StaticMap::empty(),
            vec2(50.0, 0.0),
            None,
            Some(judge),
        )
    };
    let d = plan(&judge);
    assert_eq!(
        d.command,
        Command::Unicycle {
            speed: 1.0,
            yaw_rate: 0.0
        }
    );
    // Nothing passes untouched: the fastest admitted, 2 m/s.
    let admitted_only = |c: Command| match judge(c) {
        Admission::Passes => Admission::Admitted,
        a => a,
    };
    let d = plan(&admitted_only);
    assert!(
        matches!(d.command, Command::Unicycle { speed, .. } if speed == 2.0),
        "{d:?}"
    );
    // Nothing admitted: the layer acts on the best of all of them.
    let d = plan(&|_| Admission::Refused);
    assert!(
        matches!(d.command, Command::Unicycle { speed, .. } if speed == 3.0),
        "{d:?}"
    );
}

/// A 3 m/s robot's plan toward a goal 50 m ahead in the open, under a judge that lets
/// through `most` m/s at most: its speed and where its path ends (t).
fn plan_under_a_speed_bound(params: PnpParams, most: Real) -> (Real, Real) {
    let judge = |c: Command| match c {
        Command::Unicycle { speed, .. } if speed <= most + 1e-9 => Admission::Passes,
        _ => Admission::Refused,
    };
    let d = hallway_robot(params).plan_within(
        &ego(vec2(0.0, 0.0), 0.0, 1.0),
        &[],
        &StaticMap::empty(),
        vec2(50.0, 0.0),
        None,
        Some(&judge),
    );
    let Command::Unicycle { speed, .. } = d.command else {
        panic!("a unicycle command, not {:?}", d.command);
    };
    (speed, d.trajectory.last().expect("a path").t)
}

#[test]
fn the_fine_variant_takes_the_speed_the_layer_leaves_between_the_coarse_ones() {
    // 7 × 5 first segments, each followed by the 4 × 5 second ones.
    assert_eq!(Pnp::new(PnpParams::fine(true)).candidates(), 700);
    // Under 1.5 m/s at most, the coarse speeds of a 3 m/s robot (0, 1, 2, 3 m/s) leave it
    // 1 m/s; sixths (0, 0.5, …, 3 m/s) the 1.5 m/s let through.
    let (fine, _) = plan_under_a_speed_bound(PnpParams::fine(true), 1.5);
    assert!((fine - 1.5).abs() < 1e-9);
    let (coarse, _) = plan_under_a_speed_bound(PnpParams::peeking(true), 1.5);
    assert!((coarse - 1.0).abs() < 1e-9);
}

#[test]
fn the_agile_variant_looks_1_5_s_ahead_and_takes_speeds_in_twelfths() {
    // 13 × 5 first segments, each followed by the 4 × 5 second ones.
    assert_eq!(Pnp::new(PnpParams::agile(true)).candidates(), 1300);
    // Under 1.25 m/s at most, sixths leave a 3 m/s robot 1 m/s; twelfths (0, 0.25, …,
    // 3 m/s) the 1.25 m/s let through.
    let (agile, end) = plan_under_a_speed_bound(PnpParams::agile(true), 1.25);
    assert!((agile - 1.25).abs() < 1e-9);
    assert!((end - 1.5).abs() < 1e-9, "the path ends at t_f = {end}");
    let (fine, end) = plan_under_a_speed_bound(PnpParams::fine(true), 1.25);
    assert!((fine - 1.0).abs() < 1e-9);
    assert!((end - 3.0).abs() < 1e-9, "the path ends at t_f = {end}");
}

#[test]
fn the_omni_variant_steps_aside_where_the_agile_one_stops() {
    // A person walks head-on at a standing robot, 2.5 m away, on its line.
    let e = ego(vec2(0.0, 0.0), 0.0, 0.0);
    let walker = [person(1, vec2(2.5, 0.0), vec2(-1.2, 0.0))];
    let goal = vec2(50.0, 0.0);
    let agile = hallway_robot(PnpParams::agile(true)).plan(&e, &walker, &hallway(), goal, None);
    let omni = hallway_robot(PnpParams::omni(true)).plan(&e, &walker, &hallway(), goal, None);
    eprintln!("agile {:?}\nomni {:?}", agile.command, omni.command);
    let Command::Velocity(v) = omni.command else {
        panic!("a holonomic command: {omni:?}");
    };
    assert!(v.y.abs() > 0.3, "it steps out of the person's line: {v:?}");
    assert!(
        matches!(agile.command, Command::Unicycle { .. }),
        "{agile:?}"
    );
}

#[test]
fn holonomic_paths_are_the_velocity_commands_executed_within_the_acceleration_limit() {
    // `pnp-omni`, and a three-segment set whose segments do not divide the grid evenly; the
    // closed form against stepping each substep.
    let three = PnpParams {
        segments: 3,
        first_speeds: Vec::new(),
        speeds: vec![0.0, 0.5, 1.0],
        directions: vec![0.0, 0.7, -2.0],
        horizon: 1.75,
        ..PnpParams::omni(true)
    };
    for (params, n, count) in [
        (PnpParams::omni(true), 6_usize, 121 * 31),
        (three, 7, 7 * 7 * 7),
    ] {
        let mut pnp = hallway_robot(params);
        let e = EgoState {
            velocity: vec2(1.5, -0.4),
            ..ego(vec2(1.0, -0.5), 0.3, 0.0)
        };
        let goal = vec2(20.0, 5.0);
        pnp.plan(&e, &[], &StaticMap::empty(), goal, None);
        let p = pnp.params().clone();
        let toward = (goal - e.position).normalize();
        let (substeps, h) = (5, 0.05);
        let per_segment = n.div_ceil(p.segments);
        assert_eq!(pnp.candidates(), count);
        for (c, primitive) in pnp.candidates.primitives.iter().enumerate() {
            let (mut position, mut v) = (e.position, e.velocity);
            let mut path = vec![position];
            for k in 0..n {
                let (fv, a) = primitive[(k / per_segment).min(p.segments - 1)];
                let target = candidates::rotate(toward, a) * (fv * p.v_max);
                for _ in 0..substeps {
                    v += clamp_norm(target - v, p.a_max * h);
                    position += v * h;
                }
                path.push(position);
            }
            let rolled = pnp.candidates.path(c, n);
            assert_eq!(rolled.len(), path.len());
            for (k, (a, b)) in rolled.iter().zip(&path).enumerate() {
                assert!(
                    (a - b).norm() < 1e-9,
                    "candidate {c}, point {k}: {a} against {b}"
                );
            }
        }
    }
}

#[test]
fn within_the_tolerance_of_a_goal_it_still_has_it_closes_in() {
    // A route's corner 0.38 m ahead, inside the 0.5 m arrival tolerance, that the fleet
    // counts as reached only nearer (seen in `warehouse-narrow`: the robot stood there for
    // good, every candidate counted as arrived at its start).
    for params in [
        PnpParams::default(),
        PnpParams::agile(true),
        PnpParams::omni(true),
    ] {
        let mut pnp = Pnp::new(params);
        let e = ego(vec2(31.54, 9.97), std::f64::consts::FRAC_PI_2, 0.0);
        let goal = vec2(31.5, 10.35);
        let d = pnp.plan(&e, &[], &StaticMap::empty(), goal, None);
        let v = match d.command {
            Command::Unicycle { speed, yaw_rate } => unit(e.heading + 0.1 * yaw_rate) * speed,
            Command::Velocity(v) => v,
        };
        assert!(v.dot(&(goal - e.position)) > 0.0, "{:?}", d.command);
    }
}

/// `pnp-omni-across` spreads a walking person's samples across their way by `across_spread`
/// and along it as before; a standing person and a robot keep the round spread, and so does
/// every body under `pnp-omni`.
#[test]
fn samples_spread_across_a_walking_persons_way_by_the_across_share() {
    let e = ego(vec2(0.0, 0.0), 0.0, 0.0);
    let walking = vec2(0.6, 0.8);
    let bodies = [
        person(1, vec2(4.0, 1.0), walking * 1.2),
        person(2, vec2(4.0, -1.0), vec2(0.1, 0.0)),
        Neighbour::new(3, vec2(6.0, 0.0), walking, 0.3, AgentKind::Robot),
    ];
    let plan = |params: PnpParams| {
        let mut pnp = Pnp::new(params);
        pnp.plan(&e, &bodies, &StaticMap::empty(), vec2(50.0, 0.0), None);
        pnp
    };
    let across = plan(PnpParams::omni_across(true));
    let round = plan(PnpParams::omni(true));
    let across_way = vec2(-walking.y, walking.x);
    for (j, &(o, _)) in across.offsets.iter().enumerate() {
        let shaped = across.predicted[0].offsets[j];
        assert!(
            (shaped.dot(&walking) - o.dot(&walking)).abs() < 1e-12,
            "sample {j}"
        );
        assert!(
            (shaped.dot(&across_way) - 0.5 * o.dot(&across_way)).abs() < 1e-12,
            "sample {j}"
        );
        assert_eq!(
            across.predicted[1].offsets[j], o,
            "a standing person, sample {j}"
        );
        assert_eq!(across.predicted[2].offsets[j], o, "a robot, sample {j}");
        for body in &round.predicted {
            assert_eq!(body.offsets[j], o, "pnp-omni, sample {j}");
        }
    }
}

/// The velocity a holonomic variant commands with nobody about.
fn decide(params: PnpParams, e: &EgoState, map: &StaticMap, goal: Vec2) -> Vec2 {
    let d = Pnp::new(params).plan(e, &[], map, goal, None);
    match d.command {
        Command::Velocity(v) => v,
        Command::Unicycle { .. } => panic!("a holonomic variant: {:?}", d.command),
    }
}

/// `pnp-side` keeps to the nearer wall of a hallway with nobody about, where
/// `pnp-omni-across` heads for a goal on the hallway's axis; in open ground, where no wall is
/// within reach, the two decide alike; near its goal the side term has faded and it closes
/// in.
#[test]
fn pnp_side_keeps_to_the_nearer_wall_and_still_reaches_a_goal_in_the_middle() {
    // 0.4 m below the axis of a 3 m hallway, the goal 40 m on along the axis.
    let e = ego(vec2(0.0, -0.4), 0.0, 1.0);
    let goal = vec2(40.0, 0.0);
    let side = decide(PnpParams::side(true), &e, &hallway(), goal);
    let across = decide(PnpParams::omni_across(true), &e, &hallway(), goal);
    assert!(side.x > 0.0 && side.y < 0.0, "pnp-side: {side:?}");
    assert!(across.y >= 0.0, "pnp-omni-across: {across:?}");
    let open = StaticMap::empty();
    assert_eq!(
        decide(PnpParams::side(true), &e, &open, goal),
        decide(PnpParams::omni_across(true), &e, &open, goal)
    );
    // 0.8 m from a goal on the axis, 0.6 m off it: it drives at the goal, not at the wall.
    let near = ego(vec2(39.5, -0.6), 0.0, 0.5);
    let v = decide(PnpParams::side(true), &near, &hallway(), goal);
    assert!(v.dot(&(goal - near.position)) > 0.0 && v.y > 0.0, "{v:?}");
}

/// `pnp-right` keeps to the wall on its right whichever wall is nearer: 0.4 m above the
/// axis of a 3 m hallway, heading east it moves down toward the south wall where `pnp-side`
/// moves up to the nearer north one; heading west it keeps to the north wall. Two robots
/// meeting head-on so keep to opposite walls.
#[test]
fn pnp_right_keeps_to_the_wall_on_its_right() {
    let east = ego(vec2(0.0, 0.4), 0.0, 1.0);
    let right = decide(PnpParams::right(true), &east, &hallway(), vec2(40.0, 0.0));
    let side = decide(PnpParams::side(true), &east, &hallway(), vec2(40.0, 0.0));
    assert!(
        right.x > 0.0 && right.y < 0.0,
        "pnp-right heading east: {right:?}"
    );
    assert!(side.y > 0.0, "pnp-side heading east: {side:?}");
    let west = ego(vec2(0.0, 0.4), std::f64::consts::PI, 1.0);
    let right = decide(PnpParams::right(true), &west, &hallway(), vec2(-40.0, 0.0));
    assert!(
        right.x < 0.0 && right.y > 0.0,
        "pnp-right heading west: {right:?}"
    );
}

/// Beside shelves' end faces broken by aisle mouths (a cross-aisle), `pnp-side` leaves the
/// side term out and decides as `pnp-omni-across` does: keeping to such a "wall" would drive
/// it past blind corners. Beside a wall that runs on it keeps to the side.
#[test]
fn pnp_side_keeps_to_walls_that_run_on_not_to_shelf_ends() {
    // A 3 m cross-aisle along +x: shelf ends 1.2 m wide with 1.5 m mouths along y = −1.5,
    // the same along y = +1.5.
    let mut shelves = Vec::new();
    for k in 0..12 {
        let x = -6.0 + 2.7 * Real::from(k);
        for (near, far) in [(-1.5, -8.0), (1.5, 8.0)] {
            shelves.push(Obstacle::Polygon(vec![
                vec2(x, near),
                vec2(x + 1.2, near),
                vec2(x + 1.2, far),
                vec2(x, far),
            ]));
        }
    }
    let cross_aisle = StaticMap::new(shelves).expect("valid shelves");
    // 0.4 m below the axis, beside a shelf end, the goal 20 m on along the axis.
    let e = ego(vec2(-1.0, -0.4), 0.0, 1.0);
    let goal = vec2(20.0, 0.0);
    assert_eq!(
        decide(PnpParams::side(true), &e, &cross_aisle, goal),
        decide(PnpParams::omni_across(true), &e, &cross_aisle, goal)
    );
    // With the shelves' side joined into one wall, it keeps to that wall.
    let mut walled = cross_aisle.obstacles().to_vec();
    walled.push(Obstacle::Wall(vec2(-6.0, -1.5), vec2(30.0, -1.5)));
    let walled = StaticMap::new(walled).expect("valid map");
    let v = decide(PnpParams::side(true), &e, &walled, goal);
    assert!(v.x > 0.0 && v.y < 0.0, "pnp-side beside a wall: {v:?}");
}

/// `braking_path`: one grid step on the candidate, then braking straight on to a stop.
#[test]
fn the_braking_path_drives_one_grid_step_then_stops_within_the_acceleration_limit() {
    // 1 m/s along x on a 0.25 s grid.
    let path: Vec<Vec2> = (0..7).map(|k| vec2(0.25 * Real::from(k), 0.0)).collect();
    let mut out = Vec::new();
    super::hidden::braking_path(&path, 0.25, 1.5, &mut out);
    assert_eq!(out.len(), path.len());
    assert_eq!(&out[..2], &path[..2]);
    // From 1 m/s at 1.5 m/s²: stopped after 2/3 s, 1/3 m on.
    let stop = 0.25 + 1.0 / 3.0;
    for w in out.windows(2) {
        assert!(w[1].x >= w[0].x - 1e-12 && w[1].y == 0.0, "{out:?}");
    }
    assert!((out[6].x - stop).abs() < 1e-9, "{out:?}");
    assert!((out[4].x - stop).abs() < 1e-9, "stopped by 1 s: {out:?}");
    assert!(out[3].x < stop, "not yet at 0.75 s: {out:?}");
    assert!(out[2].x < stop && out[2].x > 0.25 + 0.25 * 0.5, "{out:?}");
    // Standing still it stays.
    let still = vec![vec2(1.0, 2.0); 7];
    super::hidden::braking_path(&still, 0.25, 1.5, &mut out);
    assert_eq!(out, still);
}

/// Siblings share one braking path's Ψ (`hidden_braking`): by a blind side passage, where Ψ
/// costs, a planner sharing it and cutting candidates short decides bit for bit as one
/// scoring every candidate in full.
#[test]
fn sharing_siblings_braking_risk_changes_no_decision_by_a_blind_passage() {
    // A 2 m corridor along y, closed at y = 1, with a 1 m passage leaving its west wall at
    // y = −1.5 to −0.5.
    let map = StaticMap::new(vec![
        Obstacle::Wall(vec2(-1.0, 1.0), vec2(1.0, 1.0)),
        Obstacle::Wall(vec2(1.0, 1.0), vec2(1.0, -10.0)),
        Obstacle::Wall(vec2(-1.0, 1.0), vec2(-1.0, -0.5)),
        Obstacle::Wall(vec2(-1.0, -1.5), vec2(-1.0, -10.0)),
        Obstacle::Wall(vec2(-1.0, -0.5), vec2(-8.0, -0.5)),
        Obstacle::Wall(vec2(-1.0, -1.5), vec2(-8.0, -1.5)),
    ])
    .expect("valid walls");
    let goal = vec2(0.0, -5.0);
    let mut peeked = 0;
    for x in [-0.6, -0.3, 0.0, 0.3] {
        for y in [0.4, 0.0] {
            let e = ego(vec2(x, y), std::f64::consts::FRAC_PI_2, 0.0);
            let mut full = Pnp::new(PnpParams::side_brake(true));
            full.exhaustive = true;
            let want = full.plan(&e, &[], &map, goal, None);
            let got = Pnp::new(PnpParams::side_brake(true)).plan(&e, &[], &map, goal, None);
            assert_eq!(got, want, "at ({x}, {y})");
            peeked += usize::from(want.cost.peek > 0.0);
        }
    }
    assert!(peeked > 0, "Ψ costs somewhere by the passage");
}
