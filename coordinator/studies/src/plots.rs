//! Plots in the style of the PGP paper's Fig. 4 (success metrics) and Fig. 5 (quality and
//! social metrics): a metric against crowd density, one colour per short-term planner, PGP+X
//! solid and X dashed.

use super::summary::{Group, Summary};
use plotters::prelude::*;
use plotters::series::DashedLineSeries;
use std::path::Path;
use std::sync::Once;

/// DejaVu Sans (see `assets/DejaVuSans.LICENSE`), bundled so that plots need no system fonts.
static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

/// A plot could not be drawn or written.
#[derive(Debug, thiserror::Error)]
#[error("plot {}: {source}", path.display())]
pub struct PlotError {
    path: std::path::PathBuf,
    source: Box<dyn std::error::Error + Send + Sync>,
}

fn plot_error<E: std::error::Error + Send + Sync + 'static>(path: &Path, e: E) -> PlotError {
    PlotError {
        path: path.to_owned(),
        source: Box::new(e),
    }
}

/// One panel: its y-axis label and how to read the value from a group.
type Panel = (&'static str, fn(&Group) -> Option<f64>);

fn register_font() {
    REGISTER.call_once(|| {
        // The bundled font is valid; a failure would only leave labels blank.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// Writes `fig4_success.png` and `fig5_social.png` into `out`.
pub fn write_figures(summary: &Summary, out: &Path) -> Result<(), PlotError> {
    register_font();
    let fig4: [Panel; 3] = [
        ("time to goal (s)", |g| g.time_to_goal_s),
        ("path length (m)", |g| g.path_length_m),
        ("collision rate while moving (%)", |g| {
            g.collision_rate.map(|v| 100.0 * v)
        }),
    ];
    let fig5: [Panel; 3] = [
        ("min. distance to people (m)", |g| g.min_human_distance_m),
        ("space-violation rate while moving (%)", |g| {
            g.svr.map(|v| 100.0 * v)
        }),
        ("avg. social force on robot", |g| g.social_force),
    ];
    figure(
        &out.join("fig4_success.png"),
        "Success metrics (cf. PGP paper Fig. 4)",
        &fig4,
        summary,
    )?;
    figure(
        &out.join("fig5_social.png"),
        "Quality / social metrics (cf. PGP paper Fig. 5)",
        &fig5,
        summary,
    )
}

fn colour(algorithm: &str) -> RGBColor {
    match algorithm.trim_start_matches("pgp+") {
        "dwa" => RGBColor(31, 119, 180),
        "orca" => RGBColor(214, 39, 40),
        "sf" => RGBColor(44, 160, 44),
        "asfm" => RGBColor(148, 103, 189),
        "pnp" | "pnp-nopeek" => RGBColor(255, 127, 14),
        _ => RGBColor(127, 127, 127),
    }
}

fn figure(path: &Path, title: &str, panels: &[Panel], summary: &Summary) -> Result<(), PlotError> {
    let err = |e| plot_error(path, e);
    let root = BitMapBackend::new(path, (900, 1150)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, ("sans-serif", 24)).map_err(err)?;
    let mut algorithms: Vec<&str> = Vec::new();
    for g in &summary.groups {
        if !algorithms.contains(&g.algorithm.as_str()) {
            algorithms.push(&g.algorithm);
        }
    }
    let x_max = summary.groups.iter().map(|g| g.density).fold(0.0, f64::max) * 1.05;
    for (area, (label, get)) in root.split_evenly((panels.len(), 1)).iter().zip(panels) {
        let series: Vec<(&str, Vec<(f64, f64)>)> = algorithms
            .iter()
            .map(|a| {
                let mut pts: Vec<(f64, f64)> = summary
                    .groups
                    .iter()
                    .filter(|g| g.algorithm == *a)
                    .filter_map(|g| get(g).map(|v| (g.density, v)))
                    .collect();
                pts.sort_by(|p, q| p.0.total_cmp(&q.0));
                (*a, pts)
            })
            .collect();
        let y_max = series
            .iter()
            .flat_map(|(_, p)| p.iter().map(|q| q.1))
            .fold(0.0, f64::max)
            .max(1e-9)
            * 1.1;
        let mut chart = ChartBuilder::on(area)
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..x_max, 0.0..y_max)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("density (people / m²)")
            .y_desc(*label)
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(err)?;
        for (name, pts) in series {
            let style = colour(name).stroke_width(2);
            let name = name.to_uppercase();
            if name.starts_with("PGP") {
                chart
                    .draw_series(LineSeries::new(pts, style))
                    .map_err(err)?
                    .label(name)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
            } else {
                chart
                    .draw_series(DashedLineSeries::new(pts, 7, 5, style))
                    .map_err(err)?
                    .label(name)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 8, y)], style));
            }
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .label_font(("sans-serif", 13))
            .border_style(BLACK)
            .background_style(WHITE.mix(0.85))
            .draw()
            .map_err(err)?;
    }
    root.present().map_err(err)
}

