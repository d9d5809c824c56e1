use super::*;
use crate::map::Obstacle;
use crate::model::AgentKind;

/// The simulator's default robot: 1 m/s, 1.5 m/s², commanded at 10 Hz.
fn limits() -> SafetyLimits {
    SafetyLimits::SIMULATED_ROBOT
}

fn ego(position: Vec2, velocity: Vec2) -> EgoState {
    EgoState {
        position,
        heading: velocity.y.atan2(velocity.x),
        velocity,
        yaw_rate: 0.0,
        radius: 0.3,
    }
}

fn person(id: u64, position: Vec2, velocity: Vec2) -> Neighbour {
    Neighbour::new(id, position, velocity, 0.35, AgentKind::Human)
}

/// A contact's onset: who was moving toward whom.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Onset {
    /// The robot moved toward the body.
    RobotCaused,
    /// The body came to a robot standing or moving away.
    BodyCaused,
}

/// A closed loop at the simulator's 0.1 s step: a planner that always wants `want` (a world
/// velocity), the layer under it, bodies walking at constant velocity except where `script`
/// changes them, and every contact onset classified.
struct Loop {
    /// Without the layer, the planner's command goes straight to the base.
    guarded: bool,
    layer: SafetyLayer,
    robot: Motion,
    bodies: Vec<Neighbour>,
    map: StaticMap,
    touching: Vec<bool>,
    onsets: Vec<Onset>,
    zones: Vec<Zone>,
    wall_onsets: usize,
}

impl Loop {
    fn new(start: Vec2, velocity: Vec2, bodies: Vec<Neighbour>, map: StaticMap) -> Self {
        let n = bodies.len();
        Self {
            guarded: true,
            layer: SafetyLayer::new(SafetyParams::default()),
            robot: Motion {
                position: start,
                velocity,
                heading: velocity.y.atan2(velocity.x),
                yaw_rate: 0.0,
            },
            bodies,
            map,
            touching: vec![false; n],
            onsets: Vec::new(),
            zones: Vec::new(),
            wall_onsets: 0,
        }
    }

    fn ego(&self) -> EgoState {
        EgoState {
            position: self.robot.position,
            heading: self.robot.heading,
            velocity: self.robot.velocity,
            yaw_rate: self.robot.yaw_rate,
            radius: 0.3,
        }
    }

    /// One step; `visible` picks the bodies the robot perceives.
    fn step(&mut self, want: Vec2, visible: impl Fn(&Neighbour) -> bool) {
        let seen: Vec<Neighbour> = self.bodies.iter().filter(|b| visible(b)).cloned().collect();
        let guarded = if self.guarded {
            self.layer.guard(
                Command::Velocity(want),
                &self.ego(),
                &limits(),
                &seen,
                &self.map,
            )
        } else {
            Guarded {
                command: Command::Velocity(want),
                zone: Zone::Clear,
                scale: 1.0,
            }
        };
        self.zones.push(guarded.zone);
        let before_wall = self.map.distance(&self.robot.position) - 0.3;
        step_toward(&mut self.robot, guarded.command, &limits(), 0.1);
        for b in &mut self.bodies {
            b.position += b.velocity * 0.1;
        }
        for (i, b) in self.bodies.iter().enumerate() {
            let d = b.position - self.robot.position;
            let touching = d.norm() < 0.3 + b.radius;
            if touching && !self.touching[i] {
                let toward = d.dot(&self.robot.velocity) > 0.0;
                self.onsets.push(if toward {
                    Onset::RobotCaused
                } else {
                    Onset::BodyCaused
                });
            }
            self.touching[i] = touching;
        }
        let wall = self.map.distance(&self.robot.position) - 0.3;
        if wall < 0.0 && before_wall >= 0.0 {
            self.wall_onsets += 1;
        }
    }
}

#[test]
fn a_clear_command_passes_through_bit_identical() {
    let mut layer = SafetyLayer::new(SafetyParams::default());
    let command = Command::Velocity(vec2(0.713_279_841_205_139_2, 0.3));
    let far = [person(1, vec2(30.0, 0.0), vec2(-1.0, 0.0))];
    let g = layer.guard(
        command,
        &ego(vec2(0.0, 0.0), vec2(0.5, 0.2)),
        &limits(),
        &far,
        &StaticMap::empty(),
    );
    assert_eq!(g.zone, Zone::Clear);
    assert_eq!(g.scale, 1.0);
    match (g.command, command) {
        (Command::Velocity(a), Command::Velocity(b)) => {
            assert_eq!(
                (a.x.to_bits(), a.y.to_bits()),
                (b.x.to_bits(), b.y.to_bits())
            );
        }
        _ => panic!("kind changed"),
    }
}

#[test]
fn the_warning_field_slows_before_the_protective_field_stops() {
    let mut layer = SafetyLayer::new(SafetyParams::default());
    let at = ego(vec2(0.0, 0.0), vec2(1.0, 0.0));
    let full = Command::Velocity(vec2(1.0, 0.0));
    // A person standing 2 m ahead: the robot could still stop (0.53 m), but not had it kept
    // going a second longer; at half speed it stays clear even of where the person could
    // get to at a_h.
    let ahead = |x| [person(1, vec2(x, 0.0), vec2(0.0, 0.0))];
    let warned = layer.guard(full, &at, &limits(), &ahead(2.0), &StaticMap::empty());
    assert_eq!((warned.zone, warned.scale), (Zone::Warning, 0.5));
    // 0.9 m ahead (0.25 m between bodies): only a stop keeps it clear.
    let stopped = layer.guard(full, &at, &limits(), &ahead(0.9), &StaticMap::empty());
    assert_eq!((stopped.zone, stopped.scale), (Zone::Protective, 0.0));
    assert_eq!(stopped.command, Command::Velocity(vec2(0.0, 0.0)));
}

