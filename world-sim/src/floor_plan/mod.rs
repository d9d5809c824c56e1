//! Sites from real floor plans: a Nav2 map (its YAML and image, [`nav2`]) becomes the walls
//! and shelves of a fleet site, and a scenario's `[floor_plan]` table names its stations.
//!
//! Every cell that is occupied or unknown is solid, except specks of unknown in the floor
//! (scanner noise, [`UNKNOWN_SPECK_M2`]): people and robots keep to the floor.
//! The boundary between free and solid cells becomes walls ([`boundary_walls`]): only what
//! faces the free space, straight runs joined, so a planner near a shelf sees its outline
//! rather than its cells. Routes come from [`router::Router`]. Coordinates are the map
//! frame's: a site from a floor plan does not start at (0, 0).
//!
//! A Nav2 keep-out filter mask ([`FloorPlan::with_keepout`]) takes floor away from robots
//! only: its occupied cells are walls to the robots' planners, safety layers and routes, while
//! people walk there and sensors see through them. A Nav2 speed filter mask
//! ([`speed`]) limits the robots' speed in its zones.

pub mod nav2;
pub mod router;
mod spec;
pub mod speed;

pub use spec::{FloorPlanSpec, StationSpec};

use agent::map::Obstacle;
use agent::math::{Real, Vec2, vec2};
use nav2::{Cell, MapFileError, OccupancyGrid};
use router::Router;
use std::path::Path;
use std::sync::{Arc, Mutex, PoisonError};

/// Robots start at least this far (m) from each other and from every station.
pub const START_SPACING_M: Real = 1.2;

/// The maps shipped with gapfleet: name, YAML text, image file name, image bytes.
pub const BUILTIN_MAPS: &[(&str, &str, &str, &[u8])] = &[(
    "aws-small-warehouse",
    include_str!("../../maps/aws-small-warehouse/map.yaml"),
    "map_rotated.png",
    include_bytes!("../../maps/aws-small-warehouse/map_rotated.png"),
)];

/// A loaded floor plan: the occupancy grid and the obstacles made from it.
#[derive(Clone)]
pub struct FloorPlan {
    /// Where it came from: a built-in map's name or the YAML's path.
    pub source: String,
    /// The cells.
    pub grid: OccupancyGrid,
    /// Per cell, whether it is on the main floor ([`main_floor`]).
    pub floor: Vec<bool>,
    /// The boundary of the free space as walls ([`boundary_walls`]).
    pub obstacles: Vec<Obstacle>,
    /// Per cell, whether robots may drive there: the main floor less the keep-out mask's
    /// cells ([`FloorPlan::with_keepout`]); the main floor without a mask.
    pub robot_floor: Vec<bool>,
    /// The boundary of the robots' floor as walls, when a keep-out mask took floor away.
    pub robot_obstacles: Option<Vec<Obstacle>>,
    /// Where a speed mask limits the robots' speed ([`FloorPlan::with_speed_mask`]).
    pub speed_zones: Option<Arc<speed::SpeedZones>>,
    /// FNV-1a of the YAML text and the image bytes, mixed with each mask's: two runs on the
    /// same fingerprint ran on the same map and masks.
    pub fingerprint: u64,
    /// The last router built, for the robot radius and stations it was built for: validating
    /// a scenario and building its world need the same one.
    router: Arc<Mutex<Option<CachedRouter>>>,
    /// The same for the people's router on a plan with a keep-out mask.
    people_router: Arc<Mutex<Option<CachedRouter>>>,
}

/// A router and the robot radius and stations it was built for.
type CachedRouter = (Real, Vec<Vec2>, Arc<Router>);

impl PartialEq for FloorPlan {
    fn eq(&self, other: &Self) -> bool {
        self.source == other.source
            && self.fingerprint == other.fingerprint
            && self.grid == other.grid
    }
}

impl std::fmt::Debug for FloorPlan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FloorPlan")
            .field("source", &self.source)
            .field("cells", &(self.grid.width, self.grid.height))
            .field("resolution", &self.grid.resolution)
            .field("origin", &self.grid.origin)
            .field("obstacles", &self.obstacles.len())
            .field("fingerprint", &format_args!("{:016x}", self.fingerprint))
            .finish()
    }
}

