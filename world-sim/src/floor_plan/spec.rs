//! A scenario's `[floor_plan]` table: the map and masks it names, loaded relative to the
//! scenario's folder, and its stations, checked against the loaded plan.

use super::nav2::{self, Cell};
use super::router::{self, Router};
use super::{FloorPlan, START_SPACING_M, speed};
use crate::warehouse::StationKind;
use agent::math::{Real, Vec2, vec2};
use std::path::Path;
use std::sync::Arc;

/// A scenario's `[floor_plan]` table: a fleet site from a Nav2 map's walls and
/// shelves, and the stations this table names. People walk between the stations in groups;
/// robots do pick/drop tasks, starting near the docks.
#[derive(Debug, Clone, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FloorPlanSpec {
    /// A built-in map's name (`aws-small-warehouse`), or the path of a Nav2 map.yaml,
    /// relative to the scenario file's folder.
    pub map: String,
    /// Number of robots (≥ 1).
    pub robots: usize,
    /// Number of people.
    pub humans: usize,
    /// Groups have 1 to this many members.
    pub max_group_size: usize,
    /// Where goods are picked and dropped, in the map's frame.
    pub stations: Vec<StationSpec>,
    /// A Nav2 keep-out filter mask (its map.yaml, relative to the scenario file's folder):
    /// its occupied cells are out of bounds for robots, not for people
    /// ([`FloorPlan::with_keepout`]). None by default.
    #[serde(default)]
    pub keepout: Option<String>,
    /// A Nav2 speed filter mask and the limit on its zones ([`speed::SpeedMaskSpec`]). None
    /// by default.
    #[serde(default)]
    pub speed_mask: Option<speed::SpeedMaskSpec>,
    /// The map, loaded when the scenario is read.
    #[serde(skip)]
    pub plan: Option<Arc<FloorPlan>>,
}

/// One station of a floor plan.
#[derive(Debug, Clone, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StationSpec {
    /// A name for reports and errors.
    pub name: String,
    /// `"dock"` (goods dropped) or `"pick"` (goods picked).
    pub kind: StationKind,
    /// Where robots stop: x and y in the map's frame (m).
    pub at: [Real; 2],
}

impl FloorPlanSpec {
    /// Loads the map and the masks the table names, paths relative to `folder` (the scenario
    /// file's), into [`FloorPlanSpec::plan`]. The error names the field at fault and why.
    pub fn load(&mut self, folder: &Path) -> Result<(), (String, String)> {
        let field = |name: &str, reason: String| (format!("floor_plan.{name}"), reason);
        let mut plan =
            FloorPlan::load(&self.map, folder).map_err(|e| field("map", e.to_string()))?;
        // A mask's path is the scenario folder's too; its errors name the mask's field.
        let mask = |path: &str, name: &str| {
            if !(path.ends_with(".yaml") || path.ends_with(".yml")) {
                return Err(field(
                    name,
                    format!("{path:?} is no path to a Nav2 mask's .yaml file"),
                ));
            }
            let path = folder.join(path);
            let mask = nav2::load(&path).map_err(|e| field(name, e.to_string()))?;
            Ok((mask, path.display().to_string()))
        };
        if let Some(keepout) = &self.keepout {
            let (m, path) = mask(keepout, "keepout")?;
            plan = plan.with_keepout(&m.grid, m.fingerprint, &path);
        }
        if let Some(speed) = &self.speed_mask {
            let limit = speed.limit_m_s;
            if !(limit > 0.0 && limit <= speed::MAX_LIMIT_M_S) {
                return Err(field(
                    "speed_mask.limit_m_s",
                    format!("is {limit}; must be in (0, {}] m/s", speed::MAX_LIMIT_M_S),
                ));
            }
            let (m, path) = mask(&speed.mask, "speed_mask.mask")?;
            plan = plan.with_speed_mask(&m.grid, limit, m.fingerprint, &path);
        }
        self.plan = Some(Arc::new(plan));
        Ok(())
    }

    /// The stations' positions and kinds, docks first, each kind in the table's order.
    pub fn stations(&self) -> Vec<(Vec2, StationKind)> {
        let mut out: Vec<(Vec2, StationKind)> = self
            .stations
            .iter()
            .map(|s| (vec2(s.at[0], s.at[1]), s.kind))
            .collect();
        out.sort_by_key(|s| s.1 != StationKind::Dock);
        out
    }