#[test]
fn the_graded_warning_field_slows_only_as_far_as_it_must() {
    let mut layer = SafetyLayer::new(SafetyParams {
        warning_graded: true,
        ..SafetyParams::default()
    });
    let at = ego(vec2(0.0, 0.0), vec2(1.0, 0.0));
    let full = Command::Velocity(vec2(1.0, 0.0));
    // The person standing 2 m ahead (1.4 m between bodies): kept 1.1 s and then braked, full
    // speed covers 1.43 m, more than the 1.35 m to the margin; 80 % covers about 1.1 m.
    let ahead = |x| [person(1, vec2(x, 0.0), vec2(0.0, 0.0))];
    let warned = layer.guard(full, &at, &limits(), &ahead(2.0), &StaticMap::empty());
    assert_eq!((warned.zone, warned.scale), (Zone::Warning, 0.8));
    assert_eq!(warned.command, Command::Velocity(vec2(0.8, 0.0)));
    // Nearer, no fraction above `warning_scale` passes the warning check: as without grading.
    let near = layer.guard(full, &at, &limits(), &ahead(1.6), &StaticMap::empty());
    let fixed = SafetyLayer::new(SafetyParams::default()).guard(
        full,
        &at,
        &limits(),
        &ahead(1.6),
        &StaticMap::empty(),
    );
    assert_eq!(near, fixed);
    assert!(near.scale <= 0.5, "{near:?}");
}

#[test]
fn a_robot_may_back_away_from_a_person_closing_in() {
    let mut layer = SafetyLayer::new(SafetyParams::default());
    let closing = [person(1, vec2(0.8, 0.0), vec2(-1.3, 0.0))];
    let back = Command::Velocity(vec2(-1.0, 0.0));
    let map = StaticMap::empty();
    let set = layer.prepare(
        &ego(vec2(0.0, 0.0), vec2(0.0, 0.0)),
        &limits(),
        &closing,
        &map,
    );
    // The predicate never blocks moving away.
    assert!(set.admits(back));
    // Threatened, the layer keeps backing off (or steps aside as it backs off).
    assert!(set.threatened());
    let g = set.guard(back);
    let Command::Velocity(v) = g.command else {
        panic!("kind changed: {g:?}");
    };
    assert!(v.x < 0.0, "{g:?}");
    assert!(set.admits(g.command));
}

/// A person walks head-on at 2 m/s toward a robot driving at full speed toward them.
fn head_on(guarded: bool, yielding: bool) -> Loop {
    let walker = person(1, vec2(8.0, 0.0), vec2(-2.0, 0.0));
    let mut sim = Loop::new(
        vec2(0.0, 0.0),
        vec2(1.0, 0.0),
        vec![walker],
        StaticMap::empty(),
    );
    sim.guarded = guarded;
    sim.layer = SafetyLayer::new(SafetyParams {
        yielding,
        ..SafetyParams::default()
    });
    for _ in 0..60 {
        sim.step(vec2(1.0, 0.0), |_| true);
    }
    sim
}

#[test]
fn head_on_person_at_two_metres_per_second_is_never_hit() {
    assert!(head_on(false, true).onsets.contains(&Onset::RobotCaused));
    // Stopping alone: the person walks into the stopped robot, and the contact is theirs.
    let stopping = head_on(true, false);
    assert_eq!(stopping.onsets, [Onset::BodyCaused]);
    assert!(stopping.zones.contains(&Zone::Protective));
    // Yielding: the robot stops and steps aside; nobody touches.
    let sim = head_on(true, true);
    assert!(sim.onsets.is_empty(), "{:?}", sim.onsets);
    assert!(sim.zones.contains(&Zone::Yield));
}

/// A person steps out from behind a shelf corner 1 m ahead of the robot (between the bodies),
/// across its path, and is seen only once out.
fn blind_corner(guarded: bool) -> Loop {
    // The robot drives along the shelf's face at y = 0.5 (0.2 m clear of it); the person
    // waits out of sight and steps into the aisle when the robot is 1 m (surface to surface)
    // short of them.
    let shelf = Obstacle::Polygon(vec![
        vec2(2.0, 0.5),
        vec2(3.0, 0.5),
        vec2(3.0, 2.0),
        vec2(2.0, 2.0),
    ]);
    let map = StaticMap::new(vec![shelf]).expect("a valid shelf");
    let hidden = person(1, vec2(3.6, 1.2), vec2(0.0, 0.0));
    let mut sim = Loop::new(vec2(0.0, 0.0), vec2(1.0, 0.0), vec![hidden], map);
    sim.guarded = guarded;
    let mut stepped_out = false;
    for _ in 0..80 {
        let x = sim.robot.position.x;
        if !stepped_out && 3.6 - x - 0.65 <= 1.0 {
            stepped_out = true;
            sim.bodies[0].position = vec2(3.6, 0.8);
            sim.bodies[0].velocity = vec2(0.0, -0.8);
        }
        if sim.bodies[0].position.y < -1.0 {
            sim.bodies[0].velocity = vec2(0.0, 0.0);
        }
        // Seen once it is out (its centre below the shelf's back).
        sim.step(vec2(1.0, 0.0), |b| b.position.y < 0.9);
    }
    assert!(stepped_out);
    sim
}

