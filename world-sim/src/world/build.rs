//! Building a world from a scenario: the layouts (open stage, hallway, laned hallway,
//! warehouse site), robots placed, people spawned in groups clear of walls and robots.

use super::*;

impl World {
    /// The world a scenario describes.
    pub fn from_scenario(scenario: &Scenario) -> Self {
        if let Some(hall) = &scenario.hallway
            && let Some(robots) = hall.robots
        {
            // A fleet hallway: a site with stations at both ends, robots along the centre line.
            let site = Site::hallway(hall.length_m, hall.width_m, hall.stations());
            let robots = in_a_row(robots, hall.length_m, hall.width_m / 2.0);
            let mut layout = site_layout(scenario, &site, robots, hall.humans, hall.max_group_size);
            // People walk to points anywhere on the hallway's floor (`GoalRule::Anywhere`), not
            // to the stations, which are the robots'.
            layout.people_to_stations = false;
            // Robots stand every length/N along the centre line (2 m for 20 in 40 m), where the
            // usual 1.5 m would leave no room for anyone.
            layout.robot_clearance = scenario.robot.radius_m + scenario.humans.radius_m + 0.2;
            return Self::build_with_site(scenario, layout, Some(site));
        }
        if let Some(hall) = &scenario.hallway {
            let (length, width) = (hall.length_m, hall.width_m);
            // Walled along both sides, and closed HALLWAY_END_ROOM_M beyond the end behind
            // the robot's start and, unless people walk out of it in lanes, beyond the far end:
            // open ends let a robot pushed back at its start leave the hallway and drive its
            // length outside, where nobody walks (3–4 of 30 runs at 25 m in the hallway
            // study, every planner). People turn back a metre inside the ends, out of the end
            // walls' reach.
            let (start, end) = (
                -HALLWAY_END_ROOM_M,
                if hall.lanes.is_none() {
                    length + HALLWAY_END_ROOM_M
                } else {
                    length
                },
            );
            let mut walls = vec![
                Obstacle::Wall(vec2(start, 0.0), vec2(end, 0.0)),
                Obstacle::Wall(vec2(start, width), vec2(end, width)),
                Obstacle::Wall(vec2(start, 0.0), vec2(start, width)),
            ];
            if hall.lanes.is_none() {
                walls.push(Obstacle::Wall(vec2(end, 0.0), vec2(end, width)));
            }
            let map = StaticMap::new(walls).expect("straight walls of positive length are valid");
            let margin = (scenario.humans.radius_m + 0.05).min(width / 2.0);
            let layout = Layout {
                spawn_min: vec2(END_MARGIN_M, margin),
                spawn_max: vec2(length - END_MARGIN_M, width - margin),
                map,
                robots: vec![(
                    vec2(END_MARGIN_M, width / 2.0),
                    vec2(length - END_MARGIN_M, width / 2.0),
                )],
                goals: GoalRule::OppositeEnd,
                people: hall.humans,
                max_group_size: hall.max_group_size,
                avoid_obstacles: false,
                people_to_stations: false,
                robot_clearance: ROBOT_CLEARANCE_M,
            };
            let mut world = Self::build(scenario, layout);
            if let Some(lanes) = hall.lanes {
                world.keep_lanes(scenario, lanes, length, width);
            }
            return world;
        }
        if let Some(plan) = &scenario.floor_plan
            && let Some(site) = Site::floor_plan(plan, scenario.robot.radius_m)
        {
            let robots = plan
                .starts(scenario.robot.radius_m)
                .into_iter()
                .map(|p| (p, p))
                .collect();
            let layout = site_layout(scenario, &site, robots, plan.humans, plan.max_group_size);
            return Self::build_with_site(scenario, layout, Some(site));
        }
        if let Some(spec) = &scenario.warehouse {
            let site = Site::generate(spec);
            let robots = in_a_row(spec.robots, site.size.x, site.stations[0].position.y);
            let layout = site_layout(scenario, &site, robots, spec.humans, spec.max_group_size);
            return Self::build_with_site(scenario, layout, Some(site));
        }
        Self::open_space(scenario)
    }

    /// The PGP paper's open stage with one robot crossing it from the middle of the left edge
    /// to the middle of the right edge; people in groups of 1..=max_group_size between random
    /// goals on the stage.
    pub fn open_space(scenario: &Scenario) -> Self {
        let open = scenario
            .open_space
            .expect("validated scenarios have a layout");
        let size = open.size_m;
        let map = match open.walls_margin_m {
            None => StaticMap::empty(),
            Some(m) => {
                let (lo, hi) = (-m, size + m);
                let corners = [vec2(lo, lo), vec2(hi, lo), vec2(hi, hi), vec2(lo, hi)];
                let walls = (0..4)
                    .map(|i| Obstacle::Wall(corners[i], corners[(i + 1) % 4]))
                    .collect();
                StaticMap::new(walls).expect("a square of positive size is valid")
            }
        };
        let layout = Layout {
            spawn_min: vec2(0.0, 0.0),
            spawn_max: vec2(size, size),
            map,
            robots: vec![(vec2(0.0, size / 2.0), vec2(size, size / 2.0))],
            goals: GoalRule::Anywhere,
            people: scenario.human_count(),
            max_group_size: open.max_group_size,
            avoid_obstacles: false,
            people_to_stations: false,
            robot_clearance: ROBOT_CLEARANCE_M,
        };
        Self::build(scenario, layout)
    }

