//! Scenarios on real floor plans: a Nav2 map on disk beside its scenario, and every kind of
//! bad map refused with an error that names the field at fault.

use world_sim::fleet::Fleet;
use world_sim::fleet::{FleetOptions, run_fleet_with};
use world_sim::scenario::{Scenario, ScenarioError};
use world_sim::traffic_policy::PolicyParams;

/// The built-in scenario's text with its map and (when given) its stations replaced.
fn scenario_text(map: &str, stations: Option<&str>) -> String {
    let text = world_sim::scenario::BUILTIN
        .iter()
        .find(|(name, _)| *name == "aws-small-warehouse")
        .expect("built in")
        .1;
    let map_line = format!("map = {map:?}");
    let Some(stations) = stations else {
        return text.replace("map = \"aws-small-warehouse\"", &map_line);
    };
    let start = text.find("stations = [").expect("stations");
    let end = start + text[start..].find("\n]\n").expect("end of stations") + 3;
    format!(
        "{}stations = [{stations}]\n{}",
        &text[..start],
        &text[end..]
    )
    .replace("map = \"aws-small-warehouse\"", &map_line)
}

const STATIONS: &str = r#"
    { name = "dock", kind = "dock", at = [-6.0, 1.0] },
    { name = "pick", kind = "pick", at = [3.6, -4.5] },
"#;

/// A folder holding the sample map's files (the YAML possibly changed) and a scenario.
fn on_disk(yaml: impl Fn(&str) -> String, stations: Option<&str>) -> (tempfile::TempDir, String) {
    let dir = tempfile::tempdir().expect("temp dir");
    let sample = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("maps/aws-small-warehouse");
    let maps = dir.path().join("maps");
    std::fs::create_dir(&maps).expect("maps folder");
    let text = std::fs::read_to_string(sample.join("map.yaml")).expect("sample yaml");
    std::fs::write(maps.join("map.yaml"), yaml(&text)).expect("yaml");
    std::fs::copy(sample.join("map_rotated.png"), maps.join("map_rotated.png")).expect("png");
    let scenario = dir.path().join("site.toml");
    std::fs::write(&scenario, scenario_text("maps/map.yaml", stations)).expect("scenario");
    let path = scenario.display().to_string();
    (dir, path)
}

fn load(path: &str) -> Result<Scenario, ScenarioError> {
    let text = std::fs::read_to_string(path).expect("scenario file");
    Scenario::from_toml(&text, path)
}

/// The field an error names, and its message.
fn field_of(e: ScenarioError) -> (String, String) {
    let message = e.to_string();
    match e {
        ScenarioError::Invalid { field, .. } => (field, message),
        other => panic!("not a field error: {other}"),
    }
}

#[test]
fn a_map_on_disk_loads_relative_to_its_scenario_and_runs() {
    let (_dir, path) = on_disk(str::to_owned, None);
    let scenario = load(&path).expect("loads");
    let builtin = Scenario::builtin("aws-small-warehouse").expect("built in");
    let (disk, built) = (
        scenario
            .floor_plan
            .as_ref()
            .and_then(|f| f.plan.as_ref())
            .expect("plan"),
        builtin
            .floor_plan
            .as_ref()
            .and_then(|f| f.plan.as_ref())
            .expect("plan"),
    );
    assert_eq!(disk.grid, built.grid);
    assert_eq!(disk.fingerprint, built.fingerprint);
    assert_eq!(Fleet::new(&scenario).expect("a fleet site").robots(), 8);
    // Robots do tasks on it: 60 s of the default fleet, the policy and the layer on.
    let options = FleetOptions {
        share_intents: true,
        policy: Some(PolicyParams::default()),
        human_impact_window_s: None,
    };
    let planner = "pgp+orca".parse().expect("a planner");
    let report = run_fleet_with(&scenario, planner, 60.0, options).expect("runs");
    let tasks: u64 = report.tasks_done.iter().sum();
    println!("{tasks} tasks in 60 s");
    assert!(tasks >= 4, "{tasks} tasks in 60 s");
}