impl FloorPlan {
    /// A built-in map by name, or a Nav2 map.yaml: a name ending in `.yaml` or `.yml` is a
    /// path, taken relative to `folder`.
    pub fn load(map: &str, folder: &Path) -> Result<Self, MapFileError> {
        let is_path = map.ends_with(".yaml") || map.ends_with(".yml");
        if !is_path {
            let Some(&(name, yaml, image_name, image)) =
                BUILTIN_MAPS.iter().find(|(n, ..)| *n == map)
            else {
                let known: Vec<&str> = BUILTIN_MAPS.iter().map(|m| m.0).collect();
                return Err(MapFileError::Read {
                    file: map.to_owned(),
                    reason: format!(
                        "is no built-in map ({}) nor a path to a .yaml file",
                        known.join(", ")
                    ),
                });
            };
            let meta = nav2::MapYaml::parse(yaml, name)?;
            let grid = meta.grid(image, image_name)?;
            let fingerprint = nav2::fingerprint(yaml.as_bytes(), image);
            return Ok(Self::from_grid(name.to_owned(), grid, fingerprint));
        }
        let path = folder.join(map);
        let loaded = nav2::load(&path)?;
        Ok(Self::from_grid(
            path.display().to_string(),
            loaded.grid,
            loaded.fingerprint,
        ))
    }

    /// The floor plan of `grid`.
    pub fn from_grid(source: String, grid: OccupancyGrid, fingerprint: u64) -> Self {
        let floor = main_floor(&grid);
        let obstacles = boundary_walls(&grid, &floor);
        Self {
            source,
            grid,
            robot_floor: floor.clone(),
            floor,
            obstacles,
            robot_obstacles: None,
            speed_zones: None,
            fingerprint,
            router: Arc::default(),
            people_router: Arc::default(),
        }
    }

    /// This floor plan with a Nav2 keep-out filter mask (nav2_map_server's `filter_mask`
    /// of a keep-out zone filter, trinary): a map cell whose centre falls on an occupied
    /// mask cell is taken from the robots' floor. The mask may have its own resolution and
    /// origin; cells it does not cover stay as they were. `mask_fingerprint` is folded into
    /// the plan's, and `mask_source` (the mask's path) into its source.
    pub fn with_keepout(
        mut self,
        mask: &OccupancyGrid,
        mask_fingerprint: u64,
        mask_source: &str,
    ) -> Self {
        let g = &self.grid;
        let mut robot_floor = self.floor.clone();
        for y in 0..g.height {
            for x in 0..g.width {
                let kept_out = mask
                    .cell_of(g.centre(x, y))
                    .is_some_and(|(mx, my)| mask.at(mx, my) == Cell::Occupied);
                if kept_out {
                    robot_floor[y * g.width + x] = false;
                }
            }
        }
        if robot_floor != self.floor {
            self.robot_obstacles = Some(boundary_walls(g, &robot_floor));
        }
        self.robot_floor = robot_floor;
        self.fingerprint = (self.fingerprint ^ mask_fingerprint).wrapping_mul(0x0100_0000_01b3);
        self.source = format!("{} with the keep-out mask {mask_source}", self.source);
        // A fresh cache: clones of the plan without the mask share the old one.
        self.router = Arc::default();
        self.people_router = Arc::default();
        self
    }

    /// The router people walk by when a keep-out mask took floor from the robots: the whole
    /// main floor's, for bodies of `radius`, with fields to `stations`; `None` without a mask
    /// (people walk by the robots' router, [`FloorPlan::router`]).
    pub fn people_router(&self, radius: Real, stations: &[Vec2]) -> Option<Arc<Router>> {
        self.routers(radius, stations).1
    }

    /// This floor plan with a Nav2 speed filter mask: robots drive no faster than `limit_m_s`
    /// on the map cells whose centres fall on the mask's occupied cells
    /// ([`speed::SpeedZones`]). `mask_fingerprint` and `mask_source` are folded into the
    /// plan's as with a keep-out mask.
    pub fn with_speed_mask(
        mut self,
        mask: &OccupancyGrid,
        limit_m_s: Real,
        mask_fingerprint: u64,
        mask_source: &str,
    ) -> Self {
        self.speed_zones = speed::SpeedZones::new(&self.grid, mask, limit_m_s).map(Arc::new);
        self.fingerprint = (self.fingerprint ^ mask_fingerprint).wrapping_mul(0x0100_0000_01b3);
        self.source = format!("{} with the speed mask {mask_source}", self.source);
        self
    }