    fn build(scenario: &Scenario, layout: Layout) -> Self {
        Self::build_with_site(scenario, layout, None)
    }

    fn build_with_site(scenario: &Scenario, layout: Layout, site: Option<Site>) -> Self {
        let (min, max) = (layout.spawn_min, layout.spawn_max);
        let robots: Vec<RobotBody> = layout
            .robots
            .iter()
            .map(|&(start, goal)| RobotBody::new(start, goal, scenario.robot))
            .collect();
        let starts: Vec<Vec2> = layout.robots.iter().map(|r| r.0).collect();
        let mut spawn = stream(scenario.seed, SPAWN_STREAM);
        let mut goal_rng = stream(scenario.seed, GOAL_STREAM);
        let h = &scenario.humans;
        let n = layout.people;

        let (mut positions, mut goals, mut offsets, mut groups, mut routes) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let min_gap = 2.0 * h.radius_m + 0.05;
        while positions.len() < n {
            let size_left = n - positions.len();
            let members = spawn.random_range(1..=layout.max_group_size.min(size_left));
            let mut centre = uniform(&mut spawn, min, max);
            for _ in 0..100 {
                if !layout.avoid_obstacles
                    || layout.map.distance(&centre) >= h.radius_m + 0.05
                        && !layout.map.is_inside(&centre)
                        && site.as_ref().is_none_or(|s| s.walkable(centre, h.radius_m))
                {
                    break;
                }
                centre = uniform(&mut spawn, min, max);
            }
            let stations = site.as_ref().filter(|_| layout.people_to_stations);
            let (group_goal, route) = match stations {
                Some(site) => {
                    let station = goal_rng.random_range(0..site.stations.len());
                    let mut route: VecDeque<Vec2> = site
                        .people_route(centre, site.stations[station].position)
                        .into();
                    let first = route.pop_front().unwrap_or(centre);
                    (first, route)
                }
                None => (layout.goals.first(&mut goal_rng, min, max), VecDeque::new()),
            };
            let mut group = Vec::new();
            for _ in 0..members {
                // Rejection sampling near the group's centre, then anywhere.
                let mut placed = None;
                for attempt in 0..200 {
                    let p = if attempt < 50 {
                        centre + disc(&mut spawn, GROUP_SPREAD_M * 1.5)
                    } else {
                        uniform(&mut spawn, min, max)
                    };
                    let inside = p.x >= min.x && p.y >= min.y && p.x <= max.x && p.y <= max.y;
                    let free = positions.iter().all(|q: &Vec2| (q - p).norm() >= min_gap)
                        && starts
                            .iter()
                            .all(|s| (p - s).norm() >= layout.robot_clearance)
                        && (!layout.avoid_obstacles
                            || (!layout.map.is_inside(&p)
                                && layout.map.distance(&p) >= h.radius_m + 0.05
                                && site.as_ref().is_none_or(|s| s.walkable(p, h.radius_m))));
                    if inside && free {
                        placed = Some(p);
                        break;
                    }
                }
                let Some(p) = placed else { break };
                let offset = disc(&mut spawn, GROUP_SPREAD_M);
                group.push(positions.len());
                positions.push(p);
                offsets.push(offset);
                goals.push(clamp_box(group_goal + offset, min, max));
            }
            if group.is_empty() {
                break; // The stage is full; fewer people than asked.
            }
            groups.push(group);
            routes.push(route);
        }
        // PySocialForce derives each person's maximum speed from the initial speed.
        let velocities: Vec<Vec2> = positions
            .iter()
            .zip(&goals)
            .map(|(p, g): (&Vec2, &Vec2)| {
                let d = g - p;
                if d.norm() > 1e-9 {
                    d / d.norm() * h.speed
                } else {
                    unit(0.0) * h.speed
                }
            })
            .collect();
        let sf = SfParams {
            step_width: scenario.dt_s,
            agent_radius: h.radius_m,
            interaction_range: h.interaction_range_m,
            ..SfParams::default()
        };
        let groups_len = groups.len();
        let mut crowd = Crowd::new(positions, velocities, goals, groups, &sf);
        if h.react_share < 1.0 {
            let mut draw = stream(scenario.seed, REACT_STREAM);
            crowd.ignores_externals = (0..crowd.len())
                .map(|_| draw.random::<Real>() >= h.react_share)
                .collect();
        }
        // Indexed: a warehouse has tens of thousands of wall points, and a person feels only
        // those within the obstacle threshold (exact, see `Walls::indexed`).
        let mut walls = Walls::from(layout.map.sampled_points(sf.resolution).into_owned())
            .indexed(sf.obstacle.threshold + 2.0 * sf.agent_radius);
        if h.walls == WallModel::Field {
            walls = walls.with_field(sf.agent_radius, &sf.obstacle, h.wall_field_spacing_m);
        }
        World {
            time: 0.0,
            step: 0,
            dt: scenario.dt_s,
            map: layout.map,
            humans: Humans {
                crowd,
                offsets,
                radius: h.radius_m,
                react_to_robots: h.react_to_robots,
            },
            robots,
            sf,
            walls,
            stage_min: min,
            stage_max: max,
            goal_rule: layout.goals,
            people_to_stations: layout.people_to_stations,
            regoal_stalled: h
                .regoal_stalled_s
                .filter(|_| site.is_some())
                .map(|after| (after, vec![(Real::INFINITY, 0.0); groups_len])),
            site,
            routes,
            lanes: Vec::new(),
            lanes_end: 0.0,
            goal_rng,
            seed: scenario.seed,
            scratch: Vec::new(),
            externals: Vec::new(),
        }
    }