#[test]
fn person_stepping_out_from_a_blind_corner_is_never_hit() {
    assert!(blind_corner(false).onsets.contains(&Onset::RobotCaused));
    let sim = blind_corner(true);
    assert!(
        !sim.onsets.contains(&Onset::RobotCaused),
        "{:?}",
        sim.onsets
    );
    assert_eq!(sim.wall_onsets, 0);
}

/// A robot drives 0.6 m behind another robot at 1 m/s; after 2 s the one ahead stops dead.
fn stops_dead(guarded: bool) -> Loop {
    let lead = Neighbour::new(2, vec2(1.2, 0.0), vec2(1.0, 0.0), 0.3, AgentKind::Robot);
    let mut sim = Loop::new(
        vec2(0.0, 0.0),
        vec2(1.0, 0.0),
        vec![lead],
        StaticMap::empty(),
    );
    sim.guarded = guarded;
    for k in 0..60 {
        if k == 20 {
            sim.bodies[0].velocity = vec2(0.0, 0.0);
        }
        sim.step(vec2(1.0, 0.0), |_| true);
    }
    sim
}

#[test]
fn robot_behind_a_robot_that_stops_dead_never_hits_it() {
    assert!(stops_dead(false).onsets.contains(&Onset::RobotCaused));
    let sim = stops_dead(true);
    assert!(sim.onsets.is_empty(), "{:?}", sim.onsets);
    let gap = (sim.bodies[0].position - sim.robot.position).norm() - 0.6;
    assert!((0.0..0.6).contains(&gap), "stopped {gap} m behind");
}

/// A planner that always commands full speed straight at a wall.
fn at_a_wall(guarded: bool) -> Loop {
    let map = StaticMap::new(vec![Obstacle::Wall(vec2(3.0, -5.0), vec2(3.0, 5.0))])
        .expect("a valid wall");
    let mut sim = Loop::new(vec2(0.0, 0.0), vec2(0.0, 0.0), vec![], map);
    sim.guarded = guarded;
    for _ in 0..80 {
        sim.step(vec2(1.0, 0.0), |_| true);
    }
    sim
}

#[test]
fn full_speed_at_a_wall_stops_short_of_it() {
    assert_eq!(at_a_wall(false).wall_onsets, 1);
    let sim = at_a_wall(true);
    assert_eq!(sim.wall_onsets, 0);
    let gap = 3.0 - sim.robot.position.x - 0.3;
    assert!((0.0..0.3).contains(&gap), "stopped {gap} m short");
    assert!(sim.robot.velocity.norm() < 1e-9);
}

#[test]
fn a_way_out_keeps_within_the_bases_limits_when_the_command_does_not() {
    // A planner asking for 1.63 m/s of a 1 m/s base while a person crosses ahead: the
    // command's fractions above 1 m/s are no ways out (proptest found the yield taking 0.8 of
    // it, 1.3 m/s, with the open ground's parameters).
    let mut layer = SafetyLayer::new(params(true));
    let command = Command::Velocity(vec2(-0.8075, -1.4186));
    let bodies = [person(1, vec2(-1.6853, 2.3629), vec2(1.1603, -0.9434))];
    let g = layer.guard(
        command,
        &ego(vec2(0.0, 0.0), vec2(0.8917, 0.7236)),
        &limits(),
        &bodies,
        &StaticMap::empty(),
    );
    assert_eq!(g.zone, Zone::Yield, "{g:?}");
    let Command::Velocity(out) = g.command else {
        panic!("kind changed: {g:?}");
    };
    assert!(out.norm() <= limits().max_speed + 1e-12, "{g:?}");
}

/// The layer's defaults, or the open ground's longer, roomier yield (the built-in
/// `open-space` scenario's `[robot.safety_layer]`).
fn params(open_ground: bool) -> SafetyParams {
    if open_ground {
        SafetyParams {
            yield_time: 3.0,
            yield_clearance: 0.6,
            ..SafetyParams::default()
        }
    } else {
        SafetyParams::default()
    }
}

/// People at (x, y) walking at (vx, vy), one per tuple.
fn crowd(others: &[(Real, Real, Real, Real)]) -> Vec<Neighbour> {
    others
        .iter()
        .enumerate()
        .map(|(i, o)| person(i as u64, vec2(o.0, o.1), vec2(o.2, o.3)))
        .collect()
}

