//! The viewer's layout, built in Rust and sent with the recording.

use crate::HeatKind;

/// The layout. Left: the floor (tabs: the last minute's heatmaps, the whole run's, PGP fans)
/// over the robot table. Right: the fleet KPIs, one plot each with the fleet's series only,
/// over tabs for the event log, per-robot plots and the other fleet plots.
pub(crate) fn blueprint() -> rerun::blueprint::Blueprint {
    use rerun::blueprint::components::PanelState;
    use rerun::blueprint::{
        Blueprint, BlueprintPanel, Grid, Horizontal, SelectionPanel, Spatial2DView, Tabs,
        TextDocumentView, TextLogView, TimePanel, TimeSeriesView, Vertical,
    };
    let fleet_plot = |name: &str, metrics: &[&str]| {
        TimeSeriesView::new(name)
            .with_contents(metrics.iter().map(|m| format!("/metrics/{m}/fleet")))
            .into()
    };
    let robot_plot = |name: &str, metric: &str| {
        TimeSeriesView::new(name)
            .with_contents([format!("/metrics/{metric}/robot/**")])
            .into()
    };
    let floor = |name: &str, contents: &[&str]| {
        Spatial2DView::new(name)
            .with_contents(contents.iter().map(|c| (*c).to_owned()))
            .into()
    };
    let heat_kinds = |span: &str| {
        HeatKind::ALL
            .iter()
            .map(move |k| format!("/map/heat/{span}/{}", k.name()))
            .collect::<Vec<_>>()
    };
    let mut last_minute = vec!["/map/**", "/world/**", "-/map/heat/**", "-/world/fan/**"]
        .into_iter()
        .map(str::to_owned)
        .collect::<Vec<_>>();
    last_minute.extend(heat_kinds("window"));
    let mut whole_run = vec!["/map/**", "/world/**", "-/map/heat/**", "-/world/fan/**"]
        .into_iter()
        .map(str::to_owned)
        .collect::<Vec<_>>();
    whole_run.extend(heat_kinds("run"));
    let floor_tabs = Tabs::new([
        Spatial2DView::new("floor: heat of the last minute")
            .with_contents(last_minute)
            .into(),
        Spatial2DView::new("floor: heat of the whole run")
            .with_contents(whole_run)
            .into(),
        floor(
            "floor: PGP fans",
            &["/map/**", "/world/**", "-/map/heat/**"],
        ),
    ]);
    let kpis = Grid::new([
        fleet_plot(
            "fleet efficiency (% of one robot alone)",
            &["efficiency_pct"],
        ),
        fleet_plot("tasks / min", &["tasks_per_minute"]),
        fleet_plot(
            "contacts: robot-caused, person-caused, robot–robot, total",
            &[
                "robot_caused_contacts",
                "person_caused_contacts",
                "robot_robot_contacts",
                "total_contacts",
            ],
        ),
        fleet_plot("space violations (SVR)", &["svr"]),
        fleet_plot(
            "people's delay (person-s / min)",
            &["human_delay_s_per_min"],
        ),
        fleet_plot("stuck robots", &["stuck_robots"]),
        fleet_plot("live agents", &["live_agents"]),
    ]);
    let per_robot = Grid::new([
        robot_plot("SVR per robot", "svr"),
        robot_plot("min human distance per robot (m)", "min_human_distance"),
        robot_plot("people's delay per robot", "human_delay_s_per_min"),
        robot_plot("social force per robot", "social_force"),
    ])
    .with_name("per robot");
    let more = Grid::new([
        fleet_plot("collision rate", &["collision_rate"]),
        fleet_plot("min human distance (m)", &["min_human_distance"]),
        fleet_plot("social force", &["social_force"]),
        fleet_plot(
            "traffic: deadlocks, gridlocks, waiting robots",
            &["deadlocks", "gridlocks", "waiting_robots"],
        ),
        fleet_plot(
            "stuck robot-s by what held them",
            &[
                "stuck_s_policy",
                "stuck_s_person",
                "stuck_s_robot",
                "stuck_s_layer",
                "stuck_s_planner",
            ],
        ),
        fleet_plot(
            "protective stops, extra path (m / min)",
            &["protective_robots", "human_extra_path_m_per_min"],
        ),
        fleet_plot(
            "planner p99 (µs), stale commands, dropped frames",
            &["planner_p99_us", "stale_commands", "dropped_frames"],
        ),
    ])
    .with_name("more fleet plots");
    Blueprint::new(
        Horizontal::new([
            Vertical::new([
                floor_tabs.into(),
                TextDocumentView::new("robots")
                    .with_contents(["/fleet/robots"])
                    .into(),
            ])
            .with_row_shares([0.62, 0.38])
            .into(),
            Vertical::new([
                kpis.into(),
                Tabs::new([
                    TextLogView::new("events").with_contents(["/events"]).into(),
                    per_robot.into(),
                    more.into(),
                ])
                .into(),
            ])
            .with_row_shares([0.6, 0.4])
            .into(),
        ])
        .with_column_shares([0.55, 0.45]),
    )
    // The side panels folded away: the floor, KPIs and table get the screen.
    .with_blueprint_panel(BlueprintPanel::new().with_state(PanelState::Collapsed))
    .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
    .with_time_panel(TimePanel::new().with_state(PanelState::Collapsed))
}
