//! Where a fleet's robots lose speed: one in-process fleet run (policy and layer on, as the
//! traffic study runs it), and for every robot-step with a task how far below top speed the
//! robot was, split into what its planner wanted without the safe set (a shadow stack planning
//! on the same observations with no layer), what planning inside the safe set and the layer's
//! check took off that, and what the base's limits left unexecuted; binned by the nearest person
//! and robot.
//!
//!     cargo run --release -p world-sim --example speed_budget -- SCENARIO ROBOTS SEEDS \
//!         [SECONDS [PLANNER]]
//!
//! SCENARIO is a built-in's name or a scenario file (`….toml`); SEEDS is `a-b`. The shadow
//! stacks only watch: their commands are never executed. The environment variable `LAYER`
//! changes the layer's parameters (`key=value,…`, as `--safety-layer` does).

use agent::math::Vec2;
use agent::model::{AgentKind, Command, Neighbour};
use agent::planner::{PlannerSpec, PlanningInput};
use agent::safety::Zone;
use world_sim::fleet::{Fleet, plan_all, stacks as stacks_for};
use world_sim::scenario::Scenario;
use world_sim::traffic_policy::PolicyParams;

/// Speed lost, summed over robot-steps, per part.
#[derive(Debug, Default, Clone, Copy)]
struct Loss {
    steps: f64,
    planner: f64,
    layer: f64,
    base: f64,
    warned: f64,
    protective: f64,
    yielded: f64,
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map_or("warehouse", String::as_str);
    let robots: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(8);
    let (first, last): (u64, u64) = args
        .get(2)
        .and_then(|a| a.split_once('-'))
        .map_or((1, 3), |(a, b)| {
            (a.parse().expect("a seed"), b.parse().expect("a seed"))
        });
    let seconds: f64 = args.get(3).and_then(|a| a.parse().ok()).unwrap_or(300.0);
    let planner: PlannerSpec = args
        .get(4)
        .map_or("pgp+orca", String::as_str)
        .parse()
        .expect("a known planner");
    // Bins: nearest person < 1.5 m, 1.5–3 m, farther (or none); and whether a robot is within 2 m.
    let labels = [
        "person < 1.5 m, standing",
        "person < 1.5 m, walking its way",
        "person < 1.5 m, coming at it",
        "person < 1.5 m, crossing",
        "person 1.5-3 m",
        "person > 3 m, robot < 2 m",
        "nobody within 3 / 2 m",
    ];
    let mut bins = [Loss::default(); 7];
    // The same losses within 3 m of the station the leg ends at, and farther.
    let mut at_station = [Loss::default(); 2];
    let mut tasks = 0;
    for seed in first..=last {
        let mut scenario = Scenario::load(name)
            .expect("a built-in scenario or a scenario file")
            .0;
        scenario.seed = seed;
        scenario.set_fleet_size(Some(robots), None);
        if let Ok(overrides) = std::env::var("LAYER") {
            scenario.robot.safety_layer = scenario
                .robot
                .safety_layer
                .with_overrides(&overrides)
                .expect("LAYER: key=value,… of the safety layer's parameters");
        }
        let mut fleet = Fleet::new(&scenario).expect("a fleet site");
        fleet.set_traffic_policy(Some(PolicyParams::default()));
        let max_speed = scenario.robot.max_speed;
        let mut stacks = stacks_for(&fleet, planner, max_speed);
        let mut shadows = stacks_for(&fleet, planner, max_speed);
        let mut guards = world_sim::episode::fleet_guards(&scenario, &fleet);
        let mut commands = vec![Command::STOP; robots];
        let steps = (seconds / fleet.world.dt).round() as u64;
        for _ in 0..steps {
            // As `world_sim::fleet::drive` does, with the shadow planner beside each robot's.
            fleet.dispatch();
            let stations: Vec<Option<Vec2>> = (0..robots)
                .map(|i| {
                    let site = fleet.world.site()?;
                    Some(site.stations[fleet.job(i)?.station()].position)
                })
                .collect();
            let mut rows = Vec::new();
            let mut held = vec![false; robots];
            plan_all(&mut fleet, &mut stacks, &mut commands, |i, stack, input| {
                let free = speed(shadows[i].plan(input).command).min(max_speed);
                let (plan, zone) = match &mut guards[i] {
                    Some(g) => {
                        let (plan, guarded) = g.plan(stack, input);
                        (plan, guarded.zone)
                    }
                    None => (stack.plan(input), Zone::Clear),
                };
                held[i] = matches!(zone, Zone::Protective | Zone::Yield);
                let bin = bin_of(input);
                let here = input.ego.position;
                let near = stations[i].is_some_and(|q| (q - here).norm() < 3.0);
                rows.push((i, bin, near, free, speed(plan.command), zone));
                plan
            });
            for (i, &held) in held.iter().enumerate() {
                fleet.set_layer_held(i, held);
            }
            fleet.step(&commands);
            for (i, bin, near, free, commanded, zone) in rows {
                let v = fleet.world.robots[i].state.velocity.norm();
                for b in [&mut bins[bin], &mut at_station[usize::from(near)]] {
                    add(b, max_speed, free, commanded, v, zone);
                }
            }
        }
        tasks += (0..robots).map(|i| fleet.tasks_done(i)).sum::<u64>();
    }
    println!(
        "{name}, {robots} robots, seeds {first}-{last}, {seconds} s, {planner}: {tasks} tasks"
    );
    print(&bins, &labels, &at_station);
}

