//! Nav2 filter masks on a floor plan. The keep-out sample
//! (`scenarios/aws-small-warehouse-keepout.toml`) takes a packing area from the robots, not
//! from the people; in the speed sample's slow strip along the dock bays
//! (`scenarios/aws-small-warehouse-slow-docks.toml`) robots drive no faster than its limit.
//! Bad masks are refused naming the field at fault.

use agent::math::vec2;
use agent::model::Command;
use agent::planner::PlannerSpec;
use world_sim::fleet::{Fleet, drive, stacks};
use world_sim::scenario::{Scenario, ScenarioError};
use world_sim::traffic_policy::PolicyParams;

/// The keep-out sample's zone (x0, y0, x1, y1), as masks/make_aws_masks.py writes it.
const ZONE: [f64; 4] = [-1.5, -5.0, 1.5, -3.0];
/// The speed sample's strip: x below this (m), the whole map's height.
const STRIP_EAST_X: f64 = -4.5;
/// The speed sample's limit (m/s).
const LIMIT: f64 = 0.5;

fn scenarios() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios")
}

fn load(path: &std::path::Path) -> Result<Scenario, ScenarioError> {
    let text = std::fs::read_to_string(path).expect("scenario file");
    Scenario::from_toml(&text, &path.display().to_string())
}

/// A sample scenario of `scenarios/` by file name.
fn sample(file: &str) -> Scenario {
    load(&scenarios().join(file)).expect("the sample loads")
}

/// The built-in `aws-small-warehouse` at `scenario`'s seed: the samples without their masks.
fn bare(scenario: &Scenario) -> Scenario {
    let mut bare = Scenario::builtin("aws-small-warehouse").expect("built in");
    bare.seed = scenario.seed;
    bare
}

fn plan(scenario: &Scenario) -> &world_sim::floor_plan::FloorPlan {
    scenario
        .floor_plan
        .as_ref()
        .and_then(|f| f.plan.as_ref())
        .expect("a loaded plan")
}

/// Runs `scenario` for `seconds` with `pgp+orca`, the policy and the layer on, showing
/// `observe` the fleet after every step; returns the tasks done.
fn run(scenario: &Scenario, seconds: f64, mut observe: impl FnMut(&Fleet)) -> u64 {
    let planner: PlannerSpec = "pgp+orca".parse().expect("a planner");
    let mut fleet = Fleet::new(scenario).expect("a fleet site");
    fleet.set_traffic_policy(Some(PolicyParams::default()));
    let n = fleet.robots();
    let mut stacks = stacks(&fleet, planner, scenario.robot.max_speed);
    let mut guards = world_sim::episode::guards(scenario, n);
    let mut commands = vec![Command::STOP; n];
    for _ in 0..(seconds / fleet.world.dt).round() as u64 {
        drive(&mut fleet, &mut stacks, &mut guards, &mut commands);
        observe(&fleet);
    }
    (0..n).map(|i| fleet.tasks_done(i)).sum()
}

