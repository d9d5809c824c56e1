//! ROS 2 as rmw_zenoh puts it on Zenoh, with no ROS installation: the CDR encoding of the
//! messages an agent exchanges with a robot, and the key expressions, liveliness tokens and
//! attachments that make a Zenoh publisher or subscriber a ROS 2 one.
//!
//! - [`cdr`]: the encoding, and a reader for untrusted bytes ([`cdr::Limits`], [`CdrError`]).
//! - [`msg`]: the messages (`Odometry`, `LaserScan`, `Twist`, `TwistStamped`, `TFMessage`,
//!   `PoseWithCovarianceStamped`, `People`), [`encode`] and [`decode`] with finite and physical
//!   checks.
//! - [`graph`]: names, keys, tokens, QoS strings and attachments, for Humble, Jazzy and Kilted.
//! - [`fuzzing`]: the oracle the malformed-input tests and the AFL++ harness share.
//!
//! It knows nothing about Zenoh sessions: the agent's runtime and the coordinator's robot bridge
//! declare the publishers, subscribers and tokens with the strings built here. The messages'
//! bytes are checked against rosbags' serializer (`fixtures/make_fixtures.py`).

#![warn(missing_docs)]

pub mod cdr;
pub mod fuzzing;
pub mod graph;
pub mod msg;

pub use cdr::CdrError;
pub use graph::{Attachment, Distro, EntityKind, Node, Qos};
pub use msg::{Message, decode, encode};