proptest::proptest! {
    /// Outside a yield the layer only ever keeps a fraction s ∈ [0, 1] of the planner's
    /// command: it never adds speed or turns the robot another way.
    #[test]
    fn never_adds_speed_outside_a_yield(
        v in (-1.5..1.5f64, -1.5..1.5f64),
        own in (-1.0..1.0f64, -1.0..1.0f64),
        open_ground in proptest::bool::ANY,
        others in proptest::collection::vec(
            (-4.0..4.0f64, -4.0..4.0f64, -1.5..1.5f64, -1.5..1.5f64), 0..12),
    ) {
        let mut layer = SafetyLayer::new(params(open_ground));
        let bodies = crowd(&others);
        let command = Command::Velocity(vec2(v.0, v.1));
        let g = layer.guard(command, &ego(vec2(0.0, 0.0), vec2(own.0, own.1)), &limits(),
            &bodies, &StaticMap::empty());
        proptest::prop_assert!((0.0..=1.0).contains(&g.scale));
        let Command::Velocity(out) = g.command else {
            return Err(proptest::test_runner::TestCaseError::fail("kind changed"));
        };
        if g.zone != Zone::Yield {
            proptest::prop_assert_eq!(out, vec2(v.0, v.1) * g.scale);
            proptest::prop_assert_eq!(g.zone == Zone::Clear, g.scale == 1.0);
        } else {
            // A way out is within the base's limits.
            proptest::prop_assert!(out.norm() <= limits().max_speed + 1e-12);
        }
    }

    /// The graded warning field keeps at least the fixed one's fraction outside a yield, and
    /// passive safety holds under it: every command out is admissible, or a stop.
    #[test]
    fn the_graded_warning_field_keeps_more_and_stays_admissible(
        v in (-1.5..1.5f64, -1.5..1.5f64),
        own in (-1.0..1.0f64, -1.0..1.0f64),
        open_ground in proptest::bool::ANY,
        others in proptest::collection::vec(
            (-4.0..4.0f64, -4.0..4.0f64, -1.5..1.5f64, -1.5..1.5f64), 0..12),
    ) {
        let fixed_params = params(open_ground);
        let mut fixed = SafetyLayer::new(fixed_params);
        let mut graded = SafetyLayer::new(SafetyParams { warning_graded: true, ..fixed_params });
        let bodies = crowd(&others);
        let command = Command::Velocity(vec2(v.0, v.1));
        let at = ego(vec2(0.0, 0.0), vec2(own.0, own.1));
        let open = StaticMap::empty();
        let f = fixed.guard(command, &at, &limits(), &bodies, &open);
        let set = graded.prepare(&at, &limits(), &bodies, &open);
        let g = set.guard(command);
        proptest::prop_assert!(g.scale == 0.0 || set.admits(g.command), "{:?}", g);
        if f.zone != Zone::Yield {
            proptest::prop_assert_eq!(g.zone == Zone::Yield, false);
            proptest::prop_assert!(g.scale >= f.scale, "{:?} against {:?}", g, f);
        }
    }

    /// Passive safety: every command out of the layer is admissible (the robot can still
    /// brake before it moves into anything it perceives, people swerving at up to a_h), or a
    /// stop when nothing is. For holonomic and unicycle bases, among walls.
    #[test]
    fn every_command_out_is_admissible_or_a_stop(
        v in (-1.5..1.5f64, -1.5..1.5f64),
        own in (-1.0..1.0f64, -1.0..1.0f64),
        unicycle in proptest::bool::ANY,
        walled in proptest::bool::ANY,
        open_ground in proptest::bool::ANY,
        others in proptest::collection::vec(
            (-4.0..4.0f64, -4.0..4.0f64, -1.5..1.5f64, -1.5..1.5f64), 0..12),
    ) {
        let mut layer = SafetyLayer::new(params(open_ground));
        let bodies = crowd(&others);
        let command = if unicycle {
            Command::Unicycle { speed: v.0, yaw_rate: v.1 }
        } else {
            Command::Velocity(vec2(v.0, v.1))
        };
        let map = if walled {
            StaticMap::new(vec![
                Obstacle::Wall(vec2(-10.0, -0.9), vec2(10.0, -0.9)),
                Obstacle::Wall(vec2(-10.0, 0.9), vec2(10.0, 0.9)),
            ]).expect("valid walls")
        } else {
            StaticMap::empty()
        };
        let at = ego(vec2(0.0, 0.0), vec2(own.0, own.1));
        let set = layer.prepare(&at, &limits(), &bodies, &map);
        let g = set.guard(command);
        let stop = g.zone == Zone::Protective && g.scale == 0.0;
        proptest::prop_assert!(stop || set.admits(g.command), "{:?}", g);
        // A way out never moves toward anyone within the margin: the predicate's promise.
        if g.zone == Zone::Yield {
            proptest::prop_assert!(set.admits(g.command));
        }
    }
}

