//! AFL++ harness: each input is decoded as every message type, and what decodes must round-trip
//! (`schemas::fuzzing`). A panic or a failed round trip aborts, and AFL++ keeps the input as a
//! crash.

fn main() {
    afl::fuzz!(|bytes: &[u8]| {
        if let Err(e) = schemas::fuzzing::decode_as_every_type(bytes) {
            panic!("{e}");
        }
    });
}