    /// Puts everyone in one of `lanes` lanes along +x, alone, walking out of the far end of a
    /// `length` × `width` hallway at their own speed (½–1½ × the scenario's), spaced along
    /// each lane by at least a body and a margin; inside the hallway they keep to the lane.
    fn keep_lanes(&mut self, scenario: &Scenario, lanes: usize, length: Real, width: Real) {
        let mut rng = stream(scenario.seed, LANE_STREAM);
        let crowd = &mut self.humans.crowd;
        let n = crowd.positions.len();
        let lane_y = |lane: usize| width * (lane as Real + 0.5) / lanes as Real;
        let min_gap = 2.0 * self.humans.radius + 0.05;
        // Nearest lane, then spaced along it in order of x.
        let mut order: Vec<(usize, Real, usize)> = (0..n)
            .map(|i| {
                let p = crowd.positions[i];
                let lane = ((p.y / width * lanes as Real).floor() as usize).min(lanes - 1);
                (lane, p.x, i)
            })
            .collect();
        order.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)).then(a.2.cmp(&b.2)));
        let mut last: Option<(usize, Real)> = None;
        for (lane, x, i) in order {
            let x = match last {
                Some((l, prev)) if l == lane => x.max(prev + min_gap),
                _ => x,
            };
            last = Some((lane, x));
            let speed = scenario.humans.speed * rng.random_range(0.5..=1.5);
            crowd.positions[i] = vec2(x, lane_y(lane));
            crowd.velocities[i] = vec2(speed, 0.0);
            crowd.max_speeds[i] = speed * self.sf.max_speed_multiplier;
            // Far beyond the open end: nobody turns back during a trial.
            crowd.goals[i] = vec2(length + 1000.0, lane_y(lane));
        }
        crowd.groups = (0..n).map(|i| vec![i]).collect();
        self.humans.offsets = vec![Vec2::zeros(); n];
        self.routes = vec![VecDeque::new(); n];
        self.lanes = crowd.goals.iter().map(|g| g.y).collect();
        self.lanes_end = length;
    }
}

/// What a layout contributes to a world.
struct Layout {
    spawn_min: Vec2,
    spawn_max: Vec2,
    map: StaticMap,
    /// Start and first goal of each robot.
    robots: Vec<(Vec2, Vec2)>,
    goals: GoalRule,
    people: usize,
    max_group_size: usize,
    /// Keep people from spawning inside or against obstacles (shelves).
    avoid_obstacles: bool,
    /// With a site: people walk between its stations (a warehouse); else by `goals` (a fleet
    /// hallway, where the stations are the robots').
    people_to_stations: bool,
    /// People do not spawn closer than this to a robot's start (m).
    robot_clearance: Real,
}

/// `n` robots standing evenly along y = `y`, each in the middle of its `length`/`n` (start
/// and first goal the same).
fn in_a_row(n: usize, length: Real, y: Real) -> Vec<(Vec2, Vec2)> {
    (0..n)
        .map(|i| {
            let p = vec2(length * (i as Real + 0.5) / n as Real, y);
            (p, p)
        })
        .collect()
}

/// A fleet site's layout: people spawn anywhere on it clear of shelves and walls and walk
/// between its stations; the robots at `robots`.
fn site_layout(
    scenario: &Scenario,
    site: &Site,
    robots: Vec<(Vec2, Vec2)>,
    people: usize,
    max_group_size: usize,
) -> Layout {
    let margin = scenario.humans.radius_m + 0.05;
    Layout {
        spawn_min: site.origin + vec2(margin, margin),
        spawn_max: site.origin + site.size - vec2(margin, margin),
        map: site.map(),
        robots,
        // Unused while people walk between the site's stations.
        goals: GoalRule::Anywhere,
        people,
        max_group_size,
        avoid_obstacles: true,
        people_to_stations: true,
        robot_clearance: ROBOT_CLEARANCE_M,
    }
}

fn disc(rng: &mut ChaCha8Rng, radius: Real) -> Vec2 {
    let r = radius * rng.random::<Real>().sqrt();
    unit(rng.random_range(0.0..std::f64::consts::TAU)) * r
}