proptest::proptest! {
    /// The across-the-way bound (`person_accel_across`) never calls a point outside that is
    /// within `within` of the ellipse a walking person may stray in: points on the ellipse
    /// pushed out by less than `within`, in any direction, are all inside.
    #[test]
    fn the_stray_ellipse_test_misses_no_point_within_reach(
        heading in -3.2..3.2f64,
        across in 0.0..3.0f64,
        t in 0.05..2.0f64,
        on in -3.2..3.2f64,
        out in -3.2..3.2f64,
        fraction in 0.0..0.999f64,
    ) {
        let (a, within) = (3.0, 0.7);
        let along = vec2(heading.cos(), heading.sin());
        let body = Body {
            position: vec2(0.0, 0.0),
            velocity: along,
            within,
            accel: a,
            along,
            accel_across: across,
            halting: Real::INFINITY,
            speed: 1.0,
            relevant: [[true; 2]; 2],
        };
        let half_tt = 0.5 * t * t;
        let side = vec2(-along.y, along.x);
        let on_ellipse = along * (a * half_tt * on.cos()) + side * (across * half_tt * on.sin());
        let point = on_ellipse + vec2(out.cos(), out.sin()) * (within * fraction);
        // `d` runs from the robot to the body: the robot stands at `point`.
        proptest::prop_assert!(body.within_ellipse(-point, half_tt));
    }

    /// Passive safety holds with the candidate bound too: every command out of the layer is
    /// admissible under it, or a stop.
    /// Without `people_stop_dead`, a person's halting hypothesis (braking along their way at
    /// a_h) is always within the swerve's reach ½·a_h·t² of walking on, which is why the
    /// protective check may skip it.
    #[test]
    fn halting_at_a_h_is_within_the_swerves_reach_of_walking_on(
        heading in -3.2..3.2f64,
        speed in 0.0..3.0f64,
        t in 0.0..3.0f64,
    ) {
        let a = 3.0;
        let velocity = vec2(heading.cos(), heading.sin()) * speed;
        let body = Body {
            position: vec2(1.0, -2.0),
            velocity,
            within: 0.7,
            accel: a,
            along: vec2(0.0, 0.0),
            accel_across: a,
            halting: a,
            speed,
            relevant: [[true; 2]; 2],
        };
        let (at, moving) = body.halt(t);
        let walking_on = body.position + velocity * t;
        proptest::prop_assert!((at - walking_on).norm() <= 0.5 * a * t * t + 1e-9);
        proptest::prop_assert!(moving.norm() <= speed + 1e-12);
        proptest::prop_assert!(moving.dot(&velocity) >= 0.0);
    }

    /// Also with a smaller a_h away from a place where people turn
    /// (`person_accel_away`), the place anywhere near the robot.
    #[test]
    fn every_command_out_is_admissible_with_the_across_bound(
        v in (-1.5..1.5f64, -1.5..1.5f64),
        own in (-1.0..1.0f64, -1.0..1.0f64),
        across in 0.0..3.0f64,
        away in 0.0..3.0f64,
        place in (-4.0..4.0f64, -4.0..4.0f64),
        others in proptest::collection::vec(
            (-4.0..4.0f64, -4.0..4.0f64, -1.5..1.5f64, -1.5..1.5f64), 0..12),
    ) {
        let mut layer = SafetyLayer::new(SafetyParams {
            person_accel_across: across,
            person_accel_away: away,
            turn_reach: 1.0,
            ..SafetyParams::default()
        });
        let p = vec2(place.0, place.1);
        layer.set_turn_places(Some(vec![(p, p)]));
        let bodies = crowd(&others);
        let at = ego(vec2(0.0, 0.0), vec2(own.0, own.1));
        let map = StaticMap::empty();
        let set = layer.prepare(&at, &limits(), &bodies, &map);
        let g = set.guard(Command::Velocity(vec2(v.0, v.1)));
        let stop = g.zone == Zone::Protective && g.scale == 0.0;
        proptest::prop_assert!(stop || set.admits(g.command), "{:?}", g);
    }
}

/// A robot driving at full speed and a person 1.3 m to its left walking the other way, on
/// open ground; and the robot's command to drive on.
fn walking_past() -> (EgoState, Vec<Neighbour>, StaticMap, Command) {
    let person = Neighbour::new(1, vec2(1.0, 1.3), vec2(-1.0, 0.0), 0.3, AgentKind::Human);
    (
        ego(vec2(0.0, 0.0), vec2(1.0, 0.0)),
        vec![person],
        StaticMap::empty(),
        Command::Velocity(vec2(1.0, 0.0)),
    )
}

/// Beside a person walking past, a person farther than `turn_reach` from every place where
/// robots and people turn may swerve only at `person_accel_away`, and the robot drives on
/// where the full a_h stops it; within reach of a place, or with no places known, the full
/// a_h holds.
#[test]
fn away_from_where_people_turn_a_person_swerves_less() {
    let (robot, beside, map, drive_on) = walking_past();
    let admits = |places: Option<Vec<(Vec2, Vec2)>>| {
        let mut layer = SafetyLayer::new(SafetyParams {
            person_accel_away: 1.0,
            people_stop_dead: true,
            ..SafetyParams::default()
        });
        layer.set_turn_places(places);
        layer
            .prepare(&robot, &limits(), &beside, &map)
            .admits(drive_on)
    };
    let far = vec2(20.0, 20.0);
    assert!(
        admits(Some(vec![(far, far)])),
        "away from the place: 1 m/s²"
    );
    assert!(!admits(None), "no places known: 3 m/s² everywhere");
    // A station 3 m along from the person (its box a point): within reach.
    let near = vec2(4.0, 1.3);
    assert!(!admits(Some(vec![(near, near)])), "within reach: 3 m/s²");
    // A line 3.5 m off: out of reach.
    assert!(admits(Some(vec![(vec2(4.5, -5.0), vec2(4.5, 5.0))])));
}

proptest::proptest! {
    /// With no places where robots and people turn known, `person_accel_away` changes
    /// nothing: every command comes out bit for bit as with the layer's defaults.
    #[test]
    fn without_turn_places_the_away_allowance_changes_nothing(
        v in (-1.5..1.5f64, -1.5..1.5f64),
        own in (-1.0..1.0f64, -1.0..1.0f64),
        away in 0.0..3.0f64,
        others in proptest::collection::vec(
            (-4.0..4.0f64, -4.0..4.0f64, -1.5..1.5f64, -1.5..1.5f64), 0..12),
    ) {
        let bodies = crowd(&others);
        let at = ego(vec2(0.0, 0.0), vec2(own.0, own.1));
        let map = StaticMap::empty();
        let command = Command::Velocity(vec2(v.0, v.1));
        let mut shipped = SafetyLayer::new(SafetyParams::default());
        let mut away_set = SafetyLayer::new(SafetyParams {
            person_accel_away: away,
            ..SafetyParams::default()
        });
        away_set.set_turn_places(None);
        let a = shipped.prepare(&at, &limits(), &bodies, &map).guard(command);
        let b = away_set.prepare(&at, &limits(), &bodies, &map).guard(command);
        proptest::prop_assert_eq!(a, b);
    }
}

