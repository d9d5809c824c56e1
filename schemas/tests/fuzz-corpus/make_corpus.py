"""Writes the fuzzer's hand-made seeds (schemas/tests/fuzz.rs replays every file here first,
then mutates them): inputs that reach past the size and version checks with shapes a decoder
finds hard. Run from this folder: python make_corpus.py (needs msgpack==1.2.4)."""

import struct

import msgpack

OBS = {
    "v": 1, "robot_id": 3, "seq": 17, "sim_time": 12.5, "dt": 0.1, "map_version": 1,
    "p": [1.0, 2.0], "heading": 0.5, "vel": [0.3, 0.0], "yaw_rate": 0.0, "radius": 0.3,
    "goal": [10.0, 2.0], "task": None, "neighbours": [], "visibility": None,
}


def pack(value):
    return msgpack.packb(value, use_bin_type=True)


def write(name, data):
    with open(name, "wb") as f:
        f.write(data)


# The version last, not first (decode then probes the whole map).
write("version-last.msgpack", pack(dict(list(OBS.items())[1:] + [("v", 1)])))
# Deep nesting under an unknown key: a decoder that recurses without a limit overflows its stack.
deep = b"\x91" * 100_000 + b"\xc0"
write("deep-nesting.msgpack", b"\x82\xa1v\x01\xa3zzz" + deep)
# An array header claiming 2^31 neighbours with none following.
body = pack(dict(OBS, neighbours=[]))
write("huge-array-header.msgpack", body.replace(b"\xaaneighbours\x90", b"\xaaneighbours\xdd\x80\x00\x00\x00"))
# The same key twice (the second robot_id differs).
pairs = list(OBS.items()) + [("robot_id", 9)]
data = b"\xde" + struct.pack(">H", len(pairs)) + b"".join(pack(k) + pack(v) for k, v in pairs)
write("duplicate-key.msgpack", data)
# A string that is not UTF-8 where the planner's name goes.
intent = {"v": 1, "robot_id": 3, "obs_seq": 1, "stamp": 0.0, "planner": "pgp",
          "subgoal": [0.0, 0.0], "trajectory": []}
write("bad-utf8.msgpack", pack(intent).replace(b"\xa3pgp", b"\xa3\xff\xfe\xfd"))
# A 32-bit NaN for a position.
write("f32-nan.msgpack", pack(OBS).replace(b"\xa1p\x92\xcb" + struct.pack(">d", 1.0),
                                           b"\xa1p\x92\xca" + struct.pack(">f", float("nan"))))
# Bytes (bin) where a string goes, and an extension type where a number goes.
write("bin-for-str.msgpack", pack(intent).replace(b"\xa3pgp", b"\xc4\x03pgp"))
write("ext-for-number.msgpack", pack(OBS).replace(b"\xa3seq\x11", b"\xa3seq\xd4\x01\x00"))
# An unused marker, and nothing at all.
write("never-used-marker.msgpack", b"\xc1")
write("empty.msgpack", b"")
# A command whose obs_seq is u64::MAX (once an overflow in the coordinator).
cmd = {"v": 1, "robot_id": 0, "obs_seq": 2**64 - 1, "stamp": 0.0,
       "motion": {"velocity": [9.0, 0.0]}, "safe_stop": False, "safety": "clear"}
write("command-max-seq.msgpack", pack(cmd))