#[test]
fn bad_maps_are_refused_naming_the_field() {
    type Case = (
        &'static str,
        Box<dyn Fn(&str) -> String>,
        &'static str,
        &'static str,
    );
    let cases: [Case; 5] = [
        (
            "a missing image",
            Box::new(|y| y.replace("map_rotated.png", "nowhere.png")),
            "floor_plan.map",
            "nowhere.png",
        ),
        (
            "an image outside the YAML's folder",
            Box::new(|y| y.replace("map_rotated.png", "../site.toml")),
            "floor_plan.map",
            "field `image`",
        ),
        (
            "a zero resolution",
            Box::new(|y| y.replace("0.050000", "0")),
            "floor_plan.map",
            "field `resolution`",
        ),
        (
            "a huge resolution",
            Box::new(|y| y.replace("0.050000", "500")),
            "floor_plan.map",
            "field `resolution`",
        ),
        (
            "a file that is no image",
            Box::new(|y| y.replace("map_rotated.png", "map.yaml")),
            "floor_plan.map",
            "neither a PNG nor a PGM",
        ),
    ];
    for (what, yaml, want_field, want_text) in cases {
        let (_dir, path) = on_disk(yaml, Some(STATIONS));
        let (field, message) = field_of(load(&path).expect_err(what));
        assert_eq!(field, want_field, "{what}: {message}");
        assert!(message.contains(want_text), "{what}: {message}");
    }
}

#[test]
fn stations_in_walls_off_the_map_or_cut_off_are_refused() {
    let cases = [
        (
            r#"{ name = "dock", kind = "dock", at = [-6.0, 1.0] },
               { name = "in-shelf", kind = "pick", at = [-1.8, 5.0] },"#,
            "floor_plan.stations[1].at",
            "\"in-shelf\"",
        ),
        (
            r#"{ name = "far", kind = "dock", at = [40.0, 1.0] },
               { name = "pick", kind = "pick", at = [3.6, -4.5] },"#,
            "floor_plan.stations[0].at",
            "off the map",
        ),
        (
            r#"{ name = "far", kind = "dock", at = [1e300, -1e300] },
               { name = "pick", kind = "pick", at = [3.6, -4.5] },"#,
            "floor_plan.stations[0].at",
            "off the map",
        ),
        (
            r#"{ name = "tight", kind = "dock", at = [-6.75, 1.0] },
               { name = "pick", kind = "pick", at = [3.6, -4.5] },"#,
            "floor_plan.stations[0].at",
            "from the nearest wall",
        ),
        (
            r#"{ name = "dock", kind = "dock", at = [-6.0, 1.0] },"#,
            "floor_plan.stations",
            "no pick station",
        ),
    ];
    for (stations, want_field, want_text) in cases {
        let text = scenario_text("aws-small-warehouse", Some(stations));
        let (field, message) = field_of(Scenario::from_toml(&text, "test").expect_err(want_text));
        assert_eq!(field, want_field, "{message}");
        assert!(message.contains(want_text), "{message}");
    }
    // Too many robots to start near the docks.
    let text =
        scenario_text("aws-small-warehouse", Some(STATIONS)).replace("robots = 8", "robots = 4000");
    let (field, message) = field_of(Scenario::from_toml(&text, "test").expect_err("room"));
    assert_eq!(field, "floor_plan.robots", "{message}");
}

/// An image that is a symbolic link out of the YAML's folder is refused like a path out of it.
#[cfg(unix)]
#[test]
fn an_image_linked_from_outside_the_folder_is_refused() {
    let (dir, path) = on_disk(|y| y.replace("map_rotated.png", "link.png"), Some(STATIONS));
    let outside = dir.path().join("outside.png");
    std::fs::rename(dir.path().join("maps/map_rotated.png"), &outside).expect("moved out");
    std::os::unix::fs::symlink(&outside, dir.path().join("maps/link.png")).expect("linked");
    let (field, message) = field_of(load(&path).expect_err("a link out"));
    assert_eq!(field, "floor_plan.map", "{message}");
    assert!(message.contains("leads outside"), "{message}");
}