/// Beside a person walking past, the across bound lets the robot drive on where the round one
/// stops it; ahead of the person both stop it. (With the person allowed to stop dead where
/// they are, as before `people_stop_dead` turned off: walking on, they pass the robot before
/// any swerve reaches it.)
#[test]
fn a_person_walking_past_strays_less_across_than_along() {
    let (robot, beside, map, drive_on) = walking_past();
    let admits = |across: Real, bodies: &[Neighbour]| {
        let mut layer = SafetyLayer::new(SafetyParams {
            person_accel_across: across,
            people_stop_dead: true,
            ..SafetyParams::default()
        });
        layer
            .prepare(&robot, &limits(), bodies, &map)
            .admits(drive_on)
    };
    assert!(
        !admits(3.0, &beside),
        "round: a 3 m/s² swerve reaches the robot"
    );
    assert!(admits(1.0, &beside), "across at 1 m/s²: it does not");
    // The same person straight ahead, coming at the robot: along their way, a_h as before.
    let ahead = vec![Neighbour::new(
        1,
        vec2(2.2, 0.0),
        vec2(-1.0, 0.0),
        0.3,
        AgentKind::Human,
    )];
    assert!(!admits(3.0, &ahead) && !admits(1.0, &ahead));
    // A smaller a_h alone keeps the check round (a_⊥ above a_h counts as a_h).
    let p = SafetyParams::default()
        .with_overrides("person_accel=2")
        .expect("a_h may go below the default a_⊥");
    assert_eq!(p.person_accel_across, 3.0);
    assert!(
        SafetyParams::default()
            .with_overrides("person_accel_across=nan")
            .is_err()
    );
}

/// A person overtakes the robot close beside it (`gap` between bodies) and, `ahead` of it,
/// turns across its path at `accel` (at walking speed) down to 60° off its line:
/// the residual robot-caused contact of the demo's warehouse before `person_accel`
/// (`safety_contacts`, seed 1, t = 15.1 s).
fn swerve_at(params: Option<SafetyParams>, ahead: Real, accel: Real, gap: Real) -> Loop {
    let walker = person(1, vec2(-0.3, 0.65 + gap), vec2(1.3, 0.0));
    let mut sim = Loop::new(
        vec2(0.0, 0.0),
        vec2(1.0, 0.0),
        vec![walker],
        StaticMap::empty(),
    );
    match params {
        Some(p) => sim.layer = SafetyLayer::new(p),
        None => sim.guarded = false,
    }
    for _ in 0..40 {
        let b = &mut sim.bodies[0];
        let heading = b.velocity.y.atan2(b.velocity.x);
        if b.position.x - sim.robot.position.x > ahead && heading > -1.05 {
            // Turning at a/v keeps the speed and accelerates at a sideways.
            let turned = heading - accel / 1.3 * 0.1;
            b.velocity = vec2(turned.cos(), turned.sin()) * 1.3;
        }
        sim.step(vec2(1.0, 0.0), |_| true);
    }
    sim
}

#[test]
fn a_person_swerving_across_from_beside_the_robot_is_never_hit() {
    // 0.1 m beside, turning 0.2 m ahead at 2 m/s² (a_h is 3). A scan of turns at 2–4 m/s²
    // from 0.05–0.2 m beside, 0–0.4 m ahead, found no robot-caused contact either.
    // Dangerous without the layer, and with it when people are trusted to keep their line.
    assert!(
        swerve_at(None, 0.2, 2.0, 0.1)
            .onsets
            .contains(&Onset::RobotCaused)
    );
    let trusting = SafetyParams {
        person_accel: 0.0,
        ..SafetyParams::default()
    };
    assert!(
        swerve_at(Some(trusting), 0.2, 2.0, 0.1)
            .onsets
            .contains(&Onset::RobotCaused)
    );
    let sim = swerve_at(Some(SafetyParams::default()), 0.2, 2.0, 0.1);
    assert!(
        !sim.onsets.contains(&Onset::RobotCaused),
        "{:?}",
        sim.onsets
    );
    assert!(sim.zones.contains(&Zone::Protective));
}

/// A robot wanting full speed follows a person walking its way at 1 m/s, `gap` m apart
/// (surface to surface); after 2 s the person brakes at `braking` m/s² to a standstill and
/// stays. The person's velocity is the mean over each 0.1 s step, so that their path is the
/// continuous one of braking at that rate.
fn follow_a_person_who_halts(params: SafetyParams, gap: Real, braking: Real) -> Loop {
    let walker = person(1, vec2(0.65 + gap, 0.0), vec2(1.0, 0.0));
    let mut sim = Loop::new(
        vec2(0.0, 0.0),
        vec2(1.0, 0.0),
        vec![walker],
        StaticMap::empty(),
    );
    sim.layer = SafetyLayer::new(params);
    let mut speed: Real = 1.0;
    for k in 0..60 {
        if k >= 20 {
            let next = (speed - braking * 0.1).max(0.0);
            // Mean velocity over the step (braking ends within it at most once).
            let moving = if braking > 0.0 {
                (speed / braking).min(0.1)
            } else {
                0.1
            };
            let mean = (speed * moving - 0.5 * braking * moving * moving) / 0.1;
            sim.bodies[0].velocity = vec2(mean, 0.0);
            speed = next;
        }
        sim.step(vec2(1.0, 0.0), |_| true);
    }
    sim
}