    /// Map cells taken from the robots' floor by the keep-out mask.
    pub fn kept_out_cells(&self) -> usize {
        self.floor
            .iter()
            .zip(&self.robot_floor)
            .filter(|(f, r)| **f && !**r)
            .count()
    }

    /// Whether robots may drive at `p`: on the main floor and outside every keep-out zone.
    pub fn robots_may_drive(&self, p: Vec2) -> bool {
        self.grid
            .cell_of(p)
            .is_some_and(|(x, y)| self.robot_floor[y * self.grid.width + x])
    }

    /// The router for robots of `radius` with fields to `stations` (built once per radius
    /// and stations).
    pub fn router(&self, radius: Real, stations: &[Vec2]) -> Arc<Router> {
        self.routers(radius, stations).0
    }

    /// The robots' router ([`FloorPlan::router`]) and the people's
    /// ([`FloorPlan::people_router`]), each built once per radius and stations; when both
    /// are to be built, on two threads.
    pub fn routers(&self, radius: Real, stations: &[Vec2]) -> (Arc<Router>, Option<Arc<Router>>) {
        let cached = |cache: &Mutex<Option<CachedRouter>>| {
            let cache = cache.lock().unwrap_or_else(PoisonError::into_inner);
            cache
                .as_ref()
                .filter(|(r, s, _)| *r == radius && s == stations)
                .map(|(_, _, router)| router.clone())
        };
        let build = |floor: &[bool]| Arc::new(Router::new(&self.grid, floor, radius, stations));
        let masked = self.robot_obstacles.is_some();
        let (robots, people) = (cached(&self.router), cached(&self.people_router));
        let build_people = masked && people.is_none();
        let (robots, people) = match (robots, build_people) {
            (Some(r), false) => (r, people),
            (Some(r), true) => (r, Some(build(&self.floor))),
            (None, false) => (build(&self.robot_floor), people),
            (None, true) => std::thread::scope(|scope| {
                let people = scope.spawn(|| build(&self.floor));
                let robots = build(&self.robot_floor);
                // A panic building the people's router is the same panic on this thread.
                let people = people
                    .join()
                    .unwrap_or_else(|e| std::panic::resume_unwind(e));
                (robots, Some(people))
            }),
        };
        let keep = |cache: &Mutex<Option<CachedRouter>>, router: &Arc<Router>| {
            *cache.lock().unwrap_or_else(PoisonError::into_inner) =
                Some((radius, stations.to_vec(), router.clone()));
        };
        keep(&self.router, &robots);
        if let Some(people) = &people {
            keep(&self.people_router, people);
        }
        (robots, people)
    }
}

/// How far (in cells) a simplified wall may stray from the floor's edge: one cell, enough to
/// join the ragged edges a scanner leaves (the sample map: 421 walls, against 1,196 within
/// 0.4 of a cell).
pub const SIMPLIFY_CELLS: Real = 1.0;

