//! People walking by the Social Force Model exactly as PySocialForce's `Simulator` steps
//! them, robots pushing on them as further pedestrians would: the simulated humans of every
//! world.
//!
//! The force law is `agent::social_force`'s (the Social Force planner uses the same one); what
//! lives here is the crowd's machinery: its positions and velocities as columns with each
//! pair evaluated once (`columns`), a grid for neighbour look-ups with an interaction range
//! ([`grid`]), the walls indexed or tabulated ([`walls`], [`wall_field`]), and the
//! thread-local scratch that keeps a step free of allocations. The whole force pass is one
//! operation that `pulp` compiles once per instruction set; every sum keeps `LANES` partial
//! sums by item index, so each instruction set gives the same bits.

mod columns;
pub mod grid;
pub mod wall_field;
mod wall_index;
pub mod walls;

use agent::math::{Real, Vec2, vec2};
use agent::social_force::{SfParams, capped_velocity, desired_force, normalize, social_force_pair};
use columns::Columns;
use grid::PointGrid;
pub use wall_field::WallField;
pub use walls::Walls;

/// The grids and lists of a force pass with an interaction range.
#[derive(Debug, Clone, Default)]
struct Lookups {
    /// The people, by cell.
    people: PointGrid,
    /// The runs of columns around one person.
    runs: Vec<(usize, usize)>,
    /// The external agents' positions, and the agents by cell.
    external_positions: Vec<Vec2>,
    externals: PointGrid,
    /// The external agents in reach of one person: indices, then the agents.
    near_indices: Vec<u32>,
    near_externals: Vec<(Vec2, Vec2)>,
}

thread_local! {
    /// The crowd's columns and look-ups, reused between steps.
    static SCRATCH: std::cell::RefCell<(Columns, Lookups)> =
        std::cell::RefCell::new(Default::default());
}

/// Every force on every agent but the group forces: [`Crowd::forces_with_externals`] as one
/// operation that `pulp` compiles once per instruction set (everything it calls is inlined).
struct IndividualForces<'a> {
    crowd: &'a Crowd,
    walls: &'a Walls,
    p: &'a SfParams,
    externals: &'a [(Vec2, Vec2)],
    columns: &'a mut Columns,
    lookups: &'a mut Lookups,
    out: &'a mut [Vec2],
}

impl pulp::WithSimd for IndividualForces<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) {
        let Self {
            crowd,
            walls,
            p,
            externals,
            columns,
            lookups,
            out,
        } = self;
        let n = crowd.len();
        match p.interaction_range {
            // PySocialForce: every pair.
            None => {
                columns.gather(&crowd.positions, &crowd.velocities, 0..n);
                for (a, force) in out.iter_mut().enumerate() {
                    let (pa, va) = (crowd.positions[a], crowd.velocities[a]);
                    let m = columns.pack(pa, &[(a + 1, n)], Real::INFINITY);
                    let social = columns.social(a, pa, va, m, &p.social);
                    *force = crowd.force_on(a, social, walls, p, externals);
                }
            }
            // Pairs closer than the range: the agents sorted by grid cell, so that the 3 × 3
            // cells around an agent are three runs of consecutive columns.
            Some(range) => {
                let Lookups {
                    people,
                    runs,
                    external_positions,
                    externals: external_grid,
                    near_indices,
                    near_externals,
                } = lookups;
                people.build(&crowd.positions, range);
                let order = people.items();
                columns.gather(
                    &crowd.positions,
                    &crowd.velocities,
                    order.iter().map(|&i| i as usize),
                );
                // The external agents in reach of a person, from a grid of their own, in index
                // order as the full scan adds them (so the bits stay the scan's).
                external_positions.clear();
                external_positions.extend(externals.iter().map(|e| e.0));
                external_grid.build(external_positions, range);
                for (k, &a) in order.iter().enumerate() {
                    let a = a as usize;
                    runs.clear();
                    // Only the columns after k: the pairs with lower ones are done.
                    people.runs_near(crowd.positions[a], |lo, hi| {
                        if hi > k + 1 {
                            runs.push((lo.max(k + 1), hi));
                        }
                    });
                    let (pa, va) = (crowd.positions[a], crowd.velocities[a]);
                    let m = columns.pack(pa, runs, range * range);
                    let social = columns.social(k, pa, va, m, &p.social);
                    near_indices.clear();
                    external_grid.runs_near(pa, |lo, hi| {
                        near_indices.extend_from_slice(&external_grid.items()[lo..hi]);
                    });
                    near_indices.sort_unstable();
                    near_externals.clear();
                    for &i in near_indices.iter() {
                        near_externals.push(externals[i as usize]);
                    }
                    out[a] = crowd.force_on(a, social, walls, p, near_externals);
                }
            }
        }
    }
}

/// A crowd simulated exactly as PySocialForce's `Simulator` does.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Crowd {
    /// Positions (m).
    pub positions: Vec<Vec2>,
    /// Velocities (m/s).
    pub velocities: Vec<Vec2>,
    /// Goals.
    pub goals: Vec<Vec2>,
    /// Maximum speeds (m/s): 1.3 × the initial speeds in PySocialForce.
    pub max_speeds: Vec<Real>,
    /// Groups of member indices.
    pub groups: Vec<Vec<usize>>,
    /// Per agent, whether the external agents (robots) do not push on it; empty: they push
    /// on everyone.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub ignores_externals: Vec<bool>,
}

