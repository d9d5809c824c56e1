//! The crowd's walls: PySocialForce's wall points, indexed by a grid so that each person
//! visits only the points near it (bit-identical to the full scan), and optionally the
//! separately named tabulated model of the same force ([`WallField`]).

use super::wall_field::WallField;
use super::wall_index::{WallIndex, runs_near};
use agent::fastmath::LaneSums;
use agent::math::{Real, Vec2};
use agent::obstacle_points::ObstaclePoints;
use agent::social_force::ObstacleForceParams;
use std::sync::Arc;

/// Wall points for a crowd: [`ObstaclePoints`], optionally indexed
/// ([`indexed`](Self::indexed)) and tabulated ([`with_field`](Self::with_field)).
#[derive(Debug, Clone, Default)]
pub struct Walls {
    points: ObstaclePoints,
    index: Option<WallIndex>,
    /// The tabulated potential, used instead of the points for the radius and parameters it
    /// was built for.
    field: Option<Arc<WallField>>,
}

impl PartialEq for Walls {
    fn eq(&self, other: &Self) -> bool {
        self.points == other.points
    }
}

impl From<ObstaclePoints> for Walls {
    fn from(points: ObstaclePoints) -> Self {
        Self {
            points,
            index: None,
            field: None,
        }
    }
}

impl Walls {
    /// Indexes the points by a grid for bodies on which a point acts only within `reach` of
    /// their centre (PySocialForce's test is `‖pos − o‖ − r < threshold + r`, so that is
    /// `threshold + 2r`): each cell lists the blocks of points within `reach` of it, and a body
    /// visits only those of its cell instead of every point of the map.
    pub fn indexed(mut self, reach: Real) -> Self {
        self.index = Some(WallIndex::build(self.points.points(), reach));
        self
    }

    /// Tabulates the points' potential for a body of `radius` under `params` on a grid of
    /// `spacing` (m) ([`WallField`]): from then on [`force`](Self::force) for that radius and
    /// those parameters interpolates the table instead of summing the points. A separately
    /// named model (walls = "field"), not PySocialForce's arithmetic; index the points first.
    pub fn with_field(mut self, radius: Real, params: &ObstacleForceParams, spacing: Real) -> Self {
        let field = WallField::build(&self.points, self.index.as_ref(), radius, params, spacing);
        self.field = Some(Arc::new(field));
        self
    }

    /// The tabulated potential, if [`with_field`](Self::with_field) built one.
    pub fn field(&self) -> Option<&WallField> {
        self.field.as_deref()
    }

    /// The wall points.
    pub fn points(&self) -> &ObstaclePoints {
        &self.points
    }

    /// `ObstacleForce` on a body of `radius` at `pos`: PySocialForce's sum over the points
    /// (visiting only nearby blocks when indexed, with the full scan's bits), or the table for
    /// the radius and parameters it was built for.
    #[inline(always)]
    pub fn force(&self, pos: Vec2, radius: Real, p: &ObstacleForceParams) -> Vec2 {
        if let Some(field) = &self.field
            && field.serves(radius, p)
        {
            return field.force(pos, p.factor);
        }
        let threshold = p.threshold + radius;
        let mut acc = LaneSums::ZERO;
        let all = [(0, self.points.blocks())];
        for &run in runs_near(self.index.as_ref(), pos, threshold + radius, &all) {
            self.points
                .add_pushes(&mut acc, pos, radius, threshold, p.sigma, run);
        }
        acc.total() * p.factor
    }
}