/// Writes `text` with `from` replaced by `to` as a scenario in `dir` and loads it, expecting
/// a field error: the field and the message.
fn refused(dir: &std::path::Path, text: &str, from: &str, to: &str) -> (String, String) {
    assert!(text.contains(from), "{from}");
    let path = dir.join("site.toml");
    std::fs::write(&path, text.replace(from, to)).expect("scenario");
    let e = load(&path).expect_err("refused");
    let message = e.to_string();
    match e {
        ScenarioError::Invalid { field, .. } => (field, message),
        other => panic!("not a field error: {other}"),
    }
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
fn the_keepout_mask_takes_the_zone_from_robots_only() {
    let scenario = sample("aws-small-warehouse-keepout.toml");
    let plan = plan(&scenario);
    let bare_scenario = bare(&scenario);
    let bare = self::plan(&bare_scenario);
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
    assert!(!plan.robots_may_drive(vec2(0.0, -4.0)));
    assert!(plan.robots_may_drive(vec2(-2.5, -4.0)));
    // Robots plan on a map where the zone is walled; the world (people, sensors) is not.
    let fleet = Fleet::new(&scenario).expect("a fleet site");
    let (west, east) = (vec2(-2.5, -4.0), vec2(2.0, -4.0));
    assert!(fleet.world.map.line_of_sight(west, east));
    assert!(!fleet.robot_map().line_of_sight(west, east));
    let above = vec2(0.0, -2.9);
    assert!((fleet.robot_map().distance(&above) - 0.1).abs() < 0.06);
    assert!(fleet.world.map.distance(&above) > 0.5);
}

#[test]
fn robots_keep_out_of_the_zone_that_people_walk_through() {
    let seconds = 180.0;
    let masked = sample("aws-small-warehouse-keepout.toml");
    // The deepest any robot's body reaches into the zone (m, < 0 when none touched it),
    // and the person-steps spent in it.
    let watch = |deepest: &mut f64, people_in: &mut usize, fleet: &Fleet| {
        for r in &fleet.world.robots {
            *deepest = deepest.max(depth_in_zone(r.state.position, r.state.radius));
        }
        let crowd = &fleet.world.humans.crowd;
        *people_in += crowd.positions.iter().filter(|&&p| in_zone(p)).count();
    };
    let (mut deep_masked, mut people_masked) = (f64::NEG_INFINITY, 0);
    let tasks_masked = run(&masked, seconds, |f| {
        watch(&mut deep_masked, &mut people_masked, f)
    });
    let (mut deep_bare, mut people_bare) = (f64::NEG_INFINITY, 0);
    let tasks_bare = run(&bare(&masked), seconds, |f| {
        watch(&mut deep_bare, &mut people_bare, f)
    });
    println!(
        "with the mask: deepest {deep_masked:.3} m, {tasks_masked} tasks, {people_masked} person-steps in the zone; \
         without: deepest {deep_bare:.3} m, {tasks_bare} tasks, {people_bare} person-steps"
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
fn bad_keepout_masks_are_refused_naming_the_field() {
    let text = std::fs::read_to_string(scenarios().join("aws-small-warehouse-keepout.toml"))
        .expect("sample");
    let dir = tempfile::tempdir().expect("temp dir");
    let line = "keepout = \"masks/aws-small-warehouse-keepout.yaml\"";
    let masks = scenarios().join("masks");
    let mask = |name: &str| format!("keepout = {:?}", masks.join(name).display().to_string());
    // A mask that is not there, or not a YAML.
    let (field, message) = refused(dir.path(), &text, line, "keepout = \"nowhere.yaml\"");
    assert_eq!(field, "floor_plan.keepout", "{message}");
    assert!(message.contains("nowhere.yaml"), "{message}");
    let (field, message) = refused(
        dir.path(),
        &text,
        line,
        &mask("aws-small-warehouse-keepout.pgm"),
    );
    assert_eq!(field, "floor_plan.keepout", "{message}");
    assert!(message.contains(".yaml"), "{message}");
    // A mask whose image is not an image.
    std::fs::write(
        dir.path().join("mask.yaml"),
        "image: mask.png\nresolution: 0.1\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
    )
    .expect("yaml");
    std::fs::write(dir.path().join("mask.png"), "not a picture").expect("png");
    let (field, message) = refused(dir.path(), &text, line, "keepout = \"mask.yaml\"");
    assert_eq!(field, "floor_plan.keepout", "{message}");
    assert!(message.contains("neither a PNG nor a PGM"), "{message}");
    // A station in the zone.
    let text = text.replace(line, &mask("aws-small-warehouse-keepout.yaml"));
    let (field, message) = refused(dir.path(), &text, "at = [-6.0, 1.0]", "at = [0.0, -4.0]");
    assert_eq!(field, "floor_plan.stations[2].at", "{message}");
    assert!(message.contains("keep-out zone"), "{message}");
}

#[test]
fn robots_keep_to_the_limit_in_the_slow_strip() {
    let slow = sample("aws-small-warehouse-slow-docks.toml");
    let zones = plan(&slow).speed_zones.as_ref().expect("zones");
    assert!(zones.cells() > 10_000, "{} cells", zones.cells());
    let fleet = Fleet::new(&slow).expect("a fleet site");
    assert_eq!(fleet.site().speed_limit(vec2(-6.0, 0.0)), Some(LIMIT));
    assert_eq!(fleet.site().speed_limit(vec2(0.0, 0.0)), None);
    let bare = bare(&slow);
    assert_ne!(plan(&slow).fingerprint, plan(&bare).fingerprint);
    // A robot entering at top speed (1 m/s) brakes at 1.5 m/s² to the limit within
    // (1 − 0.25) / 3 = 0.25 m: deeper than 0.3 m it keeps to the limit.
    let (seconds, depth) = (120.0, 0.3);
    let fastest = |top: &mut f64, fleet: &Fleet| {
        for r in &fleet.world.robots {
            if r.state.position.x < STRIP_EAST_X - depth {
                *top = top.max(r.state.velocity.norm());
            }
        }
    };
    let (mut fastest_slow, mut fastest_bare) = (0.0, 0.0);
    let tasks_slow = run(&slow, seconds, |f| fastest(&mut fastest_slow, f));
    let tasks_bare = run(&bare, seconds, |f| fastest(&mut fastest_bare, f));
    println!(
        "in the strip: fastest {fastest_slow:.3} m/s with the mask ({tasks_slow} tasks), \
         {fastest_bare:.3} m/s without ({tasks_bare} tasks)"
    );
    assert!(
        fastest_bare > LIMIT + 0.2,
        "robots drive faster there without a mask"
    );
    assert!(
        fastest_slow <= LIMIT + 1e-9,
        "{fastest_slow} m/s in the strip"
    );
    assert!(tasks_slow > 0);
}

#[test]
fn bad_speed_masks_are_refused_naming_the_field() {
    let text = std::fs::read_to_string(scenarios().join("aws-small-warehouse-slow-docks.toml"))
        .expect("sample");
    let dir = tempfile::tempdir().expect("temp dir");
    let line =
        "speed_mask = { mask = \"masks/aws-small-warehouse-slow-docks.yaml\", limit_m_s = 0.5 }";
    let mask = scenarios()
        .join("masks/aws-small-warehouse-slow-docks.yaml")
        .display()
        .to_string();
    for limit in ["0", "-1", "11", "nan"] {
        let to = format!("speed_mask = {{ mask = {mask:?}, limit_m_s = {limit} }}");
        let (field, message) = refused(dir.path(), &text, line, &to);
        assert_eq!(field, "floor_plan.speed_mask.limit_m_s", "{message}");
    }
    let to = "speed_mask = { mask = \"nowhere.yaml\", limit_m_s = 0.5 }";
    let (field, message) = refused(dir.path(), &text, line, to);
    assert_eq!(field, "floor_plan.speed_mask.mask", "{message}");
    assert!(message.contains("nowhere.yaml"), "{message}");
    let to = "speed_mask = { mask = \"slow.png\", limit_m_s = 0.5 }";
    let (field, message) = refused(dir.path(), &text, line, to);
    assert_eq!(field, "floor_plan.speed_mask.mask", "{message}");
}
