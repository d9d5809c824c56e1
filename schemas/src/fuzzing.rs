//! The fuzzing oracle, shared by the structure-aware fuzz test (`tests/fuzz.rs`) and the
//! coverage-guided harness (`schemas/fuzz/`, AFL++): bytes are decoded as every message type,
//! and a message that decodes must encode and decode back to itself. A panic inside
//! [`decode`] is left to propagate, so that each fuzzer sees it as the crash it is.

use crate::*;

/// Decodes `bytes` as `M`: `Ok(true)` when it decodes and survives a round trip unchanged,
/// `Ok(false)` when it is rejected, Err when a decoded message does not come back as itself.
pub fn round_trips<M: Message + PartialEq + std::fmt::Debug>(bytes: &[u8]) -> Result<bool, String> {
    match decode::<M>(bytes) {
        Ok(m) => {
            let again = decode::<M>(&encode(&m))
                .map_err(|e| format!("{m:?} decoded, but its encoding does not: {e}"))?;
            if again != m {
                return Err(format!("{m:?} came back as {again:?}"));
            }
            Ok(true)
        }
        Err(_) => Ok(false),
    }
}

/// Decodes `bytes` as every message type; returns how many types took it, or the first
/// message that did not survive its round trip.
pub fn decode_as_every_type(bytes: &[u8]) -> Result<u32, String> {
    let ok = [
        round_trips::<Observation>(bytes)?,
        round_trips::<IntentMsg>(bytes)?,
        round_trips::<CommandMsg>(bytes)?,
        round_trips::<TaskAssignment>(bytes)?,
        round_trips::<AgentInfo>(bytes)?,
        round_trips::<FanMsg>(bytes)?,
        round_trips::<TrafficMsg>(bytes)?,
        round_trips::<FleetMetrics>(bytes)?,
        round_trips::<MapMsg>(bytes)?,
    ];
    Ok(ok.iter().filter(|&&b| b).count() as u32)
}
