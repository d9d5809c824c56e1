//! The logging thread's side: frames into Rerun archetypes, and what spans frames (the
//! heatmaps, the fading event markers).

use crate::heat::{Heat, HeatParams};
use crate::{
    EVENT_FADE_S, FieldState, FieldView, Frame, HeatKind, MapFrame, P, SegmentView, TrafficGoal,
    TrafficView, table,
};
use std::collections::VecDeque;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::Receiver;

pub(crate) fn log_map(
    rec: &rerun::RecordingStream,
    map: &MapFrame,
) -> rerun::RecordingStreamResult<()> {
    // y up, as in the world frame: Rerun's 2D views put y down.
    for root in ["map", "world"] {
        rec.log_static(root, &rerun::Transform3D::from_scale([1.0, -1.0, 1.0]))?;
    }
    let shelves: Vec<Vec<P>> = map
        .shelves
        .iter()
        .map(|poly| {
            let mut closed = poly.clone();
            if let Some(&first) = poly.first() {
                closed.push(first);
            }
            closed
        })
        .collect();
    rec.log_static(
        "map/shelves",
        &rerun::LineStrips2D::new(shelves).with_colors([rerun::Color::from_rgb(140, 110, 70)]),
    )?;
    rec.log_static(
        "map/walls",
        &rerun::LineStrips2D::new(map.walls.iter().map(|w| w.to_vec()))
            .with_colors([rerun::Color::from_rgb(90, 90, 90)]),
    )?;
    if !map.keepout.is_empty() {
        rec.log_static(
            "map/keepout",
            &rerun::LineStrips2D::new(map.keepout.iter().map(|w| w.to_vec()))
                .with_colors([rerun::Color::from_rgb(220, 60, 60)]),
        )?;
    }
    rec.log_static(
        "map/stations",
        &rerun::Points2D::new(map.stations.iter().map(|s| s.0))
            .with_labels(map.stations.iter().map(|s| s.1.clone()))
            .with_radii([0.25])
            .with_colors([rerun::Color::from_rgb(60, 160, 220)]),
    )?;
    Ok(())
}

const GROUP_COLOURS: [(u8, u8, u8); 10] = [
    (230, 159, 0),
    (86, 180, 233),
    (0, 158, 115),
    (240, 228, 66),
    (204, 121, 167),
    (213, 94, 0),
    (0, 114, 178),
    (170, 170, 170),
    (120, 200, 120),
    (200, 120, 200),
];

/// Red (survival 0) to green (survival 1).
fn survival_colour(p: f32) -> rerun::Color {
    let p = p.clamp(0.0, 1.0);
    rerun::Color::from_rgb((255.0 * (1.0 - p)) as u8, (200.0 * p) as u8, 40)
}

/// An event marker on the map: when, where, label, bad news.
type Mark = (f64, P, String, bool);

/// The logging thread's state across frames: the heatmaps and the markers still fading.
#[derive(Debug)]
pub(crate) struct Painter {
    heat: Heat,
    marks: VecDeque<Mark>,
    /// The simulated second the heatmaps and the table were last drawn in.
    drawn_second: Option<i64>,
}

impl Painter {
    pub(crate) fn new(map: &MapFrame, params: HeatParams) -> Self {
        Self {
            heat: Heat::new(map, params),
            marks: VecDeque::new(),
            drawn_second: None,
        }
    }

    pub(crate) fn run(
        &mut self,
        rec: &rerun::RecordingStream,
        rx: &Receiver<Frame>,
        dropped: &AtomicU64,
        logged: &AtomicU64,
    ) {
        while let Ok(frame) = rx.recv() {
            if let Err(e) = self.log(rec, &frame, dropped.load(Ordering::Relaxed)) {
                tracing::warn!("dashboard: {e}");
            }
            logged.fetch_add(1, Ordering::Relaxed);
        }
    }