/// The boundary between free and solid cells (the map's edge counting as solid) as walls:
/// the cells' edges chained into closed loops, each run counter-clockwise round the free
/// space, straight runs joined and simplified (Douglas–Peucker, within [`SIMPLIFY_CELLS`]).
pub fn boundary_walls(grid: &OccupancyGrid, floor: &[bool]) -> Vec<Obstacle> {
    let (w, h) = (grid.width, grid.height);
    let free = |x: isize, y: isize| {
        x >= 0
            && y >= 0
            && (x as usize) < w
            && (y as usize) < h
            && floor[y as usize * w + x as usize]
    };
    // Directed unit edges between grid corners, free cell on the left.
    let corner = |x: isize, y: isize| (y as usize) * (w + 1) + x as usize;
    let mut out_edges: Vec<[u32; 2]> = vec![[u32::MAX; 2]; (w + 1) * (h + 1)];
    let mut edges = 0_usize;
    let mut add = |from: usize, to: usize| {
        let slot = &mut out_edges[from];
        if slot[0] == u32::MAX {
            slot[0] = to as u32;
        } else {
            slot[1] = to as u32;
        }
        edges += 1;
    };
    for y in 0..h as isize {
        for x in 0..w as isize {
            if !free(x, y) {
                continue;
            }
            if !free(x, y - 1) {
                add(corner(x, y), corner(x + 1, y));
            }
            if !free(x + 1, y) {
                add(corner(x + 1, y), corner(x + 1, y + 1));
            }
            if !free(x, y + 1) {
                add(corner(x + 1, y + 1), corner(x, y + 1));
            }
            if !free(x - 1, y) {
                add(corner(x, y + 1), corner(x, y));
            }
        }
    }
    let point = |c: usize| (c % (w + 1), c / (w + 1));
    let mut walls = Vec::new();
    for start in 0..out_edges.len() {
        while out_edges[start][0] != u32::MAX {
            // Follow a loop; where two edges leave a corner (solid cells touching at a
            // corner only), turn left, round the free cell just passed.
            let mut ring = vec![start];
            let mut at = start;
            let mut came: Option<usize> = None;
            loop {
                let slot = out_edges[at];
                let pick = if slot[1] == u32::MAX {
                    0
                } else {
                    let (ax, ay) = point(at);
                    let (px, py) = point(came.unwrap_or(at));
                    let din = (ax as isize - px as isize, ay as isize - py as isize);
                    let (bx, by) = point(slot[0] as usize);
                    let d0 = (bx as isize - ax as isize, by as isize - ay as isize);
                    // Left of `din` is (-dy, dx).
                    if d0 == (-din.1, din.0) { 0 } else { 1 }
                };
                let slot = &mut out_edges[at];
                let next = slot[pick] as usize;
                if pick == 0 {
                    slot[0] = slot[1];
                }
                slot[1] = u32::MAX;
                came = Some(at);
                at = next;
                if at == start {
                    break;
                }
                ring.push(at);
            }
            let pts: Vec<Vec2> = ring
                .iter()
                .map(|&c| {
                    let (x, y) = point(c);
                    grid.origin + vec2(x as Real, y as Real) * grid.resolution
                })
                .collect();
            let kept = simplify_ring(&pts, SIMPLIFY_CELLS * grid.resolution);
            for i in 0..kept.len() {
                walls.push(Obstacle::Wall(kept[i], kept[(i + 1) % kept.len()]));
            }
        }
    }
    walls
}

/// Islands of unknown cells smaller than this (m²) that touch neither the map's edge nor
/// bigger unknown regions are floor: scanner noise, not a wall. (Nav2's planners plan
/// through unknown cells by default.)
pub const UNKNOWN_SPECK_M2: Real = 0.25;

/// The floor: the largest 4-connected region of free cells and unknown specks
/// ([`UNKNOWN_SPECK_M2`]), the first found of equal ones. Free pockets apart from it (inside
/// shelving, behind walls) are unreachable and count as solid.
pub fn main_floor(grid: &OccupancyGrid) -> Vec<bool> {
    let (w, h) = (grid.width, grid.height);
    let speck = (UNKNOWN_SPECK_M2 / (grid.resolution * grid.resolution)).floor() as usize;
    // Unknown regions, labelled; specks become open.
    let unknown = |c: usize| grid.cells[c] == Cell::Unknown;
    let (unknown_label, unknown_sizes, edge) = components(w, h, unknown);
    let open: Vec<bool> = (0..w * h)
        .map(|c| match grid.cells[c] {
            Cell::Free => true,
            Cell::Occupied => false,
            Cell::Unknown => {
                let l = unknown_label[c] as usize;
                unknown_sizes[l] < speck && !edge[l]
            }
        })
        .collect();
    let (label, sizes, _) = components(w, h, |c| open[c]);
    let main = sizes
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.cmp(b.1).then(b.0.cmp(&a.0)))
        .map(|(i, _)| i as u32);
    label.into_iter().map(|l| Some(l) == main).collect()
}

