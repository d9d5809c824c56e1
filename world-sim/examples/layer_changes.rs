//! How often, and how much, the safety layer changes each planner's commands: every planner in
//! the open-space scenario at a few densities and seeds, once planning inside the layer's safe
//! set (`Guard::plan`, as shipped) and once ignoring it (`Guard::check` on the planner's own
//! command), with the goals reached and the contacts of every cause beside it.
//!
//!     cargo run --release -p world-sim --example layer_changes [seeds] [densities] [planners]
//!
//! Defaults: seeds 1–10, densities 0.1,0.3,0.5 (people per m²), tuning seeds of the
//! open-space study, every planner below.

use agent::guard::Guard;
use agent::model::Command;
use agent::planner::{PlannerSpec, PlannerStack, PlanningInput};
use world_sim::metrics::MetricsRecorder;
use world_sim::scenario::Scenario;
use world_sim::world::World;

const PLANNERS: [&str; 10] = [
    "dwa", "orca", "sf", "pgp+dwa", "pgp+orca", "pgp+sf", "foigp", "pnp", "asfm", "pgp+pnp",
];

/// What one run of one planner did.
#[derive(Debug, Default, Clone, Copy)]
struct Tally {
    runs: u64,
    reached: u64,
    checked: u64,
    changed: u64,
    yielded: u64,
    change_sum: f64,
    robot_caused: u64,
    total_contacts: u64,
}

impl Tally {
    fn plus(self, o: Tally) -> Tally {
        Tally {
            runs: self.runs + o.runs,
            reached: self.reached + o.reached,
            checked: self.checked + o.checked,
            changed: self.changed + o.changed,
            yielded: self.yielded + o.yielded,
            change_sum: self.change_sum + o.change_sum,
            robot_caused: self.robot_caused + o.robot_caused,
            total_contacts: self.total_contacts + o.total_contacts,
        }
    }
}

fn run(spec: PlannerSpec, density: f64, seed: u64, inside: bool) -> Tally {
    let mut scenario = Scenario::builtin("open-space").expect("built-in");
    if let Some(open) = scenario.open_space.as_mut() {
        open.density = density;
    }
    scenario.seed = seed;
    let mut world = World::from_scenario(&scenario);
    let mut stack = PlannerStack::with_max_speed(spec, scenario.robot.max_speed);
    stack.set_record_fan(false);
    let mut guard = Guard::with_params(
        scenario.robot.safety_limits(scenario.dt_s),
        scenario.robot.safety_layer,
    );
    let mut recorder = MetricsRecorder::new(&world, 0);
    let steps = (scenario.max_time_s / scenario.dt_s).round() as u64;
    let mut local = agent::map::LocalMap::default();
    for _ in 0..steps {
        if recorder.arrived() {
            break;
        }
        let (ego, seen) = world.observe(0);
        let profile = world.visibility(0, &mut local);
        let input = PlanningInput {
            ego: &ego,
            neighbours: &seen,
            map: &world.map,
            goal: world.robots[0].goal,
            dt: world.dt,
            visibility: profile.as_ref(),
            safety: None,
        };
        let command: Command = if inside {
            guard.plan(&mut stack, &input).0.command
        } else {
            let planned = stack.plan(&input).command;
            guard.check(planned, &input).command
        };
        world.step(&[command]);
        recorder.record(&world);
    }
    let m = recorder.finish();
    Tally {
        runs: 1,
        reached: u64::from(m.success),
        checked: guard.checked,
        changed: guard.changed(),
        yielded: guard.yielded,
        change_sum: guard.change_sum,
        robot_caused: m.robot_caused_contacts,
        total_contacts: m.total_contacts(),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let seeds: u64 = args.first().and_then(|a| a.parse().ok()).unwrap_or(10);
    let densities: Vec<f64> = args
        .get(1)
        .map(|a| a.split(',').filter_map(|d| d.parse().ok()).collect())
        .unwrap_or_else(|| vec![0.1, 0.3, 0.5]);
    let planners: Vec<&str> = args
        .get(2)
        .map_or(PLANNERS.to_vec(), |a| a.split(',').collect());
    println!(
        "open space, densities {densities:?}, seeds 1–{seeds}: planning inside the safe set / ignoring it\n"
    );
    println!(
        "| planner | runs | reached | commands changed | of which yields | mean change (m/s) | robot-caused | total contacts |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for name in planners {
        let Ok(spec) = name.parse::<PlannerSpec>() else {
            eprintln!("unknown planner {name:?}");
            std::process::exit(2);
        };
        let tally = |inside: bool| {
            let cells: Vec<(f64, u64)> = densities
                .iter()
                .flat_map(|&d| (1..=seeds).map(move |s| (d, s)))
                .collect();
            // Two threads, each a half of the cells; the sum does not depend on the split.
            let (left, right) = cells.split_at(cells.len() / 2);
            let half = |part: &[(f64, u64)]| {
                part.iter()
                    .map(|&(d, s)| run(spec, d, s, inside))
                    .fold(Tally::default(), Tally::plus)
            };
            std::thread::scope(|scope| {
                let other = scope.spawn(|| half(right));
                let mine = half(left);
                mine.plus(other.join().expect("no panic"))
            })
        };
        let (a, b) = (tally(true), tally(false));
        let pct = |n: u64, of: u64| 100.0 * n as f64 / of.max(1) as f64;
        let mean = |t: &Tally| t.change_sum / t.changed.max(1) as f64;
        println!(
            "| {name} | {} | {:.0}% / {:.0}% | {:.1}% / {:.1}% | {:.1}% / {:.1}% | {:.2} / {:.2} | {} / {} | {} / {} |",
            a.runs,
            pct(a.reached, a.runs),
            pct(b.reached, b.runs),
            pct(a.changed, a.checked),
            pct(b.changed, b.checked),
            pct(a.yielded, a.checked),
            pct(b.yielded, b.checked),
            mean(&a),
            mean(&b),
            a.robot_caused,
            b.robot_caused,
            a.total_contacts,
            b.total_contacts,
        );
    }
}