    fn log(
        &mut self,
        rec: &rerun::RecordingStream,
        f: &Frame,
        dropped: u64,
    ) -> rerun::RecordingStreamResult<()> {
        log_frame(rec, f, dropped)?;
        self.heat.add(f.sim_time, &f.heat);
        self.log_marks(rec, f)?;
        // Heatmaps and the table once per simulated second (and on the first frame).
        let second = f.sim_time.floor() as i64;
        if self.drawn_second != Some(second) {
            self.drawn_second = Some(second);
            self.log_heat(rec)?;
            if !f.robot_rows.is_empty() {
                rec.log(
                    "fleet/robots",
                    &rerun::TextDocument::new(table::markdown(&f.robot_rows))
                        .with_media_type(rerun::MediaType::markdown()),
                )?;
            }
        }
        Ok(())
    }

    /// Markers for the events of the last [`EVENT_FADE_S`], more transparent the older.
    fn log_marks(
        &mut self,
        rec: &rerun::RecordingStream,
        f: &Frame,
    ) -> rerun::RecordingStreamResult<()> {
        let fresh = f.events.iter().filter_map(|e| {
            // Bad news is labelled, with the text up to its first colon ("robot 3 stuck: no
            // progress ..."); the rest (agents joining, tasks done) only marked, so that labels
            // stay legible with many robots.
            let label = if e.warning {
                e.text.split(':').next().unwrap_or_default().to_owned()
            } else {
                String::new()
            };
            Some((f.sim_time, e.position?, label, e.warning))
        });
        let before = self.marks.len();
        self.marks.extend(fresh);
        let mut changed = self.marks.len() != before;
        while self
            .marks
            .front()
            .is_some_and(|m| f.sim_time - m.0 >= EVENT_FADE_S)
        {
            self.marks.pop_front();
            changed = true;
        }
        // Redrawn every tenth of the fade while any are up (not every tick), and when one
        // comes or goes.
        let tick_fade = f.tick.is_multiple_of(10) && !self.marks.is_empty();
        if !changed && !tick_fade {
            return Ok(());
        }
        let alpha = |m: &Mark| {
            let left = 1.0 - (f.sim_time - m.0) / EVENT_FADE_S;
            (40.0 + 215.0 * left.clamp(0.0, 1.0)) as u8
        };
        rec.log(
            "world/events",
            &rerun::Points2D::new(self.marks.iter().map(|m| m.1))
                .with_radii([0.35])
                .with_labels(self.marks.iter().map(|m| m.2.clone()))
                .with_colors(self.marks.iter().map(|m| {
                    let (r, g, b) = if m.3 { (255, 40, 40) } else { (40, 200, 40) };
                    rerun::Color::from_unmultiplied_rgba(r, g, b, alpha(m))
                })),
        )
    }

    /// Every heatmap as an image under the map, in the map's frame.
    fn log_heat(&self, rec: &rerun::RecordingStream) -> rerun::RecordingStreamResult<()> {
        let grid = self.heat.grid;
        for kind in HeatKind::ALL {
            let layer = &self.heat.layers[kind as usize];
            for (span, values) in [("window", &layer.window), ("run", &layer.run)] {
                let path = format!("map/heat/{span}/{}", kind.name());
                rec.log(
                    path.as_str(),
                    &rerun::Transform3D::from_translation_scale(
                        [grid.origin[0], grid.origin[1], 0.0],
                        rerun::Scale3D::uniform(grid.cell_m),
                    ),
                )?;
                rec.log(
                    path.as_str(),
                    &rerun::Image::from_rgba32(self.heat.image(values, kind.colour()), grid.size)
                        .with_draw_order(-20.0),
                )?;
            }
        }
        Ok(())
    }
}

/// The fields: outlines always, in the colour of the field that acted (amber warning, red
/// protective, blue for a yield, on the protective outline), grey otherwise.
fn log_fields(
    rec: &rerun::RecordingStream,
    fields: &[FieldView],
) -> rerun::RecordingStreamResult<()> {
    let grey = rerun::Color::from_rgb(170, 170, 170);
    let colour = |acting: bool, on: rerun::Color| if acting { on } else { grey };
    rec.log(
        "world/safety/protective",
        &rerun::LineStrips2D::new(fields.iter().map(|f| f.protective.clone()))
            .with_colors(fields.iter().map(|f| match f.state {
                FieldState::Yield => rerun::Color::from_rgb(40, 110, 240),
                state => colour(
                    state == FieldState::Protective,
                    rerun::Color::from_rgb(230, 30, 30),
                ),
            }))
            .with_labels(fields.iter().map(|f| match f.state {
                FieldState::Protective => format!("{} protective", f.robot),
                FieldState::Yield => format!("{} yields", f.robot),
                _ => String::new(),
            })),
    )?;
    rec.log(
        "world/safety/warning",
        &rerun::LineStrips2D::new(fields.iter().map(|f| f.warning.clone())).with_colors(
            fields.iter().map(|f| {
                colour(
                    f.state == FieldState::Warning,
                    rerun::Color::from_rgb(240, 170, 0),
                )
            }),
        ),
    )?;
    Ok(())
}

