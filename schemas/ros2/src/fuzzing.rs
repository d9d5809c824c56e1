//! The fuzzing oracle, shared by the malformed-input tests (`tests/malformed.rs`) and the
//! coverage-guided harness (`schemas/fuzz/`, AFL++): bytes are decoded as every message type and
//! as an attachment, and whatever decodes must re-encode to bytes that decode to the same
//! encoding again. Encodings are compared rather than values, because a laser range may be NaN
//! (REP 117) and NaN is not equal to itself. A panic inside [`decode`] is left to propagate, so
//! that each fuzzer sees it as the crash it is.

use crate::msg::{
    LaserScan, Odometry, People, PoseWithCovarianceStamped, TFMessage, Twist, TwistStamped,
};
use crate::{Attachment, Message, decode, encode};

/// Decodes `bytes` as `M`: `Ok(true)` when it decodes and its encoding survives a round trip,
/// `Ok(false)` when it is rejected, Err when a decoded message does not come back as itself.
pub fn round_trips<M: Message + std::fmt::Debug>(bytes: &[u8]) -> Result<bool, String> {
    let Ok(message) = decode::<M>(bytes) else {
        return Ok(false);
    };
    let encoded = encode(&message);
    let again = decode::<M>(&encoded).map_err(|e| {
        format!(
            "{} {message:?} decoded, but its encoding does not: {e}",
            M::NAME
        )
    })?;
    if encode(&again) != encoded {
        return Err(format!("{} {message:?} came back as {again:?}", M::NAME));
    }
    Ok(true)
}

/// Decodes `bytes` as every message type and as an rmw_zenoh attachment; returns how many took
/// it, or the first that did not survive its round trip.
pub fn decode_as_every_type(bytes: &[u8]) -> Result<u32, String> {
    let attachment = match Attachment::from_bytes(bytes) {
        Ok(a) if a.to_bytes().as_slice() != bytes => {
            return Err(format!("attachment {a:?} does not encode to its bytes"));
        }
        Ok(_) => true,
        Err(_) => false,
    };
    let ok = [
        round_trips::<Twist>(bytes)?,
        round_trips::<TwistStamped>(bytes)?,
        round_trips::<Odometry>(bytes)?,
        round_trips::<PoseWithCovarianceStamped>(bytes)?,
        round_trips::<LaserScan>(bytes)?,
        round_trips::<TFMessage>(bytes)?,
        round_trips::<People>(bytes)?,
        attachment,
    ];
    Ok(ok.iter().filter(|&&b| b).count() as u32)
}
