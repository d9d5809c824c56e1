//! Planner names: which short-term planner, with which variant, optionally behind PGP, as
//! written on the command line (`pgp+orca`, `pnp-react`, `asfm-crowd`, …).

use crate::asfm::AsfmVariant;
use crate::igp::IgpVariant;
use crate::pnp::PnpParams;
use std::fmt;
use std::str::FromStr;

/// The short-term planners.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum LocalKind {
    /// Predictive Dynamic Window Approach.
    Dwa,
    /// Optimal Reciprocal Collision Avoidance.
    Orca,
    /// ORCA that does not count on people to avoid it (`orca-nr`): it takes the whole of the
    /// avoidance of a person instead of RVO2's reciprocal half, and half of the avoidance of
    /// another robot, as `orca` does. Ours, not in a paper: recorded people (and many real
    /// ones) do not give way to a robot.
    OrcaNonReciprocal,
    /// Social Force agent.
    SocialForce,
    /// First-order interacting Gaussian processes (the foIGP paper's planners).
    Igp(IgpVariant),
    /// Peek-and-pass (the "Look Before You Leap" paper's hallway planner), with peeking on
    /// (`pnp`) or off (`pnp-nopeek`: c3 high).
    Pnp {
        /// Which of its variants.
        variant: PnpVariant,
        /// Whether c3 is at the laned study's optimum (true) or high.
        peek: bool,
    },
    /// Anticipatory Social Force (the warehouse paper's planner): Â_o estimated per person,
    /// the desired velocity optimised over a Social Force rollout.
    Asfm(AsfmVariant),
}

/// The variants of peek-and-pass (agent/README.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum PnpVariant {
    /// Eq. 3 as written (`pnp-paper`): [`PnpParams::paper`].
    Paper,
    /// Constant-velocity predictions with the departures from Eq. 3 chosen on hallway seeds
    /// 1–8 (`pnp`): [`PnpParams::peeking`].
    Tuned,
    /// Predictions that react to each candidate, with the same departures (`pnp-react`):
    /// [`PnpParams::reactive`].
    Reactive,
    /// `pnp` with the first segment's speed in sixths of v_max (`pnp-fine`):
    /// [`PnpParams::fine`].
    Fine,
    /// `pnp` with a 1.5 s horizon and the first segment's speed in twelfths of v_max
    /// (`pnp-agile`): [`PnpParams::agile`].
    Agile,
    /// `pnp-agile` with a holonomic base's candidates, velocities in ten directions
    /// (`pnp-omni`): [`PnpParams::omni`].
    Omni,
    /// `pnp-omni` with the prediction samples spread across a walking person's way half as
    /// far as along it (`pnp-omni-across`): [`PnpParams::omni_across`].
    OmniAcross,
    /// `pnp-omni-across` keeping to the side of a hallway or aisle, beside walls that run on
    /// (`pnp-side`): [`PnpParams::side`].
    Side,
    /// `pnp-side` scoring its hidden people against braking once they step out
    /// (`pnp-side-brake`): [`PnpParams::side_brake`].
    SideBrake,
    /// `pnp-side` keeping to the wall on its right (`pnp-right`): [`PnpParams::right`].
    Right,
}

impl PnpVariant {
    /// The variant's parameters with peeking on or off.
    pub fn params(self, peek: bool) -> PnpParams {
        match self {
            PnpVariant::Paper => PnpParams::paper(peek),
            PnpVariant::Tuned => PnpParams::peeking(peek),
            PnpVariant::Reactive => PnpParams::reactive(peek),
            PnpVariant::Fine => PnpParams::fine(peek),
            PnpVariant::Agile => PnpParams::agile(peek),
            PnpVariant::Omni => PnpParams::omni(peek),
            PnpVariant::OmniAcross => PnpParams::omni_across(peek),
            PnpVariant::Side => PnpParams::side(peek),
            PnpVariant::Right => PnpParams::right(peek),
            PnpVariant::SideBrake => PnpParams::side_brake(peek),
        }
    }
}

/// Which planners a stack runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PlannerSpec {
    /// Whether PGP picks the short-term planner's goal.
    pub pgp: bool,
    /// The short-term planner.
    pub local: LocalKind,
}

impl PlannerSpec {
    /// The six planners of the PGP paper's study, baselines first.
    pub const STUDY: [PlannerSpec; 6] = [
        PlannerSpec {
            pgp: false,
            local: LocalKind::Dwa,
        },
        PlannerSpec {
            pgp: false,
            local: LocalKind::Orca,
        },
        PlannerSpec {
            pgp: false,
            local: LocalKind::SocialForce,
        },
        PlannerSpec {
            pgp: true,
            local: LocalKind::Dwa,
        },
        PlannerSpec {
            pgp: true,
            local: LocalKind::Orca,
        },
        PlannerSpec {
            pgp: true,
            local: LocalKind::SocialForce,
        },
    ];
}