#[test]
fn without_people_stopping_dead_a_robot_follows_closer_and_never_hits_one_who_halts() {
    let within_a_h = SafetyParams::default();
    let stopping_dead = SafetyParams {
        people_stop_dead: true,
        ..within_a_h
    };
    for gap in [0.1, 0.3, 0.6, 1.0, 1.5] {
        for braking in [1.0, 2.0, 3.0] {
            for params in [stopping_dead, within_a_h] {
                let sim = follow_a_person_who_halts(params, gap, braking);
                assert!(
                    !sim.onsets.contains(&Onset::RobotCaused),
                    "gap {gap}, braking {braking}, {params:?}: {:?}",
                    sim.onsets
                );
            }
        }
    }
    // A person who walks on (braking 0): the robot keeps closer behind them when they may
    // halt no harder than a_h. It is held back by how far they can come back at it, not by a
    // standstill they cannot reach at once.
    let behind = |params| {
        let sim = follow_a_person_who_halts(params, 1.0, 0.0);
        (sim.bodies[0].position - sim.robot.position).norm() - 0.65
    };
    let (before, after) = (behind(stopping_dead), behind(within_a_h));
    assert!(after < before - 0.3, "{after} m behind against {before} m");
}

#[test]
fn only_people_at_walking_pace_are_taken_to_halt_no_harder_than_a_h() {
    let params = SafetyParams::default();
    let stopping_dead = SafetyParams {
        people_stop_dead: true,
        ..params
    };
    let full = Command::Velocity(vec2(1.0, 0.0));
    // 1 m (surface to surface) behind a person walking on, at full speed.
    let admits = |params: SafetyParams, speed: Real| {
        let mut layer = SafetyLayer::new(params);
        let ahead = [person(1, vec2(1.65, 0.0), vec2(speed, 0.0))];
        let at = ego(vec2(0.0, 0.0), vec2(1.0, 0.0));
        let map = StaticMap::empty();
        layer.prepare(&at, &limits(), &ahead, &map).admits(full)
    };
    // At walking pace the robot may keep following; a person who may stop dead holds it back.
    assert!(admits(params, 1.0));
    assert!(!admits(stopping_dead, 1.0));
    // A person faster than `HALTING_MAX_SPEED` may still stop dead, with or without it.
    assert!(!admits(params, 2.0));
    assert!(!admits(stopping_dead, 2.0));
}

#[test]
fn field_reach_is_the_stopping_budget() {
    let p = SafetyParams::default();
    // At rest both fields are the margin; at 1 m/s: 0.2 m before braking, 1/3 m braking.
    assert_eq!(field_reach(0.0, &limits(), &p), (p.margin, p.margin));
    let (protective, warning) = field_reach(1.0, &limits(), &p);
    assert!((protective - (0.2 + 1.0 / 3.0 + 0.05)).abs() < 1e-12);
    assert!((warning - protective - 1.0).abs() < 1e-12);
}

/// Bodies walk on whatever the robot does: recorded people, or people who do not see it.
/// `want` is what the planner asks for every step.
fn run(sim: &mut Loop, want: Vec2, steps: usize) {
    for _ in 0..steps {
        sim.step(want, |_| true);
    }
}

/// An aisle `width` wide along x, its walls from x = −20 to 20.
fn aisle(width: Real) -> StaticMap {
    let half = width / 2.0;
    StaticMap::new(vec![
        Obstacle::Wall(vec2(-20.0, -half), vec2(20.0, -half)),
        Obstacle::Wall(vec2(-20.0, half), vec2(20.0, half)),
    ])
    .expect("two valid walls")
}

#[test]
fn a_person_walking_straight_at_a_stopped_robot_is_let_through() {
    // The person never reacts; the robot's planner wants it to stay where it is.
    let walker = person(1, vec2(6.0, 0.1), vec2(-1.3, 0.0));
    let mut frozen = Loop::new(
        vec2(0.0, 0.0),
        vec2(0.0, 0.0),
        vec![walker.clone()],
        StaticMap::empty(),
    );
    frozen.layer = SafetyLayer::new(SafetyParams {
        yielding: false,
        ..SafetyParams::default()
    });
    run(&mut frozen, vec2(0.0, 0.0), 80);
    // Standing still, as the layer did before it yielded: walked into.
    assert_eq!(frozen.onsets, [Onset::BodyCaused]);

    let mut sim = Loop::new(
        vec2(0.0, 0.0),
        vec2(0.0, 0.0),
        vec![walker],
        StaticMap::empty(),
    );
    run(&mut sim, vec2(0.0, 0.0), 80);
    assert!(sim.onsets.is_empty(), "{:?}", sim.onsets);
    assert!(sim.zones.contains(&Zone::Yield));
    // It stepped aside, off the person's line at y = 0.1 by more than both bodies' width.
    let off_line = (sim.robot.position.y - 0.1).abs();
    assert!(off_line > 0.65, "at {:?}", sim.robot.position);
}

#[test]
fn a_person_overtaking_a_slow_robot_in_a_narrow_aisle_gets_by() {
    // A 1.8 m aisle; the robot drives at 0.3 m/s along its middle, a person comes from
    // behind at 1.3 m/s a little off the middle and never reacts.
    let walker = person(1, vec2(-5.0, 0.15), vec2(1.3, 0.0));
    let mut sim = Loop::new(vec2(0.0, 0.0), vec2(0.3, 0.0), vec![walker], aisle(1.8));
    run(&mut sim, vec2(0.3, 0.0), 100);
    assert!(
        !sim.onsets.contains(&Onset::RobotCaused),
        "{:?}",
        sim.onsets
    );
    assert!(sim.onsets.is_empty(), "{:?}", sim.onsets);
    assert_eq!(sim.wall_onsets, 0);
    assert!(sim.zones.contains(&Zone::Yield));
    // The person is past, and the robot went on with its task.
    assert!(sim.bodies[0].position.x > sim.robot.position.x + 1.0);
    assert!(sim.robot.position.x > 1.0, "at {:?}", sim.robot.position);
}