    /// The router for robots of `radius`; `None` before the map is loaded.
    pub fn router(&self, radius: Real) -> Option<Arc<Router>> {
        let positions: Vec<Vec2> = self.stations().iter().map(|s| s.0).collect();
        Some(self.plan.as_ref()?.router(radius, &positions))
    }

    /// The people's router on a plan with a keep-out mask ([`FloorPlan::people_router`]).
    pub fn people_router(&self, radius: Real) -> Option<Arc<Router>> {
        let positions: Vec<Vec2> = self.stations().iter().map(|s| s.0).collect();
        self.plan.as_ref()?.people_router(radius, &positions)
    }

    /// Where `robots` robots of `radius` start: the roomiest places nearest the docks.
    pub fn starts(&self, radius: Real) -> Vec<Vec2> {
        let Some(router) = self.router(radius) else {
            return Vec::new();
        };
        let stations = self.stations();
        let docks: Vec<Vec2> = stations
            .iter()
            .filter(|s| s.1 == StationKind::Dock)
            .map(|s| s.0)
            .collect();
        let all: Vec<Vec2> = stations.iter().map(|s| s.0).collect();
        router.places_near(&docks, &all, self.robots, START_SPACING_M)
    }

    /// The first bad field and why, for robots of `radius`.
    pub fn validate(&self, radius: Real) -> Option<(String, String)> {
        let bad = |field: &str, reason: String| Some((format!("floor_plan.{field}"), reason));
        if !(1..=crate::scenario::MAX_ROBOTS).contains(&self.robots) {
            return bad("robots", "must be in [1, 4096]".to_owned());
        }
        if self.max_group_size == 0 {
            return bad("max_group_size", "must be at least 1".to_owned());
        }
        let Some(plan) = &self.plan else {
            return bad(
                "map",
                "was not loaded (read the scenario from its text)".to_owned(),
            );
        };
        if self.stations.len() > 1000 {
            return bad("stations", "has more than 1000 stations".to_owned());
        }
        for kind in [StationKind::Dock, StationKind::Pick] {
            if !self.stations.iter().any(|s| s.kind == kind) {
                return bad(
                    "stations",
                    format!("has no {kind:?} station").to_lowercase(),
                );
            }
        }
        let router = self.router(radius)?;
        let g = &plan.grid;
        let first = self.stations().first().map(|s| s.0)?;
        let first_name = &self
            .stations
            .iter()
            .find(|s| vec2(s.at[0], s.at[1]) == first)?
            .name;
        for (i, s) in self.stations.iter().enumerate() {
            let field = format!("stations[{i}].at");
            let p = vec2(s.at[0], s.at[1]);
            if s.name.is_empty() || s.name.len() > 64 {
                return bad(
                    &format!("stations[{i}].name"),
                    "must be 1 to 64 bytes".to_owned(),
                );
            }
            let Some((x, y)) = g.cell_of(p) else {
                let far = g.far_corner();
                return bad(
                    &field,
                    format!(
                        "({}, {}) of {:?} is off the map (x {} to {}, y {} to {})",
                        p.x, p.y, s.name, g.origin.x, far.x, g.origin.y, far.y
                    ),
                );
            };
            match g.at(x, y) {
                Cell::Occupied => {
                    return bad(
                        &field,
                        format!("{:?} stands in a wall (an occupied cell)", s.name),
                    );
                }
                Cell::Unknown => {
                    return bad(&field, format!("{:?} stands in unmapped space", s.name));
                }
                Cell::Free => {}
            }
            if plan.floor[y * g.width + x] && !plan.robot_floor[y * g.width + x] {
                return bad(
                    &field,
                    format!(
                        "{:?} stands in a keep-out zone of the keep-out mask",
                        s.name
                    ),
                );
            }
            if router.clearance(p) == 0.0 {
                return bad(
                    &field,
                    format!(
                        "{:?} is on free floor cut off from the map's main floor",
                        s.name
                    ),
                );
            }
            if !router.fits(p) {
                return bad(
                    &field,
                    format!(
                        "{:?} is {:.2} m from the nearest wall; a robot of radius {radius} m needs {:.2} m",
                        s.name,
                        router.clearance(p),
                        radius + router::PASS_MARGIN_M
                    ),
                );
            }
            if !router.reaches(0, p) {
                return bad(
                    &field,
                    format!("{:?} cannot be reached from {first_name:?}", s.name),
                );
            }
        }
        let starts = self.starts(radius).len();
        if starts < self.robots {
            return bad(
                "robots",
                format!(
                    "is {}, but the floor has room for {starts} to start near the docks",
                    self.robots
                ),
            );
        }
        None
    }
}
