//! PySocialForce's obstacle force read from a table instead of summed over wall points: a
//! separately named, faster model of the same force (not PySocialForce's arithmetic).
//!
//! Each wall point o pushes a body at p with e^(−(‖p − o‖ − r)/σ) · (p − o)/‖p − o‖, which is
//! −∇ of σ·e^(−(‖p − o‖ − r)/σ). So the whole obstacle force is F = −∇U for the potential
//! U(p) = σ Σ_o e^(−(‖p − o‖ − r)/σ) over the points that act (PySocialForce's threshold test
//! only drops points whose push is below e^(−threshold/σ) ≈ 5·10⁻⁸ of a touching one). Walls
//! do not move, so U, ∂U/∂x, ∂U/∂y and ∂²U/∂x∂y are summed exactly once per corner of a square
//! grid, and a body's force is the gradient of the bicubic Hermite interpolant of U on its
//! cell: a few dozen multiplications instead of a square root, a division and an exponential
//! for each of the ~200 points in reach of a person in a warehouse aisle.
//!
//! U is smooth except within about one point spacing of a wall (where the sampled points make
//! it ripple); bodies are kept farther off by the force itself. The error against the point
//! sum is measured in the tests and in `world-sim/README.md`.

use super::wall_index::{WallIndex, runs_near};
use agent::fastmath::{self, LANES};
use agent::math::{Real, Vec2, bounds, vec2};
use agent::obstacle_points::ObstaclePoints;
use agent::social_force::ObstacleForceParams;

/// The obstacle potential of a set of wall points tabulated on a square grid, for one body
/// radius and one set of [`ObstacleForceParams`].
#[derive(Debug, Clone, PartialEq)]
pub struct WallField {
    radius: Real,
    params: ObstacleForceParams,
    /// Grid spacing h (m).
    spacing: Real,
    /// Position of corner (0, 0).
    min: Vec2,
    cols: usize,
    rows: usize,
    /// Per corner, row-major: U, h·∂U/∂x, h·∂U/∂y, h²·∂²U/∂x∂y (scaled so that the
    /// interpolation works in cell units).
    corners: Vec<[f32; 4]>,
}

impl WallField {
    /// Sums the potential of `points` (visited through `index` where it covers their reach) at
    /// every corner of a grid of `spacing` (m) covering every
    /// place where a point acts on a body of `radius`. Costs one exact obstacle-force
    /// evaluation per corner (about 1 s for the 95 × 78 m `warehouse-large` at 0.1 m on this
    /// project's 2-core VM); `points` indexed with a reach of at least threshold + 2·radius
    /// makes that fast.
    ///
    /// # Panics
    /// If `spacing` is not positive and finite.
    pub(super) fn build(
        points: &ObstaclePoints,
        index: Option<&WallIndex>,
        radius: Real,
        params: &ObstacleForceParams,
        spacing: Real,
    ) -> Self {
        assert!(
            spacing.is_finite() && spacing > 0.0,
            "wall field spacing must be positive, got {spacing}"
        );
        let reach = params.threshold + 2.0 * radius;
        let (mut min, mut max) = bounds(points.points());
        let margin = reach + spacing;
        min -= vec2(margin, margin);
        max += vec2(margin, margin);
        let cols = ((max.x - min.x) / spacing).ceil() as usize + 1;
        let rows = ((max.y - min.y) / spacing).ceil() as usize + 1;
        let mut corners = Vec::with_capacity(cols * rows);
        pulp::Arch::new().dispatch(BuildCorners {
            points,
            index,
            radius,
            params,
            spacing,
            min,
            cols,
            rows,
            out: &mut corners,
        });
        Self {
            radius,
            params: *params,
            spacing,
            min,
            cols,
            rows,
            corners,
        }
    }

    /// Grid spacing (m).
    pub fn spacing(&self) -> Real {
        self.spacing
    }

    /// Memory held by the table (bytes).
    pub fn table_bytes(&self) -> usize {
        self.corners.len() * std::mem::size_of::<[f32; 4]>()
    }

    /// Whether this table was built for a body of `radius` under `params`.
    pub fn serves(&self, radius: Real, params: &ObstacleForceParams) -> bool {
        self.radius == radius
            && self.params.sigma == params.sigma
            && self.params.threshold == params.threshold
    }