#[test]
fn a_group_of_three_abreast_coming_down_an_aisle_is_given_way() {
    // Three people abreast (0.1 m between them) walk at 1.2 m/s down a 4 m aisle toward a
    // robot driving at them at the reduced speed of 0.5 m/s; they never react, and the
    // planner above the layer does not either.
    let group = vec![
        person(1, vec2(8.0, -0.8), vec2(-1.2, 0.0)),
        person(2, vec2(8.0, 0.0), vec2(-1.2, 0.0)),
        person(3, vec2(8.0, 0.8), vec2(-1.2, 0.0)),
    ];
    let walk = |yielding: bool| {
        let mut sim = Loop::new(vec2(0.0, 0.0), vec2(0.5, 0.0), group.clone(), aisle(4.0));
        sim.layer = SafetyLayer::new(SafetyParams {
            yielding,
            ..SafetyParams::default()
        });
        run(&mut sim, vec2(0.5, 0.0), 120);
        sim
    };
    // Stopping alone, the robot is walked into.
    assert!(!walk(false).onsets.is_empty());
    let sim = walk(true);
    assert!(
        !sim.onsets.contains(&Onset::RobotCaused),
        "{:?}",
        sim.onsets
    );
    assert!(sim.onsets.is_empty(), "{:?}", sim.onsets);
    assert_eq!(sim.wall_onsets, 0);
    assert!(sim.zones.contains(&Zone::Yield));
}

#[test]
fn a_robot_cornered_against_a_shelf_stays_put_and_the_contact_is_the_persons() {
    // The robot stands at the back of a niche in a shelf, 0.1 m from its back and sides, the
    // niche 2 m deep; a person walks straight into the niche.
    let niche = Obstacle::Polygon(vec![
        vec2(-1.4, -1.0),
        vec2(1.6, -1.0),
        vec2(1.6, -0.4),
        vec2(-0.4, -0.4),
        vec2(-0.4, 0.4),
        vec2(1.6, 0.4),
        vec2(1.6, 1.0),
        vec2(-1.4, 1.0),
    ]);
    let map = StaticMap::new(vec![niche]).expect("a valid shelf");
    let walker = person(1, vec2(5.0, 0.0), vec2(-1.3, 0.0));
    let mut sim = Loop::new(vec2(0.0, 0.0), vec2(0.0, 0.0), vec![walker], map);
    run(&mut sim, vec2(0.0, 0.0), 60);
    assert_eq!(sim.onsets, [Onset::BodyCaused]);
    assert_eq!(sim.wall_onsets, 0);
    assert!(
        sim.robot.position.norm() < 0.11,
        "moved to {:?}",
        sim.robot.position
    );
}

#[test]
fn parameters_are_changed_by_name_and_checked() {
    let d = SafetyParams::default();
    assert_eq!(d.with_overrides(""), Ok(d));
    let p = d
        .with_overrides("yield_time=3, yield_clearance=0.6,yielding=false")
        .expect("valid");
    assert_eq!(
        (p.yield_time, p.yield_clearance, p.yielding),
        (3.0, 0.6, false)
    );
    assert_eq!(p.person_accel, d.person_accel);
    let before = d.with_overrides("people_stop_dead=true").expect("valid");
    assert!(before.people_stop_dead && !d.people_stop_dead);
    let graded = d.with_overrides("warning_graded=true").expect("valid");
    assert!(graded.warning_graded && !d.warning_graded);
    for (text, named) in [
        ("yield_tme=3", "yield_tme"),
        ("yield_time", "expected key=value"),
        ("yield_time=soon", "yield_time=soon"),
        ("margin=-1", "margin"),
        ("person_accel=nan", "person_accel"),
        ("yielding=maybe", "true or false"),
        ("people_stop_dead=1", "true or false"),
    ] {
        let e = d.with_overrides(text).expect_err(text);
        assert!(e.contains(named), "{text}: {e}");
    }
}

/// The layer's parameters change by name (as `--safety-layer` and a site's map give them),
/// read back from what differs from the defaults, and a bad one is refused by name.
#[test]
fn layer_parameters_change_by_name_and_bad_ones_are_named() {
    let p = SafetyParams::default()
        .with_overrides("warning_time=0.5, yielding=false")
        .expect("valid");
    assert_eq!((p.warning_time, p.yielding), (0.5, false));
    assert_eq!(p.changes(), "warning_time=0.5,yielding=false");
    assert_eq!(SafetyParams::default().with_overrides(&p.changes()), Ok(p));
    assert_eq!(SafetyParams::default().changes(), "");
    for (bad, named) in [
        ("warning_tim=0.5", "warning_tim"),
        ("warning_time=-1", "warning_time"),
        ("margin=NaN", "margin"),
        ("margin", "margin"),
        ("yielding=1", "yielding"),
        ("check_step=x", "check_step"),
    ] {
        let e = SafetyParams::default().with_overrides(bad).expect_err(bad);
        assert!(e.contains(named), "{bad}: {e}");
    }
}