/// The 4-connected regions of the cells `inside` takes: each cell's label (`u32::MAX`
/// outside), each region's size and whether it touches the map's edge.
fn components(
    w: usize,
    h: usize,
    inside: impl Fn(usize) -> bool,
) -> (Vec<u32>, Vec<usize>, Vec<bool>) {
    let mut label = vec![u32::MAX; w * h];
    let (mut sizes, mut edge) = (Vec::new(), Vec::new());
    let mut stack = Vec::new();
    for seed in 0..w * h {
        if !inside(seed) || label[seed] != u32::MAX {
            continue;
        }
        let id = sizes.len() as u32;
        let (mut size, mut touches) = (0_usize, false);
        label[seed] = id;
        stack.push(seed);
        while let Some(c) = stack.pop() {
            size += 1;
            let (x, y) = (c % w, c / w);
            touches |= x == 0 || y == 0 || x + 1 == w || y + 1 == h;
            let around = [
                (x > 0).then(|| c - 1),
                (x + 1 < w).then(|| c + 1),
                (y > 0).then(|| c - w),
                (y + 1 < h).then(|| c + w),
            ];
            for n in around.into_iter().flatten() {
                if inside(n) && label[n] == u32::MAX {
                    label[n] = id;
                    stack.push(n);
                }
            }
        }
        sizes.push(size);
        edge.push(touches);
    }
    (label, sizes, edge)
}

/// A closed ring simplified by Douglas–Peucker within `tolerance`: split at its first point
/// and the point farthest from it, each half simplified as an open line.
fn simplify_ring(ring: &[Vec2], tolerance: Real) -> Vec<Vec2> {
    if ring.len() <= 3 {
        return ring.to_vec();
    }
    let far = (1..ring.len())
        .max_by(|&a, &b| {
            let (da, db) = ((ring[a] - ring[0]).norm(), (ring[b] - ring[0]).norm());
            da.total_cmp(&db).then(b.cmp(&a))
        })
        .unwrap_or(1);
    let mut keep = vec![false; ring.len()];
    keep[0] = true;
    keep[far] = true;
    let closed: Vec<Vec2> = ring
        .iter()
        .chain(std::iter::once(&ring[0]))
        .copied()
        .collect();
    douglas_peucker(&closed, 0, far, tolerance, &mut keep);
    let mut keep_closed = keep.clone();
    keep_closed.push(true);
    douglas_peucker(&closed, far, ring.len(), tolerance, &mut keep_closed);
    keep[far..].copy_from_slice(&keep_closed[far..ring.len()]);
    ring.iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(&p, _)| p)
        .collect()
}

