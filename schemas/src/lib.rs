//! gapfleet's wire contract: every message the fleet exchanges over Zenoh, how it is encoded
//! (MessagePack, maps with named fields), how it is checked on arrival, and the key expressions
//! it travels on.
//!
//! - [`messages`]: the message types. Every message on the wire is a MessagePack map whose
//!   first entry is `"v"`, the [`SCHEMA_VERSION`]; the other entries are the message's fields.
//! - [`codec`]: [`encode`] and [`decode`]. Decoding is strict: a size limit per message type, the
//!   version check, then structural checks (finite numbers, bounded list lengths, positive radii),
//!   each failure a typed [`DecodeError`]. Network input is untrusted; nothing here panics on it.
//! - [`fuzzing`]: the oracle both fuzzers check: decode as every type, round-trip what decodes.
//! - [`keys`]: [`Keys`] builds every key expression under `gapfleet/<site>/…`; no other code
//!   formats keys.
//!
//! `schemas/README.md` documents the same contract for clients in other languages.

pub mod codec;
pub mod fuzzing;
pub mod keys;
pub mod messages;

pub use codec::{DecodeError, Message, decode, encode};
pub use keys::{Channel, KeyError, Keys};
pub use messages::*;

/// Version of the wire contract. Bumped on any change a client would notice; decoders reject
/// other versions.
pub const SCHEMA_VERSION: u16 = 1;
