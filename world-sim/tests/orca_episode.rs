//! The ORCA infeasible case of the intent-sharing study (results/intent-sharing/REPORT.md,
//! "The contact episodes"): seed 65, robot 4 backs away from a person walking at it along an
//! aisle, with a shelf beside it, and ORCA's fallback drives it into robot 5 at t = 2.8 s. The
//! safety layer under every robot's planner ends that: no robot touches another robot, and
//! no robot drives into anyone.

use world_sim::fleet::run_fleet;
use world_sim::scenario::Scenario;

fn seed_65(safety: bool) -> world_sim::fleet::FleetReport {
    let mut s = Scenario::builtin("warehouse").expect("built-in");
    s.seed = 65;
    let w = s.warehouse.as_mut().expect("a warehouse");
    (w.robots, w.humans) = (12, 40);
    s.robot.safety = safety;
    run_fleet(&s, "pgp+orca".parse().expect("known"), 6.0, true).expect("a warehouse")
}

#[test]
fn the_orca_infeasible_episode_ends_in_no_overlap_under_the_safety_layer() {
    let robot_robot = |r: &world_sim::fleet::FleetReport| -> Vec<u64> {
        r.robots.iter().map(|m| m.robot_robot_contacts).collect()
    };
    // As published: robots 4 and 5 touch.
    let bare = seed_65(false);
    let contacts = robot_robot(&bare);
    assert!(contacts[4] > 0 && contacts[5] > 0, "{contacts:?}");
    // Under the layer: nobody touches a robot, and no robot drives into a person.
    let guarded = seed_65(true);
    assert_eq!(robot_robot(&guarded), vec![0; 12]);
    let robot_caused: u64 = guarded.robots.iter().map(|m| m.robot_caused_contacts).sum();
    assert_eq!(robot_caused, 0, "{:?}", guarded.robots);
    let acted: u64 = guarded.protective.iter().chain(&guarded.yielded).sum();
    assert!(acted > 0, "the layer acted");
}