impl PlannerSpec {
    /// The fleet's planner: what `gapfleet demo`, `gapfleet coordinator`'s free flow,
    /// `gapfleet deployment`, `gapfleet-agent` and `gapfleet study traffic` run unless told
    /// otherwise. Among people, `pnp-right` does the most work in every fleet site, with no
    /// robot-caused contact (results/fleet-default/REPORT.md).
    pub const FLEET: &'static str = "pnp-right";

    /// Whether the short-term planner keeps clear of walls and shelves. The foIGP family does
    /// not: the foIGP paper's model has people and the robot only.
    pub fn avoids_static_obstacles(&self) -> bool {
        !matches!(self.local, LocalKind::Igp(_))
    }
}

/// A planner name that is not one of ours.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "unknown planner {0:?}; expected dwa, orca, orca-nr, sf, foigp, foigp-1, igp-diag, igp-lin, mc, pnp, \
     pnp-nopeek, pnp-paper, pnp-paper-nopeek, pnp-react, pnp-react-nopeek, pnp-fine, pnp-fine-nopeek, pnp-agile, pnp-agile-nopeek, pnp-omni, pnp-omni-nopeek, pnp-omni-across, pnp-omni-across-nopeek, pnp-side, pnp-side-nopeek, pnp-side-brake, pnp-side-brake-nopeek, pnp-right, pnp-right-nopeek, asfm, asfm-q or asfm-crowd, each \
     optionally behind pgp+ (e.g. pgp+orca)"
)]
pub struct UnknownPlanner(pub String);

/// Peek-and-pass's kind: `variant` with peeking on or off.
fn pnp(variant: PnpVariant, peek: bool) -> LocalKind {
    LocalKind::Pnp { variant, peek }
}

impl FromStr for PlannerSpec {
    type Err = UnknownPlanner;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let lower = s.trim().to_ascii_lowercase();
        let (pgp, local) = match lower.strip_prefix("pgp+") {
            Some(rest) => (true, rest),
            None => (false, lower.as_str()),
        };
        let local = match local {
            "dwa" => LocalKind::Dwa,
            "orca" => LocalKind::Orca,
            "orca-nr" => LocalKind::OrcaNonReciprocal,
            "sf" | "social-force" => LocalKind::SocialForce,
            "foigp" => LocalKind::Igp(IgpVariant::Mixture),
            "foigp-1" | "igp-full" => LocalKind::Igp(IgpVariant::Full),
            "igp-diag" => LocalKind::Igp(IgpVariant::Diagonal),
            "igp-lin" => LocalKind::Igp(IgpVariant::Linear),
            "mc" | "mc-1e5" => LocalKind::Igp(IgpVariant::MonteCarlo),
            "pnp" | "peek-and-pass" => pnp(PnpVariant::Tuned, true),
            "pnp-nopeek" => pnp(PnpVariant::Tuned, false),
            "pnp-paper" => pnp(PnpVariant::Paper, true),
            "pnp-paper-nopeek" => pnp(PnpVariant::Paper, false),
            "pnp-react" => pnp(PnpVariant::Reactive, true),
            "pnp-react-nopeek" => pnp(PnpVariant::Reactive, false),
            "pnp-fine" => pnp(PnpVariant::Fine, true),
            "pnp-fine-nopeek" => pnp(PnpVariant::Fine, false),
            "pnp-agile" => pnp(PnpVariant::Agile, true),
            "pnp-agile-nopeek" => pnp(PnpVariant::Agile, false),
            "pnp-omni" => pnp(PnpVariant::Omni, true),
            "pnp-omni-nopeek" => pnp(PnpVariant::Omni, false),
            "pnp-omni-across" => pnp(PnpVariant::OmniAcross, true),
            "pnp-omni-across-nopeek" => pnp(PnpVariant::OmniAcross, false),
            "pnp-side" => pnp(PnpVariant::Side, true),
            "pnp-side-nopeek" => pnp(PnpVariant::Side, false),
            "pnp-side-brake" => pnp(PnpVariant::SideBrake, true),
            "pnp-side-brake-nopeek" => pnp(PnpVariant::SideBrake, false),
            "pnp-right" => pnp(PnpVariant::Right, true),
            "pnp-right-nopeek" => pnp(PnpVariant::Right, false),
            "asfm" | "anticipatory" => LocalKind::Asfm(AsfmVariant::Paper),
            "asfm-q" => LocalKind::Asfm(AsfmVariant::ProcessNoise),
            "asfm-crowd" => LocalKind::Asfm(AsfmVariant::Crowd),
            _ => return Err(UnknownPlanner(s.to_string())),
        };
        Ok(Self { pgp, local })
    }
}