    /// The obstacle force on a body at `pos` (with `params.factor` applied): minus the gradient
    /// of the interpolated potential; zero outside the table, where no point acts.
    #[inline(always)]
    pub fn force(&self, pos: Vec2, factor: Real) -> Vec2 {
        let gx = (pos.x - self.min.x) / self.spacing;
        let gy = (pos.y - self.min.y) / self.spacing;
        let (fx, fy) = (gx.floor(), gy.floor());
        // NaN fails these too.
        if !(fx >= 0.0 && fy >= 0.0 && fx < (self.cols - 1) as Real && fy < (self.rows - 1) as Real)
        {
            return vec2(0.0, 0.0);
        }
        let (i, j) = (fx as usize, fy as usize);
        let (s, t) = (gx - fx, gy - fy);
        // Hermite basis on [0, 1] (h: values, g: slopes) and their derivatives, at s and t.
        let basis = |s: Real| {
            let (s2, s3) = (s * s, s * s * s);
            let h = [1.0 - 3.0 * s2 + 2.0 * s3, 3.0 * s2 - 2.0 * s3];
            let g = [s - 2.0 * s2 + s3, s3 - s2];
            let dh = [6.0 * s2 - 6.0 * s, 6.0 * s - 6.0 * s2];
            let dg = [1.0 - 4.0 * s + 3.0 * s2, 3.0 * s2 - 2.0 * s];
            (h, g, dh, dg)
        };
        let (hs, gs, dhs, dgs) = basis(s);
        let (ht, gt, dht, dgt) = basis(t);
        let (mut ds, mut dt) = (0.0, 0.0);
        for b in 0..2 {
            for a in 0..2 {
                let [u, ux, uy, uxy] = self.corners[(j + b) * self.cols + i + a].map(Real::from);
                ds += (u * dhs[a] + ux * dgs[a]) * ht[b] + (uy * dhs[a] + uxy * dgs[a]) * gt[b];
                dt += (u * hs[a] + ux * gs[a]) * dht[b] + (uy * hs[a] + uxy * gs[a]) * dgt[b];
            }
        }
        vec2(ds, dt) * (-factor / self.spacing)
    }
}

/// The table's corners, summed by vector code.
struct BuildCorners<'a> {
    points: &'a ObstaclePoints,
    index: Option<&'a WallIndex>,
    radius: Real,
    params: &'a ObstacleForceParams,
    spacing: Real,
    min: Vec2,
    cols: usize,
    rows: usize,
    out: &'a mut Vec<[f32; 4]>,
}

impl pulp::WithSimd for BuildCorners<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) {
        let threshold = self.params.threshold + self.radius;
        let reach = threshold + self.radius;
        let inv_sigma = 1.0 / self.params.sigma;
        let (sigma, r, h) = (self.params.sigma, self.radius, self.spacing);
        let all = [(0, self.points.blocks())];
        let (xs, ys) = self.points.columns();
        for row in 0..self.rows {
            for col in 0..self.cols {
                let pos = self.min + vec2(col as Real, row as Real) * h;
                let runs = runs_near(self.index, pos, reach, &all);
                let mut sums = [[0.0; LANES]; 4];
                for &(first, end) in runs {
                    let (first, end) = (first as usize * LANES, end as usize * LANES);
                    let xs = xs[first..end].chunks_exact(LANES);
                    let ys = ys[first..end].chunks_exact(LANES);
                    for (xs, ys) in xs.zip(ys) {
                        for l in 0..LANES {
                            let (dx, dy) = (pos.x - xs[l], pos.y - ys[l]);
                            let rho = (dx * dx + dy * dy).sqrt();
                            let e = fastmath::exp(-(rho - r) * inv_sigma);
                            let inv = 1.0 / rho;
                            let e_inv = e * inv;
                            let terms = [
                                sigma * e,
                                -e_inv * dx,
                                -e_inv * dy,
                                e_inv * dx * dy * (inv * inv_sigma + inv * inv),
                            ];
                            // Padding (NaN) and points out of range add exact zeros.
                            let acts = (rho - r < threshold) & (rho != 0.0);
                            for (sum, term) in sums.iter_mut().zip(terms) {
                                sum[l] += if acts { term } else { 0.0 };
                            }
                        }
                    }
                }
                let [u, ux, uy, uxy] = sums.map(|s| fastmath::lanes_total(&s));
                self.out.push([
                    u as f32,
                    (ux * h) as f32,
                    (uy * h) as f32,
                    (uxy * h * h) as f32,
                ]);
            }
        }
    }
}
