use super::*;

fn default_text() -> &'static str {
    BUILTIN[0].1
}

/// The error `text` is refused with, as the user reads it.
fn error_of(text: &str) -> String {
    Scenario::from_toml(text, "t.toml").unwrap_err().to_string()
}

#[test]
fn builtin_open_space_parses_with_the_papers_stage() {
    let s = Scenario::builtin("open-space").expect("valid");
    let open = s.open_space.expect("layout");
    assert_eq!((open.size_m, open.max_group_size), (10.0, 4));
    assert_eq!(s.human_count(), 50);
}

#[test]
fn load_takes_a_builtin_or_a_scenario_file() {
    let (builtin, builtin_text) = Scenario::load("hallway-fleet").expect("a built-in");
    let dir = tempfile::tempdir().expect("a temporary folder");
    let path = dir.path().join("no-people.toml");
    let text = BUILTIN
        .iter()
        .find(|(n, _)| *n == "hallway-fleet")
        .expect("built in")
        .1
        .replace("humans = 30", "humans = 0");
    std::fs::write(&path, text).expect("written");
    let (file, file_text) = Scenario::load(path.to_str().expect("a UTF-8 path")).expect("a file");
    let people = |s: &Scenario| s.hallway.as_ref().expect("a hallway").humans;
    assert_eq!((people(&builtin), people(&file)), (30, 0));
    assert!(builtin_text.contains("humans = 30") && file_text.contains("humans = 0"));
    let missing = dir.path().join("missing.toml");
    let err = Scenario::load(missing.to_str().expect("a UTF-8 path"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("missing.toml") && err.contains("built in"),
        "{err}"
    );
    let err = Scenario::load("no-such-site").unwrap_err().to_string();
    assert!(err.contains("built in"), "{err}");
    let unreadable = Scenario::load(dir.path().to_str().expect("a UTF-8 path")).unwrap_err();
    assert!(
        matches!(unreadable, ScenarioError::Read { .. }),
        "{unreadable}"
    );
}

#[test]
fn density_001_means_one_person() {
    let mut s = Scenario::builtin("open-space").expect("valid");
    s.open_space.as_mut().expect("layout").density = 0.01;
    assert_eq!(s.human_count(), 1);
}

#[test]
fn unknown_field_is_named() {
    let text = default_text().replace("density = 0.5", "densty = 0.5");
    let err = Scenario::from_toml(&text, "typo.toml")
        .unwrap_err()
        .to_string();
    assert!(err.contains("typo.toml") && err.contains("densty"), "{err}");
}

#[test]
fn wrong_type_is_named() {
    let text = default_text().replace("max_speed = 1.0", "max_speed = \"fast\"");
    let err = error_of(&text);
    assert!(err.contains("max_speed"), "{err}");
}

#[test]
fn out_of_range_value_is_named() {
    let text = default_text().replace("density = 0.5", "density = -1.0");
    let err = error_of(&text);
    assert!(
        err.contains("open_space.density") && err.contains("(0, 3]"),
        "{err}"
    );
    let text = default_text().replace("velocity_noise = 0.0", "velocity_noise = nan");
    let err = error_of(&text);
    assert!(err.contains("robot.velocity_noise"), "{err}");
}

#[test]
fn missing_layout_is_named() {
    let text = default_text()
        .replace("[open_space]", "[unused]")
        .replace("size_m = 10.0\n", "");
    let err = error_of(&text);
    assert!(
        err.contains("unused") || err.contains("open_space"),
        "{err}"
    );
}

#[test]
fn interaction_range_is_optional_and_checked() {
    let s = Scenario::builtin("open-space").expect("valid");
    assert_eq!(
        s.humans.interaction_range_m, None,
        "PySocialForce's all-pairs by default"
    );
    let text = default_text().replace(
        "react_to_robots = true",
        "react_to_robots = true\ninteraction_range_m = 6.0",
    );
    assert_eq!(
        Scenario::from_toml(&text, "t")
            .expect("valid")
            .humans
            .interaction_range_m,
        Some(6.0)
    );
    let text = default_text().replace(
        "react_to_robots = true",
        "react_to_robots = true\ninteraction_range_m = 0.0",
    );
    let err = Scenario::from_toml(&text, "t").unwrap_err().to_string();
    assert!(err.contains("humans.interaction_range_m"), "{err}");
}

#[test]
fn the_safety_layer_is_set_per_site_and_checked() {
    use agent::safety::SafetyParams;
    // The open ground's yield and two fleet sites' shorter warning field; every other
    // parameter and every other site keeps the layer's defaults.
    let open = Scenario::builtin("open-space").expect("valid").robot;
    assert_eq!(
        open.safety_layer,
        SafetyParams {
            yield_time: 3.0,
            yield_clearance: 0.6,
            ..SafetyParams::default()
        }
    );
    for fleet_site in ["warehouse", "hallway-fleet"] {
        let robot = Scenario::builtin(fleet_site).expect("valid").robot;
        let shorter_warning = SafetyParams {
            warning_time: 0.5,
            ..SafetyParams::default()
        };
        assert_eq!(robot.safety_layer, shorter_warning, "{fleet_site}");
    }
    for default_site in ["warehouse-narrow", "hallway"] {
        let robot = Scenario::builtin(default_site).expect("valid").robot;
        assert_eq!(
            robot.safety_layer,
            SafetyParams::default(),
            "{default_site}"
        );
    }
    let guard = open.guard(0.1).expect("the layer is on by default");
    assert_eq!(guard.params(), &open.safety_layer);

    let text = default_text().replace("yield_time = 3.0", "yield_time = -1.0");
    let err = error_of(&text);
    assert!(
        err.contains("robot.safety_layer.yield_time") && err.contains("-1"),
        "{err}"
    );
    let text = default_text().replace("yield_time = 3.0", "yeld_time = 3.0");
    let err = error_of(&text);
    assert!(err.contains("yeld_time"), "{err}");
    let text = default_text().replace("yield_clearance = 0.6", "yield_clearance = nan");
    let err = error_of(&text);
    assert!(err.contains("robot.safety_layer.yield_clearance"), "{err}");
}

#[test]
fn wall_model_defaults_to_points_and_is_checked() {
    let s = Scenario::builtin("warehouse").expect("valid");
    assert_eq!(
        s.humans.walls,
        WallModel::Points,
        "PySocialForce's by default"
    );
    assert_eq!(s.humans.wall_field_spacing_m, 0.1);
    let with = |extra: &str| {
        let text = default_text().replace(
            "react_to_robots = true",
            &format!("react_to_robots = true\n{extra}"),
        );
        Scenario::from_toml(&text, "t")
    };
    let s = with("walls = \"field\"\nwall_field_spacing_m = 0.05").expect("valid");
    assert_eq!(
        (s.humans.walls, s.humans.wall_field_spacing_m),
        (WallModel::Field, 0.05)
    );
    let err = with("walls = \"grid\"").unwrap_err().to_string();
    assert!(err.contains("walls") && err.contains("points"), "{err}");
    let err = with("wall_field_spacing_m = 0.0").unwrap_err().to_string();
    assert!(err.contains("humans.wall_field_spacing_m"), "{err}");
}

/// Fleet sites' people give up stalled goals after 20 s; open stages have no such rule;
/// a bad time is refused with the field's name.
#[test]
fn regoal_after_a_stall_is_set_on_fleet_sites_and_checked() {
    for name in [
        "warehouse",
        "warehouse-narrow",
        "hallway-fleet",
        "warehouse-large",
    ] {
        let s = Scenario::builtin(name).expect("valid");
        assert_eq!(s.humans.regoal_stalled_s, Some(20.0), "{name}");
    }
    let s = Scenario::builtin("open-space").expect("valid");
    assert_eq!(s.humans.regoal_stalled_s, None);
    let text = default_text().replace(
        "react_to_robots = true",
        "react_to_robots = true\nregoal_stalled_s = -1.0",
    );
    let err = Scenario::from_toml(&text, "t").unwrap_err().to_string();
    assert!(err.contains("humans.regoal_stalled_s"), "{err}");
}

/// A scenario for `n` people on an open stage at `density`, sized to fit them.
#[test]
fn sized_for_gives_the_requested_count() {
    let s = Scenario::sized_for(1000, 0.3).expect("valid");
    assert_eq!(s.human_count(), 1000);
}

#[test]
fn builtin_hallway_parses_and_one_layout_is_required() {
    let s = Scenario::builtin("hallway").expect("valid");
    let hall = s.hallway.expect("layout");
    assert_eq!((hall.length_m, hall.width_m), (25.0, 3.0));
    let both = format!(
        "{}\n[open_space]\nsize_m = 10.0\ndensity = 0.5\nmax_group_size = 4\n",
        BUILTIN[1].1
    );
    let err = Scenario::from_toml(&both, "both.toml")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("hallway") && err.contains("one layout"),
        "{err}"
    );
    let narrow = BUILTIN[1].1.replace("width_m = 3.0", "width_m = 0.5");
    let err = Scenario::from_toml(&narrow, "narrow.toml")
        .unwrap_err()
        .to_string();
    assert!(err.contains("hallway.width_m"), "{err}");
}

#[test]
fn unknown_builtin_lists_the_choices() {
    let err = Scenario::builtin("moon").unwrap_err().to_string();
    assert!(err.contains("moon") && err.contains("open-space"), "{err}");
}
