//! How much a person's motion says about whether they react to a robot: the ceiling for any
//! estimate of "reacts" read from motion, such as asfm's Â_o (issue 48's AUC).
//!
//!     cargo run --release -p studies --example react_evidence -- DENSITY SEEDS [SPEED]
//!
//! The open-space stage at DENSITY people/m² with half of the people reacting to robots
//! (`humans.react_share = 0.5`) and one robot crossing it at SPEED m/s in a straight line
//! (0: it stands in the middle), driven through people as if they were not there. Each step
//! the simulator is also stepped twice more from the same state, once with everyone reacting
//! and once with nobody reacting: the difference is the push f that the robot gives each
//! person this step, whether or not they feel it, exactly as the simulator computes it.
//!
//! Per person, over their first 3 s within 2 m of the robot (between surfaces):
//! - k = Σ a·f / Σ f·f, the least-squares fit of their observed acceleration a onto f: near 1
//!   for people who react, near 0 for people who do not, plus what everything else (their
//!   goal, their group, the other people) does to a along f;
//! - the same fit with the attraction of an unknown constant intended velocity v⁰ fitted
//!   jointly, a = (v⁰ − v)/τ + k·f, τ = PySocialForce's 0.5 s;
//! - both again for the quarter of people the robot pushed hardest (∫|f|² dt).
//!
//! k's AUC as a test of "reacts" is about the most a motion-based estimate could reach when it
//! knows the simulator's force law exactly but not each person's goal and group.

use agent::math::{Real, Vec2, vec2};
use agent::model::Command;
use world_sim::scenario::Scenario;
use world_sim::world::World;

/// Per person: Σ a·f, Σ f·f, the time near, and k once 3 s near.
#[derive(Default, Clone)]
struct Fit {
    num: Real,
    den: Real,
    near: Real,
    at_three: Option<Real>,
    /// For the fit with an unknown constant intended velocity: count, Σy, Σf, Σy·f, Σf·f,
    /// y = a + v/τ.
    n: Real,
    sy: Vec2,
    sf: Vec2,
    syf: Real,
    sff: Real,
    joint_at_three: Option<Real>,
    /// ∫|f|² dt over the first 3 s near (m²/s³): how hard the robot pushed them.
    exposure: Real,
}

/// PySocialForce's relaxation time τ (s).
const TAU: Real = 0.5;