impl Crowd {
    /// A crowd whose maximum speeds derive from the initial velocities, as in PySocialForce.
    pub fn new(
        positions: Vec<Vec2>,
        velocities: Vec<Vec2>,
        goals: Vec<Vec2>,
        groups: Vec<Vec<usize>>,
        p: &SfParams,
    ) -> Self {
        let max_speeds = velocities
            .iter()
            .map(|v| v.norm() * p.max_speed_multiplier)
            .collect();
        Self {
            positions,
            velocities,
            goals,
            max_speeds,
            groups,
            ignores_externals: Vec::new(),
        }
    }

    /// Number of agents.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// True for an empty crowd.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Sum of all forces on every agent (`Simulator.compute_forces`).
    pub fn forces(&self, walls: &Walls, p: &SfParams, out: &mut Vec<Vec2>) {
        self.forces_with_externals(walls, p, &[], out);
    }

    /// As [`Crowd::forces`], with `externals` (position, velocity) pushing on every agent as
    /// further pedestrians would, without being moved themselves: how simulated people react
    /// to robots.
    pub fn forces_with_externals(
        &self,
        walls: &Walls,
        p: &SfParams,
        externals: &[(Vec2, Vec2)],
        out: &mut Vec<Vec2>,
    ) {
        out.clear();
        out.resize(self.len(), vec2(0.0, 0.0));
        // Compiled for the best vector instructions this CPU has (AVX-512, AVX2 or SSE2),
        // chosen at run time; the arithmetic is IEEE throughout, so every choice gives the
        // same bits.
        SCRATCH.with_borrow_mut(|(columns, lookups)| {
            pulp::Arch::new().dispatch(IndividualForces {
                crowd: self,
                walls,
                p,
                externals,
                columns,
                lookups,
                out,
            })
        });
        if p.enable_group {
            self.add_group_forces(p, out);
        }
    }

    /// The force on agent `a`, given the social force of the rest of the crowd on it.
    #[inline(always)]
    fn force_on(
        &self,
        a: usize,
        mut social: Vec2,
        walls: &Walls,
        p: &SfParams,
        externals: &[(Vec2, Vec2)],
    ) -> Vec2 {
        let (pa, va) = (self.positions[a], self.velocities[a]);
        let felt = if self.ignores_externals.get(a).copied().unwrap_or(false) {
            &[][..]
        } else {
            externals
        };
        for &(pb, vb) in felt {
            if p.interaction_range
                .is_none_or(|r| (pb - pa).norm_squared() < r * r)
            {
                social += social_force_pair(pa, va, pb, vb, &p.social);
            }
        }
        desired_force(pa, va, self.goals[a], self.max_speeds[a], &p.desired)
            + social * p.social.factor
            + walls.force(pa, p.agent_radius, &p.obstacle)
    }

    fn add_group_forces(&self, p: &SfParams, out: &mut [Vec2]) {
        for group in &self.groups {
            let size = group.len();
            if size == 0 {
                continue;
            }
            let com = group.iter().map(|&i| self.positions[i]).sum::<Vec2>() / size as Real;
            // GroupCoherenceForceAlt: pull towards the centre of mass, softened by
            // (tanh(‖v‖ − threshold) + 1) / 2, except that PySocialForce measures ‖v‖ with
            // `stateutils.speeds`, which reads columns 2..4 of the 2-column array: always 0.
            let threshold = (size as Real - 1.0) / 2.0;
            let softened = ((-threshold).tanh() + 1.0) / 2.0;
            for &i in group {
                let v = com - self.positions[i];
                out[i] += v * softened * p.group_coherence_factor;
            }
            // GroupRepulsiveForce: members closer than the threshold push apart.
            for &i in group {
                let mut f = vec2(0.0, 0.0);
                for &j in group.iter().filter(|&&j| j != i) {
                    let d = self.positions[i] - self.positions[j];
                    if d.norm() <= p.group_repulsive.threshold {
                        f += d;
                    }
                }
                out[i] += f * p.group_repulsive.factor;
            }
            // GroupGazeForceAlt: turn towards the others' centre of mass.
            if size > 1 {
                for &i in group {
                    let others_com = group
                        .iter()
                        .filter(|&&j| j != i)
                        .map(|&j| self.positions[j])
                        .sum::<Vec2>()
                        / (size - 1) as Real;
                    let (com_direction, com_dist) = normalize(others_com - self.positions[i]);
                    let (direction, goal_dist) = normalize(self.goals[i] - self.positions[i]);
                    let element_prod = direction.dot(&com_direction);
                    out[i] +=
                        direction * (com_dist * element_prod / goal_dist) * p.group_gaze_factor;
                }
            }
        }
    }

    /// One `Simulator.step_once`: Euler step of the velocity, capped, zero near the goal.
    pub fn step(&mut self, walls: &Walls, p: &SfParams, scratch: &mut Vec<Vec2>) {
        self.step_with_externals(walls, p, &[], scratch);
    }

    /// [`Crowd::step`] with external agents pushing (see [`Crowd::forces_with_externals`]).
    pub fn step_with_externals(
        &mut self,
        walls: &Walls,
        p: &SfParams,
        externals: &[(Vec2, Vec2)],
        scratch: &mut Vec<Vec2>,
    ) {
        self.forces_with_externals(walls, p, externals, scratch);
        for (i, force) in scratch.iter().enumerate() {
            let mut v = capped_velocity(
                self.velocities[i] + force * p.step_width,
                self.max_speeds[i],
            );
            if (self.goals[i] - self.positions[i]).norm() < p.arrival_distance {
                v = vec2(0.0, 0.0);
            }
            self.positions[i] += v * p.step_width;
            self.velocities[i] = v;
        }
    }
}

#[cfg(test)]
mod tests;