/// One planner's runs on a recorded crowd: (s, d_r / d_h) per run.
pub type ReplayPoints<'a> = (&'a str, Vec<(f64, f64)>);

/// The foIGP paper's Figs. 5c / 6c: per planner, each run's closest distance to a pedestrian s
/// against its path length relative to the person's, d_r / d_h; lines at s = 0.21 m and 0.3 m
/// and at d_r / d_h = 1.25. The people's own s are drawn in grey at d_r / d_h = 1.
pub fn write_playback_figure(
    path: &Path,
    title: &str,
    planners: &[ReplayPoints<'_>],
    human_s: &[f64],
) -> Result<(), PlotError> {
    register_font();
    let err = |e| plot_error(path, e);
    let rows = planners.len().div_ceil(2).max(1);
    let root = BitMapBackend::new(path, (1000, 60 + 330 * rows as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(err)?;
    let finite = |v: f64| v.is_finite().then_some(v);
    let x_max = planners
        .iter()
        .flat_map(|(_, p)| p.iter().map(|q| q.0))
        .chain(human_s.iter().copied())
        .filter_map(finite)
        .fold(1.0, f64::max)
        .min(4.0)
        * 1.05;
    let y_max = planners
        .iter()
        .flat_map(|(_, p)| p.iter().map(|q| q.1))
        .filter_map(finite)
        .fold(1.5, f64::max)
        * 1.05;
    let y_min = planners
        .iter()
        .flat_map(|(_, p)| p.iter().map(|q| q.1))
        .filter_map(finite)
        .fold(0.9, f64::min)
        * 0.95;
    for (area, (name, points)) in root.split_evenly((rows, 2)).iter().zip(planners) {
        let mut chart = ChartBuilder::on(area)
            .caption(*name, ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(36)
            .y_label_area_size(50)
            .build_cartesian_2d(0.0..x_max, y_min..y_max)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("s: closest distance to a pedestrian (m)")
            .y_desc("d_r / d_h")
            .label_style(("sans-serif", 13))
            .draw()
            .map_err(err)?;
        let grey = RGBColor(170, 170, 170);
        chart
            .draw_series(human_s.iter().filter_map(|&s| {
                finite(s).map(|s| Circle::new((s.min(x_max), 1.0), 2, grey.filled()))
            }))
            .map_err(err)?;
        let red = RGBColor(214, 39, 40);
        for x in [0.21, 0.3] {
            chart
                .draw_series(DashedLineSeries::new(
                    vec![(x, y_min), (x, y_max)],
                    5,
                    4,
                    red.stroke_width(1),
                ))
                .map_err(err)?;
        }
        chart
            .draw_series(DashedLineSeries::new(
                vec![(0.0, 1.25), (x_max, 1.25)],
                5,
                4,
                BLACK.stroke_width(1),
            ))
            .map_err(err)?;
        let blue = RGBColor(31, 119, 180);
        chart
            .draw_series(points.iter().filter_map(|&(s, r)| {
                Some(Circle::new(
                    (finite(s)?.min(x_max), finite(r)?.min(y_max)),
                    3,
                    blue.filled(),
                ))
            }))
            .map_err(err)?;
    }
    root.present().map_err(err)
}

/// One named line: (x, y) points in order of x.
pub type Series = (String, Vec<(f64, f64)>);

/// One panel of [`write_lines`]: x label, y label, the lines.
pub type LinePanel<'a> = (&'a str, &'a str, Vec<Series>);

/// A figure of `panels` stacked vertically, each a line (with markers) per series.
pub fn write_lines(path: &Path, title: &str, panels: &[LinePanel<'_>]) -> Result<(), PlotError> {
    register_font();
    let err = |e| plot_error(path, e);
    let height = 80 + 380 * panels.len().max(1) as u32;
    let root = BitMapBackend::new(path, (900, height)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(err)?;
    for (area, (x_label, y_label, lines)) in root
        .split_evenly((panels.len().max(1), 1))
        .iter()
        .zip(panels)
    {
        let points = || lines.iter().flat_map(|(_, p)| p.iter());
        let x_max = points().map(|p| p.0).fold(0.0, f64::max).max(1e-9) * 1.05;
        let y_max = points().map(|p| p.1).fold(0.0, f64::max).max(1e-9) * 1.1;
        // From 0, or below it when a series goes negative.
        let y_min = points().map(|p| p.1).fold(0.0, f64::min) * 1.1;
        let mut chart = ChartBuilder::on(area)
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..x_max, y_min..y_max)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(*x_label)
            .y_desc(*y_label)
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(err)?;
        for (k, (name, pts)) in lines.iter().enumerate() {
            let style = Palette99::pick(k).stroke_width(2);
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), style))
                .map_err(err)?
                .label(name.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
            chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 3, style.filled())))
                .map_err(err)?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .label_font(("sans-serif", 13))
            .border_style(BLACK)
            .background_style(WHITE.mix(0.85))
            .draw()
            .map_err(err)?;
    }
    root.present().map_err(err)
}

/// A box per category: (label, [min, lower quartile, median, upper quartile, max]), in order.
pub fn write_boxes(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    boxes: &[(String, [f64; 5])],
) -> Result<(), PlotError> {
    register_font();
    let err = |e| plot_error(path, e);
    let root = BitMapBackend::new(path, (900, 520)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, ("sans-serif", 20)).map_err(err)?;
    let n = boxes.len().max(1);
    let y_max = boxes
        .iter()
        .map(|b| b.1[4])
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max)
        .max(1e-9)
        * 1.1;
    // From 0, or below it when a box reaches below.
    let y_min = boxes
        .iter()
        .map(|b| b.1[0])
        .filter(|v| v.is_finite())
        .fold(0.0, f64::min)
        * 1.1;
    let mut chart = ChartBuilder::on(&root)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(-0.5..(n as f64 - 0.5), y_min..y_max)
        .map_err(err)?;
    let labels: Vec<String> = boxes.iter().map(|b| b.0.clone()).collect();
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .x_labels(n)
        .x_label_formatter(&|x| {
            let i = x.round();
            if (x - i).abs() < 1e-6 && i >= 0.0 {
                labels.get(i as usize).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        })
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    let blue = RGBColor(31, 119, 180);
    for (i, (_, q)) in boxes.iter().enumerate() {
        if q.iter().any(|v| !v.is_finite()) {
            continue;
        }
        let x = i as f64;
        chart
            .draw_series([
                Rectangle::new([(x - 0.3, q[1]), (x + 0.3, q[3])], blue.mix(0.3).filled()),
                Rectangle::new([(x - 0.3, q[1]), (x + 0.3, q[3])], blue.stroke_width(2)),
            ])
            .map_err(err)?;
        chart
            .draw_series([
                PathElement::new(
                    vec![(x - 0.3, q[2]), (x + 0.3, q[2])],
                    BLACK.stroke_width(3),
                ),
                PathElement::new(vec![(x, q[0]), (x, q[1])], blue.stroke_width(1)),
                PathElement::new(vec![(x, q[3]), (x, q[4])], blue.stroke_width(1)),
                PathElement::new(
                    vec![(x - 0.15, q[0]), (x + 0.15, q[0])],
                    blue.stroke_width(1),
                ),
                PathElement::new(
                    vec![(x - 0.15, q[4]), (x + 0.15, q[4])],
                    blue.stroke_width(1),
                ),
            ])
            .map_err(err)?;
    }
    root.present().map_err(err)
}

/// A plan of a fleet site: its floor (a floor plan's cells: free white, occupied black,
/// unknown grey, kept out of by robots light red, speed-limited light blue), walls and shelves, stations (docks blue, picks red, named), where the robots
/// start (orange) and the route from every dock to every pick and back (green).
pub fn write_site(path: &Path, scenario: &world_sim::scenario::Scenario) -> Result<(), PlotError> {
    use agent::map::Obstacle;
    use world_sim::floor_plan::nav2::Cell;
    use world_sim::warehouse::StationKind;
    register_font();
    let err = |e: String| plot_error(path, std::io::Error::other(e));
    let world = world_sim::world::World::from_scenario(scenario);
    let site = world
        .site()
        .ok_or_else(|| err(format!("{} is not a fleet site", scenario.name)))?;
    let (lo, hi) = (site.origin, site.origin + site.size);
    // 40 pixels a metre, the plot's margins round it.
    let scale = 40.0;
    let (w, h) = (
        (site.size.x * scale) as u32 + 120,
        (site.size.y * scale) as u32 + 110,
    );
    let root = BitMapBackend::new(path, (w, h)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let root = root
        .titled(
            &format!("{}: stations, robot starts and routes", scenario.name),
            ("sans-serif", 20),
        )
        .map_err(|e| err(e.to_string()))?;
    let mut chart = ChartBuilder::on(&root)
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(50)
        .build_cartesian_2d(lo.x..hi.x, lo.y..hi.y)
        .map_err(|e| err(e.to_string()))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| err(e.to_string()))?;
    let e = |e: DrawingAreaErrorKind<_>| err(e.to_string());
    if let Some(plan) = scenario.floor_plan.as_ref().and_then(|f| f.plan.as_ref()) {
        let g = &plan.grid;
        let cells = (0..g.height).flat_map(|y| (0..g.width).map(move |x| (x, y)));
        chart
            .draw_series(
                cells
                    .filter(|&(x, y)| g.at(x, y) != Cell::Free)
                    .map(|(x, y)| {
                        let a = g.origin + agent::math::vec2(x as f64, y as f64) * g.resolution;
                        let colour = if g.at(x, y) == Cell::Occupied {
                            RGBColor(40, 40, 40)
                        } else {
                            RGBColor(190, 190, 190)
                        };
                        Rectangle::new(
                            [(a.x, a.y), (a.x + g.resolution, a.y + g.resolution)],
                            colour.filled(),
                        )
                    }),
            )
            .map_err(e)?;
        // Keep-out zones light red, speed zones light blue: tinted floor cells.
        let tint = |chart: &mut ChartContext<'_, _, _>,
                    colour: RGBAColor,
                    zone: &dyn Fn(usize, usize) -> bool| {
            chart
                .draw_series(
                    (0..g.height)
                        .flat_map(|y| (0..g.width).map(move |x| (x, y)))
                        .filter(|&(x, y)| plan.floor[y * g.width + x] && zone(x, y))
                        .map(|(x, y)| {
                            let a = g.origin + agent::math::vec2(x as f64, y as f64) * g.resolution;
                            Rectangle::new(
                                [(a.x, a.y), (a.x + g.resolution, a.y + g.resolution)],
                                colour.filled(),
                            )
                        }),
                )
                .map(|_| ())
        };
        tint(&mut chart, RGBColor(220, 60, 60).mix(0.35), &|x, y| {
            !plan.robot_floor[y * g.width + x]
        })
        .map_err(e)?;
        if let Some(zones) = &plan.speed_zones {
            tint(&mut chart, RGBColor(60, 120, 230).mix(0.2), &|x, y| {
                zones.limit_at(g.centre(x, y)).is_some()
            })
            .map_err(e)?;
        }
    }
    let walls = RGBColor(120, 60, 20);
    for o in &site.obstacles {
        let ring: Vec<(f64, f64)> = match o {
            Obstacle::Wall(a, b) => vec![(a.x, a.y), (b.x, b.y)],
            Obstacle::Polygon(p) => p.iter().chain(p.first()).map(|v| (v.x, v.y)).collect(),
        };
        chart
            .draw_series([PathElement::new(ring, walls.stroke_width(2))])
            .map_err(e)?;
    }
    let green = RGBColor(20, 150, 40);
    for a in site.stations_of(StationKind::Dock) {
        for b in site.stations_of(StationKind::Pick) {
            for (from, to) in [(a, b), (b, a)] {
                let mut line = vec![(from.position.x, from.position.y)];
                line.extend(
                    site.route(from.position, to.position)
                        .iter()
                        .map(|p| (p.x, p.y)),
                );
                chart
                    .draw_series([PathElement::new(line, green.mix(0.45).stroke_width(1))])
                    .map_err(e)?;
            }
        }
    }
    let orange = RGBColor(255, 140, 0);
    chart
        .draw_series(world.robots.iter().map(|r| {
            let p = r.state.position;
            Circle::new(
                (p.x, p.y),
                (scenario.robot.radius_m * scale) as i32,
                orange.filled(),
            )
        }))
        .map_err(e)?;
    let names: Vec<String> = match &scenario.floor_plan {
        Some(f) => {
            let mut s: Vec<_> = f.stations.iter().collect();
            s.sort_by_key(|s| s.kind != StationKind::Dock);
            s.iter().map(|s| s.name.clone()).collect()
        }
        None => site.stations.iter().map(|s| format!("{}", s.id)).collect(),
    };
    for (s, name) in site.stations.iter().zip(&names) {
        let colour = match s.kind {
            StationKind::Dock => RGBColor(30, 80, 220),
            StationKind::Pick => RGBColor(220, 30, 30),
        };
        let p = (s.position.x, s.position.y);
        chart
            .draw_series([EmptyElement::at(p)
                + Circle::new((0, 0), 6, colour.filled())
                + Text::new(name.clone(), (7, -14), ("sans-serif", 12).into_font())])
            .map_err(e)?;
    }
    root.present().map_err(|e| err(e.to_string()))
}
