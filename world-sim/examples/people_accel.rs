//! How hard people change their motion, along their way and across it: the simulated people
//! of a fleet site (pgp+orca robots under the safety layer) and the recorded crowds. The
//! safety layer's a_h (`SafetyParams::person_accel`) bounds a person's swerve in every
//! direction alike; this prints whether people turn as hard as they speed up and brake.
//!
//!     cargo run --release -p world-sim --example people_accel -- SCENARIO SEEDS SECONDS \
//!         [RECORDING_DIR ...]
//!
//! A person's acceleration over one step, (v₁ − v₀)/Δt, is split along v₀ and across it; only
//! people walking at 0.3 m/s or more at the step's start count (a standing person has no
//! "along"). "Near" is within 3 m of a robot's centre. Recorded crowds are annotated every
//! 0.4 s, so their accelerations are 0.4 s means: smoother than the simulator's 0.1 s steps.
//!
//! What the layer's check bounds is not the acceleration but the **stray**: how far a person
//! ends up from where walking on at constant velocity would have put them, after t seconds;
//! the layer allows ½·a_h·t². Each stray d is printed as the acceleration that would explain
//! it, 2d/t², for several t, for everyone (of any speed) near a robot at the start.

use agent::guard::Guard;
use agent::math::{Real, Vec2};
use agent::model::Command;
use agent::planner::PlannerStack;
use world_sim::dataset::Recording;
use world_sim::fleet::{Fleet, plan_all};
use world_sim::scenario::Scenario;

/// Accelerations along and across, in m/s².
#[derive(Default)]
struct Split {
    along: Vec<Real>,
    across: Vec<Real>,
    total: Vec<Real>,
}

impl Split {
    fn add(&mut self, v0: Vec2, v1: Vec2, dt: Real) {
        let speed = v0.norm();
        if speed < 0.3 {
            return;
        }
        let a = (v1 - v0) / dt;
        let u = v0 / speed;
        self.along.push(a.dot(&u).abs());
        self.across.push((a.x * u.y - a.y * u.x).abs());
        self.total.push(a.norm());
    }

    fn print(&mut self, what: &str) {
        let n = self.total.len();
        let q = |v: &mut Vec<Real>, p: Real| -> Real {
            if v.is_empty() {
                return Real::NAN;
            }
            v.sort_by(Real::total_cmp);
            v[((v.len() - 1) as Real * p).round() as usize]
        };
        let mut line = format!("{what}: {n} person-steps |");
        for (name, v) in [
            ("along", &mut self.along),
            ("across", &mut self.across),
            ("total", &mut self.total),
        ] {
            line += &format!(
                " {name} p50 {:.2} p99 {:.2} p99.9 {:.2} |",
                q(v, 0.5),
                q(v, 0.99),
                q(v, 0.999)
            );
        }
        println!("{line}");
    }
}

/// Strays from constant velocity, as 2d/t² (m/s²), per horizon.
struct Strays {
    horizons: Vec<Real>,
    effective: Vec<Vec<Real>>,
    /// The stray's part across the way a person walked (0.3 m/s or more) at the start.
    across: Vec<Vec<Real>>,
}

impl Strays {
    fn new(horizons: &[Real]) -> Self {
        Self {
            horizons: horizons.to_vec(),
            effective: vec![Vec::new(); horizons.len()],
            across: vec![Vec::new(); horizons.len()],
        }
    }

    fn add(&mut self, k: usize, p0: Vec2, v0: Vec2, p: Vec2) {
        let t = self.horizons[k];
        let stray = p - p0 - v0 * t;
        self.effective[k].push(2.0 * stray.norm() / (t * t));
        let speed = v0.norm();
        if speed >= 0.3 {
            let across = (stray.x * v0.y - stray.y * v0.x).abs() / speed;
            self.across[k].push(2.0 * across / (t * t));
        }
    }