/// The bin of a robot-step (see `main`'s labels): by the nearest person it perceives, how
/// they walk against the robot's way to its goal, and the nearest robot.
fn bin_of(input: &PlanningInput<'_>) -> usize {
    let here = input.ego.position;
    let distance = |n: &&Neighbour| (n.position - here).norm();
    let nearest = input
        .neighbours
        .iter()
        .filter(|n| n.kind == AgentKind::Human)
        .min_by(|a, b| distance(a).total_cmp(&distance(b)));
    let person = nearest.map_or(f64::INFINITY, |n| distance(&n));
    let robot = input
        .neighbours
        .iter()
        .filter(|n| n.kind == AgentKind::Robot)
        .map(|n| distance(&n))
        .fold(f64::INFINITY, f64::min);
    if person < 1.5 {
        let way = input.goal - here;
        let way = if way.norm() > 1e-6 {
            way / way.norm()
        } else {
            way
        };
        let v = nearest.map_or(Vec2::zeros(), |n| n.velocity);
        if v.norm() < 0.2 {
            0
        } else if v.dot(&way) > 0.5 * v.norm() {
            1
        } else if v.dot(&way) < -0.5 * v.norm() {
            2
        } else {
            3
        }
    } else if person < 3.0 {
        4
    } else if robot < 2.0 {
        5
    } else {
        6
    }
}

/// Adds one robot-step's losses (speed below `max_speed`) to `b`.
fn add(b: &mut Loss, max_speed: f64, free: f64, commanded: f64, v: f64, zone: Zone) {
    b.steps += 1.0;
    b.planner += (max_speed - free) / max_speed;
    let layer = (free - commanded).max(0.0) / max_speed;
    b.layer += layer;
    b.base += (commanded - v).max(0.0) / max_speed;
    match zone {
        Zone::Warning => b.warned += layer,
        Zone::Protective => b.protective += layer,
        Zone::Yield => b.yielded += layer,
        Zone::Clear => {}
    }
}

/// Prints the table: each bin's losses in points of top speed over all robot-steps.
fn print(bins: &[Loss], labels: &[&str], at_station: &[Loss; 2]) {
    let total: f64 = bins.iter().map(|b| b.steps).sum();
    println!(
        "| where | share of task time | planner (no layer) | safe set and layer | of it warned / protective / yield / clear | base | total |"
    );
    println!("|---|---:|---:|---:|---|---:|---:|");
    let mut sum = Loss::default();
    for (b, label) in bins.iter().zip(labels) {
        let share = b.steps / total;
        let per = |x: f64| 100.0 * x / total;
        println!(
            "| {label} | {:.0} % | {:.1} | {:.1} | {:.1} / {:.1} / {:.1} / {:.1} | {:.1} | {:.1} |",
            100.0 * share,
            per(b.planner),
            per(b.layer),
            per(b.warned),
            per(b.protective),
            per(b.yielded),
            per(b.layer - b.warned - b.protective - b.yielded),
            per(b.base),
            per(b.planner + b.layer + b.base),
        );
        sum.planner += b.planner;
        sum.layer += b.layer;
        sum.base += b.base;
    }
    let per = |x: f64| 100.0 * x / total;
    println!(
        "| all | 100 % | {:.1} | {:.1} | | {:.1} | {:.1} |",
        per(sum.planner),
        per(sum.layer),
        per(sum.base),
        per(sum.planner + sum.layer + sum.base)
    );
    for (b, label) in at_station.iter().zip([
        "farther than 3 m from its station",
        "within 3 m of its station",
    ]) {
        println!(
            "| {label} | {:.0} % | {:.1} | {:.1} | | {:.1} | {:.1} |",
            100.0 * b.steps / total,
            per(b.planner),
            per(b.layer),
            per(b.base),
            per(b.planner + b.layer + b.base)
        );
    }
    println!("(points of top speed over all robot-steps with a task)");
}

/// A command's speed (m/s).
fn speed(c: Command) -> f64 {
    match c {
        Command::Velocity(v) => v.norm(),
        Command::Unicycle { speed, .. } => speed.abs(),
    }
}
