//! The crowd's positions and velocities as columns, and each person's neighbours packed from
//! them, so that the social force loop vectorises and wastes no lanes.

use agent::fastmath::{CHUNK, LANES, LaneSums};
use agent::math::{Real, Vec2, vec2};
use agent::social_force::{SocialForceParams, mutual_social_forces, social_force_pair};

/// Positions and velocities of a crowd as columns, and the neighbours of one agent gathered
/// from them: the agents that act, packed, so that the vectorised force loop wastes no lanes.
///
/// Each pair is evaluated once, from its lower column: the agent at column k packs only the
/// columns after k, and what it does to them is added to their `reactions`, which are complete
/// by the time their own turn comes.
#[derive(Debug, Clone, Default)]
pub(super) struct Columns {
    x: Vec<Real>,
    y: Vec<Real>,
    vx: Vec<Real>,
    vy: Vec<Real>,
    /// The packed neighbours of the agent being summed: positions, velocities, and room to
    /// pack one more item past the last.
    near: [Vec<Real>; 4],
    /// The packed neighbours' columns.
    near_columns: Vec<usize>,
    /// Per column, the social force of the agents at lower columns.
    reactions: Vec<Vec2>,
}

impl Columns {
    /// `positions[order[k]]` and `velocities[order[k]]` at k.
    pub(super) fn gather(
        &mut self,
        positions: &[Vec2],
        velocities: &[Vec2],
        order: impl Iterator<Item = usize>,
    ) {
        for column in [&mut self.x, &mut self.y, &mut self.vx, &mut self.vy] {
            column.clear();
        }
        for i in order {
            self.x.push(positions[i].x);
            self.y.push(positions[i].y);
            self.vx.push(velocities[i].x);
            self.vy.push(velocities[i].y);
        }
        for column in &mut self.near {
            column.resize(self.x.len() + CHUNK, 0.0);
        }
        self.near_columns.resize(self.x.len() + CHUNK, 0);
        self.reactions.clear();
        self.reactions.resize(self.x.len(), vec2(0.0, 0.0));
    }

    /// Packs every agent in `runs` (ascending, disjoint ranges of columns) closer to `pa` than
    /// √`range_sq`, and returns how many. Branch-free: each candidate is written, and the
    /// count advances only past those that act.
    #[inline(always)]
    pub(super) fn pack(&mut self, pa: Vec2, runs: &[(usize, usize)], range_sq: Real) -> usize {
        let mut m = 0;
        let [nx, ny, nvx, nvy] = &mut self.near;
        // Plain slices, so that the loop keeps their bounds in registers.
        let (nx, ny, nvx, nvy) = (&mut nx[..], &mut ny[..], &mut nvx[..], &mut nvy[..]);
        let nk = &mut self.near_columns[..];
        for &(lo, hi) in runs {
            let candidates = self.x[lo..hi]
                .iter()
                .zip(&self.y[lo..hi])
                .zip(&self.vx[lo..hi])
                .zip(&self.vy[lo..hi]);
            for (k, (((&x, &y), &vx), &vy)) in (lo..hi).zip(candidates) {
                nx[m] = x;
                ny[m] = y;
                nvx[m] = vx;
                nvy[m] = vy;
                nk[m] = k;
                let (dx, dy) = (x - pa.x, y - pa.y);
                m += usize::from(dx * dx + dy * dy < range_sq);
            }
        }
        m
    }

    /// The social force of the crowd on the agent at `column`, (pa, va), whose `m` neighbours
    /// at later columns are packed: theirs, as partial sums, plus the reactions of the earlier
    /// ones. Each packed neighbour's reaction is added to its entry of `reactions`.
    #[inline(always)]
    pub(super) fn social(
        &mut self,
        column: usize,
        pa: Vec2,
        va: Vec2,
        m: usize,
        p: &SocialForceParams,
    ) -> Vec2 {
        let mut acc = LaneSums::ZERO;
        let (mut fx, mut fy) = ([0.0; CHUNK], [0.0; CHUNK]);
        let (mut gx, mut gy) = ([0.0; CHUNK], [0.0; CHUNK]);
        let [nx, ny, nvx, nvy] = &self.near;
        for start in (0..m).step_by(CHUNK) {
            // Whole blocks, so that the loop has no scalar remainder; the items past the
            // packed ones are left-overs, zeroed below.
            let len = (m - start).min(CHUNK);
            let whole = len.div_ceil(LANES) * LANES;
            let columns = nx[start..start + whole]
                .iter()
                .zip(&ny[start..start + whole])
                .zip(&nvx[start..start + whole])
                .zip(&nvy[start..start + whole]);
            let forces = fx
                .iter_mut()
                .zip(fy.iter_mut())
                .zip(gx.iter_mut().zip(&mut gy));
            // Whether some item stands exactly at pa (e = 0 as `normalize` finds it; the
            // left-overs may raise it needlessly, which only costs the check below).
            let mut coincident = false;
            for (((fx, fy), (gx, gy)), (((&x, &y), &vx), &vy)) in forces.zip(columns) {
                coincident |= (pa - vec2(x, y)).norm_squared() == 0.0;
                let (on_a, on_b) = mutual_social_forces(pa, va, vec2(x, y), vec2(vx, vy), p);
                *fx = on_a.x;
                *fy = on_a.y;
                *gx = on_b.x;
                *gy = on_b.y;
            }
            fx[len..whole].fill(0.0);
            fy[len..whole].fill(0.0);
            acc.accumulate(&fx[..whole], &fy[..whole]);
            if coincident {
                // e = 0 (as `normalize` finds it): θ of the reaction is not the shared angle.
                for t in 0..len {
                    let (pb, vb) = (
                        vec2(nx[start + t], ny[start + t]),
                        vec2(nvx[start + t], nvy[start + t]),
                    );
                    if (pa - pb).norm_squared() == 0.0 {
                        let reaction = social_force_pair(pb, vb, pa, va, p);
                        (gx[t], gy[t]) = (reaction.x, reaction.y);
                    }
                }
            }
            let reactions = gx
                .iter()
                .zip(&gy)
                .zip(&self.near_columns[start..start + len]);
            for ((&x, &y), &column) in reactions {
                self.reactions[column] += vec2(x, y);
            }
        }
        acc.total() + self.reactions[column]
    }
}
