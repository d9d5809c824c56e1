//! Nav2 keep-out filter masks on a floor plan: the sample mask of
//! `scenarios/aws-small-warehouse-keepout.toml` takes a packing area from the robots, not from
//! the people, and bad masks are refused naming the field at fault.

use agent::model::Command;
use agent::planner::PlannerSpec;
use world_sim::fleet::{Fleet, drive, stacks};
use world_sim::scenario::{Scenario, ScenarioError};
use world_sim::traffic_policy::PolicyParams;

/// The sample mask's zone (x0, y0, x1, y1), as masks/make_aws_keepout.py writes it.
const ZONE: [f64; 4] = [-1.5, -5.0, 1.5, -3.0];

fn scenarios() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios")
}

fn load(path: &std::path::Path) -> Result<Scenario, ScenarioError> {
    let text = std::fs::read_to_string(path).expect("scenario file");
    Scenario::from_toml(&text, &path.display().to_string())
}

fn sample() -> Scenario {
    load(&scenarios().join("aws-small-warehouse-keepout.toml")).expect("the sample loads")
}

fn in_zone(p: agent::math::Vec2) -> bool {
    p.x >= ZONE[0] && p.x <= ZONE[2] && p.y >= ZONE[1] && p.y <= ZONE[3]
}

/// How far `p` is inside the zone's rectangle grown by `by` (m): > 0 inside, ≤ 0 outside.
fn depth_in_zone(p: agent::math::Vec2, by: f64) -> f64 {
    let dx = (p.x - (ZONE[0] - by)).min((ZONE[2] + by) - p.x);
    let dy = (p.y - (ZONE[1] - by)).min((ZONE[3] + by) - p.y);
    dx.min(dy)
}

#[test]
fn the_sample_mask_takes_the_zone_from_robots_only() {
    let scenario = sample();
    let plan = scenario
        .floor_plan
        .as_ref()
        .and_then(|f| f.plan.as_ref())
        .expect("plan");
    let builtin = Scenario::builtin("aws-small-warehouse").expect("built in");
    let bare = builtin
        .floor_plan
        .as_ref()
        .and_then(|f| f.plan.as_ref())
        .expect("plan");
    // The same map; the mask changes the fingerprint a journal checks.
    assert_eq!(plan.grid, bare.grid);
    assert_eq!(plan.floor, bare.floor);
    assert_ne!(plan.fingerprint, bare.fingerprint);
    // Exactly the floor cells whose centres lie in the zone (0.05 m cells under 0.1 m mask
    // pixels, the zone's edges on pixel edges) are taken from the robots.
    let g = &plan.grid;
    let mut want = 0;
    for y in 0..g.height {
        for x in 0..g.width {
            let i = y * g.width + x;
            let taken = plan.floor[i] && in_zone(g.centre(x, y));
            assert_eq!(
                plan.robot_floor[i],
                plan.floor[i] && !taken,
                "cell ({x}, {y})"
            );
            want += usize::from(taken);
        }
    }
    assert!(want > 2000, "{want} cells in the zone");
    assert_eq!(plan.kept_out_cells(), want);
    let inside = agent::math::vec2(0.0, -4.0);
    assert!(!plan.robots_may_drive(inside));
    assert!(plan.robots_may_drive(agent::math::vec2(-2.5, -4.0)));
    // Robots plan on a map where the zone is walled; the world (people, sensors) is not.
    let fleet = Fleet::new(&scenario).expect("a fleet site");
    let (west, east) = (agent::math::vec2(-2.5, -4.0), agent::math::vec2(2.0, -4.0));
    assert!(fleet.world.map.line_of_sight(west, east));
    assert!(!fleet.robot_map().line_of_sight(west, east));
    let above = agent::math::vec2(0.0, -2.9);
    assert!((fleet.robot_map().distance(&above) - 0.1).abs() < 0.06);
    assert!(fleet.world.map.distance(&above) > 0.5);
}