/// [`studies::estimates::auc`], NaN without both kinds.
fn auc(pos: &[Real], neg: &[Real]) -> Real {
    studies::estimates::auc(pos, neg).unwrap_or(Real::NAN)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let density: Real = args.first().and_then(|a| a.parse().ok()).unwrap_or(0.3);
    let seeds: u64 = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(10);
    let speed: Real = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(0.5);
    let (mut reacting, mut ignoring) = (Vec::new(), Vec::new());
    let (mut reacting_joint, mut ignoring_joint) = (Vec::new(), Vec::new());
    let mut exposed: Vec<(Real, bool, Real, Real)> = Vec::new();
    let (mut f_norm, mut a_norm) = (Vec::new(), Vec::new());
    for seed in 1..=seeds {
        let mut s = Scenario::builtin("open-space").expect("built in");
        s.seed = seed;
        s.open_space.as_mut().expect("open space").density = density;
        s.humans.react_to_robots = true;
        s.humans.react_share = 0.5;
        let mut world = World::from_scenario(&s);
        let dt = world.dt;
        let n = world.humans.crowd.len();
        let mut fits = vec![Fit::default(); n];
        let size = s.open_space.expect("open space").size_m;
        if speed == 0.0 {
            world.robots[0].state.position = vec2(size / 2.0, size / 2.0);
        }
        let steps = (s.max_time_s / dt).round() as usize;
        for _ in 0..steps {
            let command = if speed > 0.0 && world.robots[0].state.position.x < size {
                Command::Velocity(vec2(speed, 0.0))
            } else {
                Command::STOP
            };
            let commands = [command];
            let mut everyone = world.clone();
            everyone.humans.crowd.ignores_externals.clear();
            let mut nobody = world.clone();
            nobody.humans.react_to_robots = false;
            everyone.step(&commands);
            nobody.step(&commands);
            let before = world.humans.crowd.velocities.clone();
            let robot = world.robots[0].state;
            world.step(&commands);
            for i in 0..n {
                let p = world.humans.crowd.positions[i];
                let gap = (p - robot.position).norm() - robot.radius - world.humans.radius;
                if gap > 2.0 {
                    continue;
                }
                let f: Vec2 =
                    (everyone.humans.crowd.velocities[i] - nobody.humans.crowd.velocities[i]) / dt;
                let a: Vec2 = (world.humans.crowd.velocities[i] - before[i]) / dt;
                f_norm.push(f.norm());
                a_norm.push(a.norm());
                let fit = &mut fits[i];
                fit.num += a.dot(&f);
                fit.den += f.dot(&f);
                fit.near += dt;
                let y = a + before[i] / TAU;
                fit.n += 1.0;
                fit.sy += y;
                fit.sf += f;
                fit.syf += y.dot(&f);
                fit.sff += f.dot(&f);
                if fit.joint_at_three.is_none() && fit.near >= 3.0 - 1e-9 {
                    let cov = fit.syf - fit.sy.dot(&fit.sf) / fit.n;
                    let var = fit.sff - fit.sf.dot(&fit.sf) / fit.n;
                    fit.joint_at_three = Some(if var > 0.0 { cov / var } else { 0.0 });
                    fit.exposure = fit.sff * dt;
                }
                if fit.at_three.is_none() && fit.near >= 3.0 - 1e-9 {
                    fit.at_three = Some(if fit.den > 0.0 {
                        fit.num / fit.den
                    } else {
                        0.0
                    });
                }
            }
        }
        for (i, fit) in fits.iter().enumerate() {
            if let (Some(k), Some(j)) = (fit.at_three, fit.joint_at_three) {
                exposed.push((fit.exposure, world.humans.reacts(i), k, j));
                if world.humans.reacts(i) {
                    reacting.push(k);
                    reacting_joint.push(j);
                } else {
                    ignoring.push(k);
                    ignoring_joint.push(j);
                }
            }
        }
    }
    let q = |v: &mut Vec<Real>, p: Real| {
        v.sort_by(Real::total_cmp);
        v.get(((v.len().max(1) - 1) as Real * p).round() as usize)
            .copied()
            .unwrap_or(Real::NAN)
    };
    println!(
        "density {density}, seeds 1–{seeds}, robot at {speed} m/s: |f| p50 {:.2} p90 {:.2}, |a| p50 {:.2} p90 {:.2} (m/s², person-steps within 2 m)",
        q(&mut f_norm, 0.5),
        q(&mut f_norm, 0.9),
        q(&mut a_norm, 0.5),
        q(&mut a_norm, 0.9)
    );
    println!(
        "after 3 s near: {} reacting (k median {:.2}), {} ignoring (k median {:.2}); AUC of k {:.3}",
        reacting.len(),
        q(&mut reacting.clone(), 0.5),
        ignoring.len(),
        q(&mut ignoring.clone(), 0.5),
        auc(&reacting, &ignoring)
    );
    println!(
        "  with the intended velocity fitted: k median {:.2} / {:.2}; AUC {:.3}",
        q(&mut reacting_joint.clone(), 0.5),
        q(&mut ignoring_joint.clone(), 0.5),
        auc(&reacting_joint, &ignoring_joint)
    );
    // The same among the people the robot pushed hardest: the top quarter by ∫|f|² dt.
    exposed.sort_by(|a, b| b.0.total_cmp(&a.0));
    let top = &exposed[..exposed.len() / 4];
    let pick = |reacts: bool, joint: bool| -> Vec<Real> {
        top.iter()
            .filter(|e| e.1 == reacts)
            .map(|e| if joint { e.3 } else { e.2 })
            .collect()
    };
    println!(
        "  the quarter pushed hardest (∫|f|²dt ≥ {:.3}): {} reacting, {} ignoring; AUC of k {:.3}, fitted {:.3}",
        top.last().map_or(Real::NAN, |e| e.0),
        pick(true, false).len(),
        pick(false, false).len(),
        auc(&pick(true, false), &pick(false, false)),
        auc(&pick(true, true), &pick(false, true))
    );
}