/// A closed circle of `radius` round `centre`.
fn ring(centre: P, radius: f32) -> Vec<P> {
    const SIDES: usize = 20;
    (0..=SIDES)
        .map(|k| {
            let a = std::f32::consts::TAU * k as f32 / SIDES as f32;
            [centre[0] + radius * a.cos(), centre[1] + radius * a.sin()]
        })
        .collect()
}

/// Segments coloured by their reservation, arrows along reserved ones, wait-for edges, rings
/// round stuck robots and the goals the policy set.
fn log_traffic(rec: &rerun::RecordingStream, t: &TrafficView) -> rerun::RecordingStreamResult<()> {
    let segment_colour = |d: Option<i8>| match d {
        None => rerun::Color::from_unmultiplied_rgba(160, 160, 160, 90),
        Some(d) if d > 0 => rerun::Color::from_unmultiplied_rgba(40, 170, 80, 150),
        Some(_) => rerun::Color::from_unmultiplied_rgba(150, 70, 200, 150),
    };
    let ids = |v: &[u32]| v.iter().map(u32::to_string).collect::<Vec<_>>().join(",");
    if !t.segments.is_empty() {
        rec.log(
            "world/traffic/segments",
            &rerun::Boxes2D::from_mins_and_sizes(
                t.segments.iter().map(|s| s.min),
                t.segments
                    .iter()
                    .map(|s| [s.max[0] - s.min[0], s.max[1] - s.min[1]]),
            )
            .with_colors(t.segments.iter().map(|s| segment_colour(s.direction)))
            .with_labels(t.segments.iter().map(|s| {
                let arrow = match s.direction {
                    None => "free",
                    Some(d) if d > 0 => "→",
                    Some(_) => "←",
                };
                let mut label = format!("seg {} {arrow}", s.id);
                if !s.holders.is_empty() {
                    label += &format!(" in: {}", ids(&s.holders));
                }
                if !s.waiting.is_empty() {
                    label += &format!(" waiting: {}", ids(&s.waiting));
                }
                label
            })),
        )?;
        let reserved: Vec<&SegmentView> = t
            .segments
            .iter()
            .filter(|s| s.direction.is_some())
            .collect();
        rec.log(
            "world/traffic/directions",
            &rerun::Arrows2D::from_vectors(reserved.iter().map(|s| {
                let d = f32::from(s.direction.unwrap_or(1));
                [d * 0.4 * (s.max[0] - s.min[0]), 0.0]
            }))
            .with_origins(reserved.iter().map(|s| {
                let d = f32::from(s.direction.unwrap_or(1));
                let mid = [(s.min[0] + s.max[0]) / 2.0, (s.min[1] + s.max[1]) / 2.0];
                [mid[0] - d * 0.2 * (s.max[0] - s.min[0]), mid[1]]
            }))
            .with_colors(reserved.iter().map(|s| segment_colour(s.direction))),
        )?;
    }
    rec.log(
        "world/traffic/waits",
        &rerun::Arrows2D::from_vectors(
            t.waits
                .iter()
                .map(|(a, b, _)| [0.85 * (b[0] - a[0]), 0.85 * (b[1] - a[1])]),
        )
        .with_origins(t.waits.iter().map(|w| w.0))
        .with_colors(t.waits.iter().map(|w| {
            if w.2 {
                rerun::Color::from_rgb(230, 30, 30)
            } else {
                rerun::Color::from_rgb(240, 170, 0)
            }
        })),
    )?;
    rec.log(
        "world/traffic/stuck",
        &rerun::LineStrips2D::new(t.stuck.iter().map(|s| ring(s.1, s.2 + 0.2)))
            .with_colors([rerun::Color::from_rgb(230, 30, 30)])
            .with_labels(t.stuck.iter().map(|s| format!("{} stuck", s.0))),
    )?;
    rec.log(
        "world/traffic/goals",
        &rerun::Points2D::new(t.goals.iter().map(|g| g.1))
            .with_radii([0.1])
            .with_labels(t.goals.iter().map(|g| {
                let kind = match g.2 {
                    TrafficGoal::Hold => "hold",
                    TrafficGoal::Queue => "queue",
                    TrafficGoal::Retreat => "retreat",
                    TrafficGoal::GiveWay => "give way",
                };
                format!("{} {kind}", g.0)
            }))
            .with_colors(t.goals.iter().map(|g| match g.2 {
                TrafficGoal::Hold | TrafficGoal::Queue => rerun::Color::from_rgb(240, 170, 0),
                TrafficGoal::Retreat => rerun::Color::from_rgb(230, 30, 30),
                TrafficGoal::GiveWay => rerun::Color::from_rgb(60, 120, 230),
            })),
    )?;
    Ok(())
}