    fn print(&mut self, what: &str) {
        let mut line = format!("{what}: stray as 2d/t² |");
        for ((t, v), a) in self
            .horizons
            .iter()
            .zip(&mut self.effective)
            .zip(&mut self.across)
        {
            if v.is_empty() || a.is_empty() {
                continue;
            }
            v.sort_by(Real::total_cmp);
            a.sort_by(Real::total_cmp);
            let q = |v: &[Real], p: Real| v[((v.len() - 1) as Real * p).round() as usize];
            line += &format!(
                " t {t:.1} s ({}): p99 {:.2} p99.9 {:.2} max {:.2}, across p99 {:.2} p99.9 {:.2} max {:.2} |",
                v.len(),
                q(v, 0.99),
                q(v, 0.999),
                v[v.len() - 1],
                q(a, 0.99),
                q(a, 0.999),
                a[a.len() - 1]
            );
        }
        println!("{line}");
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scenario_name = args.first().map_or("warehouse", String::as_str);
    let seeds: u64 = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(5);
    let seconds: Real = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(300.0);
    let (mut all, mut near) = (Split::default(), Split::default());
    // Horizons in simulator steps (0.1 s).
    let steps = [2usize, 5, 9, 15];
    let mut strays = Strays::new(&steps.map(|k| k as Real * 0.1));
    for seed in 1..=seeds {
        let mut scenario = Scenario::builtin(scenario_name).expect("a built-in scenario");
        scenario.seed = seed;
        let mut fleet = Fleet::new(&scenario).expect("a fleet site");
        let n = fleet.robots();
        let limits = scenario.robot.safety_limits(scenario.dt_s);
        let mut stacks: Vec<PlannerStack> = (0..n)
            .map(|_| PlannerStack::new("pgp+orca".parse().expect("known")))
            .collect();
        let mut guards = vec![Guard::new(limits); n];
        let mut commands = vec![Command::STOP; n];
        let dt = scenario.dt_s;
        assert!((dt - 0.1).abs() < 1e-9, "the horizons are in 0.1 s steps");
        // Each step's people (position, velocity, near a robot), newest last.
        let mut history: std::collections::VecDeque<Vec<(Vec2, Vec2, bool)>> =
            std::collections::VecDeque::new();
        for _ in 0..(seconds / dt).round() as u64 {
            fleet.dispatch();
            plan_all(&mut fleet, &mut stacks, &mut commands, |i, stack, input| {
                guards[i].plan(stack, input).0
            });
            let before = fleet.world.humans.crowd.velocities.clone();
            fleet.step(&commands);
            let w = &fleet.world;
            for (h, (&v0, &v1)) in before.iter().zip(&w.humans.crowd.velocities).enumerate() {
                all.add(v0, v1, dt);
                let p = w.humans.crowd.positions[h];
                if w.robots.iter().any(|r| (r.state.position - p).norm() < 3.0) {
                    near.add(v0, v1, dt);
                }
            }
            let now: Vec<(Vec2, Vec2, bool)> = w
                .humans
                .crowd
                .positions
                .iter()
                .zip(&w.humans.crowd.velocities)
                .map(|(&p, &v)| {
                    let near = w.robots.iter().any(|r| (r.state.position - p).norm() < 3.0);
                    (p, v, near)
                })
                .collect();
            for (k, &h) in steps.iter().enumerate() {
                let Some(then) = history.len().checked_sub(h).map(|at| &history[at]) else {
                    continue;
                };
                for (&(p0, v0, was_near), &(p, ..)) in then.iter().zip(&now) {
                    if was_near {
                        strays.add(k, p0, v0, p);
                    }
                }
            }
            history.push_back(now);
            if history.len() > steps[steps.len() - 1] {
                history.pop_front();
            }
        }
    }
    all.print(&format!("{scenario_name}, seeds 1–{seeds}, everyone"));
    near.print(&format!(
        "{scenario_name}, seeds 1–{seeds}, within 3 m of a robot"
    ));
    strays.print(&format!(
        "{scenario_name}, seeds 1–{seeds}, within 3 m of a robot"
    ));
    for dir in args.iter().skip(3) {
        let recording = Recording::load(std::path::Path::new(dir)).expect("a recording");
        let mut split = Split::default();
        for track in &recording.tracks {
            for pair in track.samples.windows(2) {
                split.add(pair[0].velocity, pair[1].velocity, pair[1].t - pair[0].t);
            }
        }
        split.print(&format!("{} (recorded)", recording.name));
        // Horizons of 1 to 4 annotations (0.4 s each in ETH and UCY).
        let mut strays = Strays::new(&[0.4, 0.8, 1.2, 1.6]);
        for track in &recording.tracks {
            for (i, s0) in track.samples.iter().enumerate() {
                for (k, later) in track.samples[i + 1..].iter().take(4).enumerate() {
                    let t = later.t - s0.t;
                    if (t - strays.horizons[k]).abs() < 0.05 {
                        strays.add(k, s0.position, s0.velocity, later.position);
                    }
                }
            }
        }
        strays.print(&format!("{} (recorded), everyone", recording.name));
    }
}
