//! The scanner as the protective field: a person the tracker does not report, seen only as
//! laser returns (`agent::scan`), still never has the robot drive into them under the safety
//! layer, whatever the planner wants.

use agent::guard::Guard;
use agent::map::StaticMap;
use agent::math::{Real, Vec2};
use agent::model::{Command, EgoState};
use agent::planner::{PlannerSpec, PlannerStack, PlanningInput};
use agent::safety::SafetyLimits;
use agent::scan::{Scan, ScanParams, unexplained_bodies};

const DT: Real = 0.1;
const ROBOT_RADIUS: Real = 0.3;
const PERSON_RADIUS: Real = 0.3;

/// A full-turn scan of one circle, as a simulated scanner would return it.
fn scan_of(origin: Vec2, person: Vec2) -> Scan {
    let n = 720;
    let increment = std::f64::consts::TAU / n as Real;
    let ranges = (0..n)
        .map(|k| {
            let d = Vec2::new((k as Real * increment).cos(), (k as Real * increment).sin());
            let oc = origin - person;
            let b = oc.dot(&d);
            let disc = b * b - (oc.norm_squared() - PERSON_RADIUS * PERSON_RADIUS);
            let t = -b - disc.max(0.0).sqrt();
            if disc >= 0.0 && t > 0.0 {
                t as f32
            } else {
                f32::INFINITY
            }
        })
        .collect();
    Scan {
        origin,
        bearing0: 0.0,
        increment,
        range_min: 0.05,
        range_max: 20.0,
        ranges,
    }
}

struct Outcome {
    robot_caused: usize,
    min_gap: Real,
    progress: Real,
}

/// The robot drives from the origin to (10, 0); a person walks from `start` with `velocity`,
/// never reacting. The robot sees them only in its scan.
fn run(planner: &str, start: Vec2, velocity: Vec2) -> Outcome {
    let spec: PlannerSpec = planner.parse().expect("planner");
    let mut stack = PlannerStack::new(spec);
    let mut guard = Guard::new(SafetyLimits::SIMULATED_ROBOT);
    let map = StaticMap::empty();
    let goal = Vec2::new(10.0, 0.0);
    let mut ego = EgoState {
        position: Vec2::zeros(),
        heading: 0.0,
        velocity: Vec2::zeros(),
        yaw_rate: 0.0,
        radius: ROBOT_RADIUS,
    };
    let mut person = start;
    let mut out = Outcome {
        robot_caused: 0,
        min_gap: Real::INFINITY,
        progress: 0.0,
    };
    let mut touching = false;
    for _ in 0..200 {
        let bodies = unexplained_bodies(
            &scan_of(ego.position, person),
            &map,
            &[],
            &ScanParams::default(),
        );
        let input = PlanningInput {
            ego: &ego,
            neighbours: &bodies,
            map: &map,
            goal,
            dt: DT,
            visibility: None,
            safety: None,
        };
        let (plan, _) = guard.plan(&mut stack, &input);
        let v = match plan.command {
            Command::Velocity(v) => v,
            Command::Unicycle { speed, yaw_rate } => {
                ego.heading += yaw_rate * DT;
                Vec2::new(ego.heading.cos(), ego.heading.sin()) * speed
            }
        };
        ego.velocity = v;
        ego.position += v * DT;
        person += velocity * DT;
        let gap = (person - ego.position).norm() - ROBOT_RADIUS - PERSON_RADIUS;
        out.min_gap = out.min_gap.min(gap);
        let now_touching = gap <= 0.0;
        if now_touching && !touching {
            // At the onset: does the robot move toward the person (world_sim's rule)?
            let toward = (person - ego.position).normalize();
            if v.dot(&toward) > 0.05 {
                out.robot_caused += 1;
            }
        }
        touching = now_touching;
    }
    out.progress = ego.position.x;
    out
}

#[test]
fn a_person_seen_only_by_the_scan_is_never_driven_into() {
    for planner in ["pgp+orca", "orca", "dwa", "sf"] {
        // Standing in the way; walking head-on; crossing.
        for (start, vel) in [
            (Vec2::new(4.0, 0.0), Vec2::zeros()),
            (Vec2::new(9.0, 0.1), Vec2::new(-1.0, 0.0)),
            (Vec2::new(4.0, -3.0), Vec2::new(0.0, 1.0)),
        ] {
            let o = run(planner, start, vel);
            assert_eq!(
                o.robot_caused, 0,
                "{planner} {start:?} {vel:?}: gap {:.2}",
                o.min_gap
            );
            // Not safe by standing still: the robot gets past a standing or crossing person.
            // DWA (unicycle arcs, a small window) stops 1 m short of a person standing on its
            // goal line whether the person is tracked or only scanned, so it is held to the
            // contact rule only.
            if vel.x == 0.0 && planner != "dwa" {
                assert!(
                    o.progress > 6.0,
                    "{planner} {start:?}: only {:.1} m",
                    o.progress
                );
            }
        }
    }
}
