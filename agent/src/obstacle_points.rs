//! Walls as PySocialForce sees them: points sampled along every obstacle line, each point
//! within range pushing on a body of its own accord. The Social Force planner and the
//! simulated crowd (`world_sim::crowd`, which indexes them) both sum these pushes.

use crate::fastmath::{self, CHUNK, LANES, LaneSums};
use crate::math::{Real, Vec2};

/// Wall points as PySocialForce samples them: `int(length · resolution)` points from start to
/// end inclusive, per obstacle line, kept also as columns padded with NaN to whole blocks of
/// `LANES` so that sums over them vectorise.
#[derive(Debug, Clone, Default)]
pub struct ObstaclePoints {
    points: Vec<Vec2>,
    xs: Vec<Real>,
    ys: Vec<Real>,
}

impl PartialEq for ObstaclePoints {
    fn eq(&self, other: &Self) -> bool {
        self.points == other.points
    }
}

impl ObstaclePoints {
    /// Samples the given lines.
    pub fn from_segments(
        segments: impl IntoIterator<Item = (Vec2, Vec2)>,
        resolution: Real,
    ) -> Self {
        let mut points = Vec::new();
        for (a, b) in segments {
            let samples = ((b - a).norm() * resolution) as usize;
            match samples {
                0 => {}
                1 => points.push(a),
                _ => points.extend(
                    (0..samples).map(|i| a + (b - a) * (i as Real / (samples - 1) as Real)),
                ),
            }
        }
        Self::from_points(points)
    }

    /// Points given directly (tests, hand-made scenes).
    pub fn from_points(points: Vec<Vec2>) -> Self {
        let padded = points.len().div_ceil(LANES) * LANES;
        let column = |axis: usize| {
            let mut c: Vec<Real> = points.iter().map(|p| p[axis]).collect();
            c.resize(padded, Real::NAN);
            c
        };
        Self {
            xs: column(0),
            ys: column(1),
            points,
        }
    }

    /// The sampled points.
    pub fn points(&self) -> &[Vec2] {
        &self.points
    }

    /// The points' x and y columns, padded with NaN to a whole number of blocks of `LANES`.
    pub fn columns(&self) -> (&[Real], &[Real]) {
        (&self.xs, &self.ys)
    }

    /// Blocks of `LANES` points (the last one padded).
    pub fn blocks(&self) -> u32 {
        (self.xs.len() / LANES) as u32
    }

    /// Adds to `acc` the pushes (`ObstacleForce` without its factor) of the points in blocks
    /// `blocks.0..blocks.1` on a body of `radius` at `pos`: e^(−dist/σ) along the direction
    /// from the point, for points whose surface distance is below `threshold`.
    #[inline(always)]
    pub fn add_pushes(
        &self,
        acc: &mut LaneSums,
        pos: Vec2,
        radius: Real,
        threshold: Real,
        sigma: Real,
        blocks: (u32, u32),
    ) {
        let (mut fx, mut fy) = ([0.0; CHUNK], [0.0; CHUNK]);
        let inv_sigma = 1.0 / sigma;
        let (first, end) = (blocks.0 as usize * LANES, blocks.1 as usize * LANES);
        for start in (first..end).step_by(CHUNK) {
            let len = (end - start).min(CHUNK);
            let points = self.xs[start..start + len]
                .iter()
                .zip(&self.ys[start..start + len]);
            for ((fx, fy), (&x, &y)) in fx.iter_mut().zip(fy.iter_mut()).zip(points) {
                let (dx, dy) = (pos.x - x, pos.y - y);
                let norm = (dx * dx + dy * dy).sqrt();
                let dist = norm - radius;
                // (d / ‖d‖) · e^(−dist/σ) with one division: the divisions, not the
                // exponential, bound this loop.
                let push = fastmath::exp(-dist * inv_sigma) / norm;
                // normalize(): a point at the body's centre has no direction and adds nothing.
                let acts = (dist < threshold) & (norm != 0.0);
                *fx = if acts { dx * push } else { 0.0 };
                *fy = if acts { dy * push } else { 0.0 };
            }
            acc.accumulate(&fx[..len], &fy[..len]);
        }
    }
}