/// Runs `scenario` for `seconds`, policy and layer on, and returns the deepest any robot's
/// body reached into the zone (m, < 0 when none touched it), the tasks done, and the
/// person-steps spent in the zone.
fn run(scenario: &Scenario, seconds: f64) -> (f64, u64, usize) {
    let planner: PlannerSpec = "pgp+orca".parse().expect("a planner");
    let mut fleet = Fleet::new(scenario).expect("a fleet site");
    fleet.set_traffic_policy(Some(PolicyParams::default()));
    let n = fleet.robots();
    let mut stacks = stacks(&fleet, planner, scenario.robot.max_speed);
    let mut guards = world_sim::episode::guards(scenario, n);
    let mut commands = vec![Command::STOP; n];
    let (mut deepest, mut people_in) = (f64::NEG_INFINITY, 0);
    for _ in 0..(seconds / fleet.world.dt).round() as u64 {
        drive(&mut fleet, &mut stacks, &mut guards, &mut commands);
        for r in &fleet.world.robots {
            deepest = deepest.max(depth_in_zone(r.state.position, r.state.radius));
        }
        people_in += fleet
            .world
            .humans
            .crowd
            .positions
            .iter()
            .filter(|&&p| in_zone(p))
            .count();
    }
    let tasks = (0..n).map(|i| fleet.tasks_done(i)).sum();
    (deepest, tasks, people_in)
}

#[test]
fn robots_keep_out_of_the_zone_that_people_walk_through() {
    let seconds = 180.0;
    let masked = sample();
    let mut bare = Scenario::builtin("aws-small-warehouse").expect("built in");
    bare.seed = masked.seed;
    let (deep_masked, tasks_masked, people_masked) = run(&masked, seconds);
    let (deep_bare, tasks_bare, _) = run(&bare, seconds);
    println!(
        "with the mask: deepest {deep_masked:.3} m, {tasks_masked} tasks, {people_masked} person-steps in the zone; \
         without: deepest {deep_bare:.3} m, {tasks_bare} tasks"
    );
    // Without the mask robots drive through the zone; with it no robot's body enters it
    // (up to 2 cm: the walls follow the cells within one 5 cm cell of simplification).
    assert!(deep_bare > 0.3, "robots crossed the zone without a mask");
    assert!(
        deep_masked < 0.02,
        "a robot reached {deep_masked} m into the zone"
    );
    // People still walk there, and the fleet still works.
    assert!(people_masked > 0, "no person entered the zone");
    assert!(tasks_masked > 0, "no task done with the mask");
}

#[test]
fn bad_masks_are_refused_naming_the_field() {
    let text = std::fs::read_to_string(scenarios().join("aws-small-warehouse-keepout.toml"))
        .expect("sample");
    let dir = tempfile::tempdir().expect("temp dir");
    let masks = scenarios().join("masks");
    let try_with = |line: &str, stations: Option<(&str, &str)>| {
        let mut t = text.replace("keepout = \"masks/aws-small-warehouse-keepout.yaml\"", line);
        if let Some((from, to)) = stations {
            t = t.replace(from, to);
        }
        let path = dir.path().join("site.toml");
        std::fs::write(&path, t).expect("scenario");
        let e = load(&path).expect_err("refused");
        let message = e.to_string();
        match e {
            ScenarioError::Invalid { field, .. } => (field, message),
            other => panic!("not a field error: {other}"),
        }
    };
    let mask = |name: &str| format!("keepout = {:?}", masks.join(name).display().to_string());
    // A mask that is not there, or not a YAML.
    let (field, message) = try_with("keepout = \"nowhere.yaml\"", None);
    assert_eq!(field, "floor_plan.keepout", "{message}");
    assert!(message.contains("nowhere.yaml"), "{message}");
    let (field, message) = try_with(&mask("aws-small-warehouse-keepout.pgm"), None);
    assert_eq!(field, "floor_plan.keepout", "{message}");
    assert!(message.contains(".yaml"), "{message}");
    // A mask whose image is not an image.
    std::fs::write(dir.path().join("mask.yaml"), "image: mask.png\nresolution: 0.1\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n").expect("yaml");
    std::fs::write(dir.path().join("mask.png"), "not a picture").expect("png");
    let (field, message) = try_with("keepout = \"mask.yaml\"", None);
    assert_eq!(field, "floor_plan.keepout", "{message}");
    assert!(message.contains("neither a PNG nor a PGM"), "{message}");
    // A station in the zone.
    let (field, message) = try_with(
        &mask("aws-small-warehouse-keepout.yaml"),
        Some(("at = [-6.0, 1.0]", "at = [0.0, -4.0]")),
    );
    assert_eq!(field, "floor_plan.stations[2].at", "{message}");
    assert!(message.contains("keep-out zone"), "{message}");
}