/// As its name (`pgp+orca`), as the command line and every `runs.csv` write it.
#[cfg(feature = "serde")]
impl serde::Serialize for PlannerSpec {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for PlannerSpec {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let name = <std::borrow::Cow<'de, str>>::deserialize(deserializer)?;
        name.parse().map_err(serde::de::Error::custom)
    }
}

impl fmt::Display for PlannerSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let local = match self.local {
            LocalKind::Dwa => "dwa",
            LocalKind::Orca => "orca",
            LocalKind::OrcaNonReciprocal => "orca-nr",
            LocalKind::SocialForce => "sf",
            LocalKind::Igp(IgpVariant::Mixture) => "foigp",
            LocalKind::Igp(IgpVariant::Full) => "foigp-1",
            LocalKind::Igp(IgpVariant::Diagonal) => "igp-diag",
            LocalKind::Igp(IgpVariant::Linear) => "igp-lin",
            LocalKind::Igp(IgpVariant::MonteCarlo) => "mc",
            LocalKind::Pnp { variant, peek } => match (variant, peek) {
                (PnpVariant::Tuned, true) => "pnp",
                (PnpVariant::Tuned, false) => "pnp-nopeek",
                (PnpVariant::Paper, true) => "pnp-paper",
                (PnpVariant::Paper, false) => "pnp-paper-nopeek",
                (PnpVariant::Reactive, true) => "pnp-react",
                (PnpVariant::Reactive, false) => "pnp-react-nopeek",
                (PnpVariant::Fine, true) => "pnp-fine",
                (PnpVariant::Fine, false) => "pnp-fine-nopeek",
                (PnpVariant::Agile, true) => "pnp-agile",
                (PnpVariant::Agile, false) => "pnp-agile-nopeek",
                (PnpVariant::Omni, true) => "pnp-omni",
                (PnpVariant::Omni, false) => "pnp-omni-nopeek",
                (PnpVariant::OmniAcross, true) => "pnp-omni-across",
                (PnpVariant::OmniAcross, false) => "pnp-omni-across-nopeek",
                (PnpVariant::Side, true) => "pnp-side",
                (PnpVariant::Side, false) => "pnp-side-nopeek",
                (PnpVariant::SideBrake, true) => "pnp-side-brake",
                (PnpVariant::SideBrake, false) => "pnp-side-brake-nopeek",
                (PnpVariant::Right, true) => "pnp-right",
                (PnpVariant::Right, false) => "pnp-right-nopeek",
            },
            LocalKind::Asfm(AsfmVariant::Paper) => "asfm",
            LocalKind::Asfm(AsfmVariant::ProcessNoise) => "asfm-q",
            LocalKind::Asfm(AsfmVariant::Crowd) => "asfm-crowd",
        };
        if self.pgp {
            write!(f, "pgp+{local}")
        } else {
            f.write_str(local)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planner_names_round_trip() {
        for spec in PlannerSpec::STUDY {
            assert_eq!(spec.to_string().parse::<PlannerSpec>(), Ok(spec));
        }
        for name in [
            "orca-nr",
            "pgp+orca-nr",
            "foigp",
            "foigp-1",
            "igp-diag",
            "igp-lin",
            "mc",
            "pgp+foigp",
            "pnp",
            "pnp-nopeek",
            "pnp-paper",
            "pnp-paper-nopeek",
            "pnp-react",
            "pnp-react-nopeek",
            "pnp-fine",
            "pnp-fine-nopeek",
            "pnp-agile",
            "pnp-agile-nopeek",
            "pnp-omni",
            "pnp-omni-nopeek",
            "pnp-omni-across",
            "pnp-omni-across-nopeek",
            "pnp-side",
            "pnp-side-nopeek",
            "pnp-side-brake",
            "pnp-side-brake-nopeek",
            "pnp-right",
            "pnp-right-nopeek",
            "asfm",
            "asfm-q",
            "asfm-crowd",
            "pgp+asfm",
        ] {
            let spec: PlannerSpec = name.parse().expect("known");
            assert_eq!(spec.to_string(), name);
        }
        assert_eq!(
            "PGP+ORCA".parse::<PlannerSpec>().map(|s| s.to_string()),
            Ok("pgp+orca".to_string())
        );
        let err = "pgp+rrt".parse::<PlannerSpec>().unwrap_err();
        assert!(err.to_string().contains("pgp+rrt") && err.to_string().contains("foigp"));
    }
}
