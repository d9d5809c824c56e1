//! AFL++ harness for the ROS 2 decoders: each input is decoded as every ROS 2 message type the
//! agent reads or writes and as an rmw_zenoh attachment, and what decodes must round-trip
//! (`ros2_wire::fuzzing`). A panic or a failed round trip aborts, and AFL++ keeps the input as a
//! crash.

fn main() {
    afl::fuzz!(|bytes: &[u8]| {
        if let Err(e) = ros2_wire::fuzzing::decode_as_every_type(bytes) {
            panic!("{e}");
        }
    });
}