fn log_frame(
    rec: &rerun::RecordingStream,
    f: &Frame,
    dropped: u64,
) -> rerun::RecordingStreamResult<()> {
    rec.set_time_sequence("tick", f.tick as i64);
    rec.set_duration_secs("sim_time", f.sim_time);
    rec.log(
        "world/humans",
        &rerun::Points2D::new(f.humans.iter().copied())
            .with_radii([f.human_radius])
            .with_colors(f.human_groups.iter().map(|&g| {
                let (r, gr, b) = GROUP_COLOURS[g as usize % GROUP_COLOURS.len()];
                rerun::Color::from_rgb(r, gr, b)
            })),
    )?;
    rec.log(
        "world/robots",
        &rerun::Points2D::new(f.robots.iter().map(|r| r.position))
            .with_radii(f.robots.iter().map(|r| r.radius))
            .with_labels(f.robots.iter().map(|r| r.id.to_string()))
            .with_colors(f.robots.iter().map(|r| {
                if r.alive {
                    rerun::Color::from_rgb(30, 30, 220)
                } else {
                    rerun::Color::from_rgb(220, 30, 30)
                }
            })),
    )?;
    rec.log(
        "world/robots/heading",
        &rerun::Arrows2D::from_vectors(
            f.robots
                .iter()
                .map(|r| [0.6 * r.heading.cos(), 0.6 * r.heading.sin()]),
        )
        .with_origins(f.robots.iter().map(|r| r.position)),
    )?;
    rec.log(
        "world/intents",
        &rerun::LineStrips2D::new(f.intents.iter().map(|i| i.path.clone()))
            .with_colors([rerun::Color::from_rgb(80, 80, 255)]),
    )?;
    rec.log(
        "world/subgoals",
        &rerun::Points2D::new(f.intents.iter().map(|i| i.subgoal))
            .with_radii([0.12])
            .with_colors([rerun::Color::from_rgb(255, 0, 255)]),
    )?;
    if !f.fields.is_empty() {
        log_fields(rec, &f.fields)?;
    }
    if let Some(traffic) = &f.traffic {
        log_traffic(rec, traffic)?;
    }
    for fan in &f.fans {
        rec.log(
            format!("world/fan/{}", fan.robot),
            &rerun::LineStrips2D::new(fan.candidates.iter().map(|c| c.0.clone()))
                .with_colors(fan.candidates.iter().map(|c| survival_colour(c.1))),
        )?;
    }
    if !f.events.is_empty() {
        for e in &f.events {
            let level = if e.warning { "WARN" } else { "INFO" };
            rec.log(
                "events",
                &rerun::TextLog::new(e.text.clone()).with_level(level),
            )?;
        }
    }
    for (name, value) in &f.fleet_metrics {
        rec.log(
            format!("metrics/{name}/fleet"),
            &rerun::Scalars::single(*value),
        )?;
    }
    rec.log(
        "metrics/dropped_frames/fleet",
        &rerun::Scalars::single(dropped as f64),
    )?;
    for (robot, series) in &f.robot_metrics {
        for (name, value) in series {
            rec.log(
                format!("metrics/{name}/robot/{robot}"),
                &rerun::Scalars::single(*value),
            )?;
        }
    }
    Ok(())
}