fn douglas_peucker(points: &[Vec2], a: usize, b: usize, tolerance: Real, keep: &mut [bool]) {
    if b <= a + 1 {
        return;
    }
    let (p, q) = (points[a], points[b]);
    let d = q - p;
    let len = d.norm();
    let off = |r: Vec2| {
        if len < 1e-12 {
            (r - p).norm()
        } else {
            (d.x * (r.y - p.y) - d.y * (r.x - p.x)).abs() / len
        }
    };
    let (worst, dist) = (a + 1..b)
        .map(|i| (i, off(points[i])))
        .fold((a + 1, -1.0), |best, c| if c.1 > best.1 { c } else { best });
    if dist > tolerance {
        keep[worst] = true;
        douglas_peucker(points, a, worst, tolerance, keep);
        douglas_peucker(points, worst, b, tolerance, keep);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sample map imports as Nav2's map_server would serve it: black pixels are walls,
    /// white free, grey unknown; row 0 is the image's bottom row; the origin is the
    /// lower-left corner.
    #[test]
    fn the_sample_map_imports_cell_for_cell() {
        let plan = FloorPlan::load("aws-small-warehouse", Path::new(".")).expect("built in");
        let g = &plan.grid;
        assert_eq!(g.resolution, 0.05);
        assert_eq!(g.origin, vec2(-7.0, -10.5));
        // Decode the PNG apart from the loader: its raw 8-bit RGB samples (no alpha), their
        // mean against the YAML's thresholds (occupied_thresh 0.65, free_thresh 0.196).
        let (_, _, _, bytes) = BUILTIN_MAPS[0];
        let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        let mut reader = decoder.read_info().expect("png");
        let mut buf = vec![0; reader.output_buffer_size().expect("size")];
        let frame = reader.next_frame(&mut buf).expect("frame");
        assert_eq!(
            (frame.width as usize, frame.height as usize),
            (g.width, g.height)
        );
        let stride = frame.line_size / frame.width as usize;
        assert_eq!(frame.color_type, png::ColorType::Rgb);
        let mut seen = [0_usize; 3];
        for row in 0..g.height {
            for x in 0..g.width {
                let px = &buf[row * frame.line_size + x * stride..][..3];
                let v = px.iter().map(|&c| Real::from(c)).sum::<Real>() / 3.0;
                let occ = 1.0 - v / 255.0;
                let want = if occ > 0.65 {
                    Cell::Occupied
                } else if occ < 0.196 {
                    Cell::Free
                } else {
                    Cell::Unknown
                };
                let cell = g.at(x, g.height - 1 - row);
                assert_eq!(cell, want, "pixel ({x}, {row}) = {px:?}");
                seen[cell.occupancy().rem_euclid(3) as usize] += 1;
            }
        }
        assert!(
            seen.iter().all(|&n| n > 1000),
            "walls, free and unknown: {seen:?}"
        );
        // The walls follow the floor's edge within the simplification's reach: at every cell
        // of the floor, the distance to the nearest wall is the distance to the nearest cell
        // off the floor (the transform's, centre to centre less half a cell, itself within
        // 0.3 of a cell of the exact one) within 1.3 cells; and two neighbours on the floor
        // that far from its edge see each other.
        let floor = &plan.floor;
        let solid: Vec<bool> = floor.iter().map(|f| !f).collect();
        let edge = router::clearance(&solid, g.width, g.height, g.resolution);
        let map = agent::map::StaticMap::new(plan.obstacles.clone()).expect("valid walls");
        let reach = (SIMPLIFY_CELLS + 0.3) * g.resolution + 1e-9;
        let deep = |x: usize, y: usize| Real::from(edge[y * g.width + x]) > reach;
        let mut checked = 0;
        for y in 0..g.height - 1 {
            for x in 0..g.width - 1 {
                if !floor[y * g.width + x] {
                    continue;
                }
                let c = g.centre(x, y);
                let want = Real::from(edge[y * g.width + x]);
                let got = map.distance(&c);
                assert!((got - want).abs() <= reach, "{c:?}: {got} vs {want}");
                for (nx, ny) in [(x + 1, y), (x, y + 1)] {
                    if deep(x, y) && deep(nx, ny) {
                        assert!(map.line_of_sight(c, g.centre(nx, ny)), "{c:?}");
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 10_000, "{checked} pairs");
        assert!(
            plan.obstacles.len() < 1000,
            "{} walls",
            plan.obstacles.len()
        );
    }

    /// An unknown speck in the floor is floor; an unknown region as large as the speck limit,
    /// or one touching the map's edge, is not; nor is a free pocket apart from the floor.
    #[test]
    fn unknown_specks_are_floor_and_pockets_are_not() {
        // 40 × 20 cells of 0.1 m: free, with a 2-cell unknown speck, a 5 × 5 unknown block
        // (0.25 m²), an unknown strip along the left edge, and a walled free pocket.
        let mut cells = vec![Cell::Free; 40 * 20];
        let mut set = |x: usize, y: usize, c: Cell| cells[y * 40 + x] = c;
        set(10, 10, Cell::Unknown);
        set(11, 10, Cell::Unknown);
        for y in 2..7 {
            for x in 20..25 {
                set(x, y, Cell::Unknown);
            }
        }
        for y in 0..20 {
            set(0, y, Cell::Unknown);
        }
        for y in 12..18 {
            for x in 30..38 {
                let edge = y == 12 || y == 17 || x == 30 || x == 37;
                set(x, y, if edge { Cell::Occupied } else { Cell::Free });
            }
        }
        let grid = OccupancyGrid {
            width: 40,
            height: 20,
            resolution: 0.1,
            origin: vec2(0.0, 0.0),
            cells,
        };
        let floor = main_floor(&grid);
        let at = |x: usize, y: usize| floor[y * 40 + x];
        assert!(at(10, 10) && at(11, 10) && at(5, 5), "speck and floor");
        assert!(!at(22, 4), "a block of 0.25 m² is solid");
        assert!(!at(0, 5), "unknown on the edge is solid");
        assert!(!at(33, 14), "a walled pocket is off the floor");
    }

    #[test]
    fn an_unknown_map_name_is_refused_naming_the_built_ins() {
        let err = FloorPlan::load("nowhere", Path::new(".")).expect_err("unknown");
        assert!(err.to_string().contains("aws-small-warehouse"), "{err}");
    }
}
