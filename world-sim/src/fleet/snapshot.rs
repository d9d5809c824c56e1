//! Snapshots of a fleet: its whole state as bytes, and a fleet again from them.
//!
//! A snapshot holds everything a run changes: robots and their jobs, people, the random
//! streams' positions (ChaCha's seed, stream and word position), metrics accumulators, the
//! traffic monitor and policy, the human-impact measurement with its shadow world. What the
//! scenario decides and nothing changes, the walls and shelves and the crowd's wall points
//! (a tabulated field of several MB), is left out: [`Fleet::restore`] builds the scenario's
//! fleet afresh and takes them from it. A restored fleet steps on bit for bit as the one the
//! snapshot was taken of (`snapshot_resumes_bit_for_bit` in `fleet/tests.rs`).
//!
//! The bytes are the format number [`SNAPSHOT_FORMAT`] (4 bytes, little-endian), then the
//! fleet in MessagePack (`rmp-serde`, fields by position): a snapshot of another format, or of another site or fleet size, is
//! refused with the reason.

use super::{Fleet, NotAWarehouse};
use crate::scenario::Scenario;

/// The snapshot format this build writes and reads.
pub const SNAPSHOT_FORMAT: u32 = 2;

/// Why a snapshot could not be restored.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SnapshotError {
    /// The bytes do not decode.
    #[error("snapshot does not decode: {0}")]
    Decode(String),
    /// Written by another format.
    #[error("snapshot format {found} (this build reads {SNAPSHOT_FORMAT})")]
    Format {
        /// The snapshot's format.
        found: u32,
    },
    /// The scenario is not a fleet site.
    #[error(transparent)]
    NotAWarehouse(#[from] NotAWarehouse),
    /// The snapshot is of another world than the scenario's.
    #[error("snapshot of another world than scenario {scenario:?}: {what}")]
    Mismatch {
        /// The scenario's name.
        scenario: String,
        /// What differs.
        what: String,
    },
}

impl Fleet {
    /// The fleet's state as bytes ([`Fleet::restore`] reads them).
    pub fn snapshot(&self) -> Vec<u8> {
        let mut bytes = SNAPSHOT_FORMAT.to_le_bytes().to_vec();
        // Structs of numbers, vectors and options always encode.
        rmp_serde::encode::write(&mut bytes, self).unwrap_or_default();
        bytes
    }

    /// The fleet of `scenario` as [`Fleet::snapshot`] saw it. The scenario must be the one
    /// the snapshot's fleet was built from (same site, robots, people and step); the parts a
    /// snapshot leaves out come from it.
    pub fn restore(scenario: &Scenario, bytes: &[u8]) -> Result<Self, SnapshotError> {
        let (format, fleet) = bytes
            .split_first_chunk::<4>()
            .ok_or_else(|| SnapshotError::Decode(format!("{} bytes", bytes.len())))?;
        let format = u32::from_le_bytes(*format);
        if format != SNAPSHOT_FORMAT {
            return Err(SnapshotError::Format { found: format });
        }
        let mut restored: Fleet =
            rmp_serde::from_slice(fleet).map_err(|e| SnapshotError::Decode(e.to_string()))?;
        let built = Self::new(scenario)?;
        let mismatch = |what: String| SnapshotError::Mismatch {
            scenario: scenario.name.clone(),
            what,
        };
        let (r, b) = (&restored.world, &built.world);
        if r.robots.len() != b.robots.len() || r.humans.crowd.len() != b.humans.crowd.len() {
            return Err(mismatch(format!(
                "{} robots and {} people, the scenario has {} and {}",
                r.robots.len(),
                r.humans.crowd.len(),
                b.robots.len(),
                b.humans.crowd.len()
            )));
        }
        if r.dt.to_bits() != b.dt.to_bits() {
            return Err(mismatch(format!(
                "step {} s, the scenario's {} s",
                r.dt, b.dt
            )));
        }
        let site_bytes = |f: &Fleet| rmp_serde::to_vec(&f.site).unwrap_or_default();
        if site_bytes(&restored) != site_bytes(&built) {
            return Err(mismatch("another site layout".to_owned()));
        }
        restored.site.adopt_router(&built.site);
        restored.robot_map.clone_from(&built.robot_map);
        restored.world.adopt_static(&built.world);
        if let Some(impact) = &mut restored.impact {
            impact.adopt_static(&built.world);
        }
        if let Some(policy) = &mut restored.policy {
            policy.adopt_static(&restored.site);
        }
        Ok(restored)
    }
}
