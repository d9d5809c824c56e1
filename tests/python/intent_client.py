"""A gapfleet client written from schemas/README.md alone: subscribes to every robot's intent
and traffic constraint on a live fleet, decodes the MessagePack payloads, checks them against
the documented shape, fetches the map from the coordinator's queryable, and prints a JSON
summary on stdout.

    python intent_client.py --connect tcp/127.0.0.1:7447 --site demo --count 40
    python intent_client.py --config SITE/observer-python/zenoh.json5 --site demo --count 40

Needs eclipse-zenoh==1.10.2 and msgpack==1.2.4 (tests/run.sh installs them).
"""

import argparse
import json
import math
import sys
import time

import msgpack
import zenoh

SCHEMA_VERSION = 1


def check_intent(key, msg):
    """Raises AssertionError unless msg is an Intent as schemas/README.md documents it."""
    assert isinstance(msg, dict), "payload is a map"
    assert next(iter(msg)) == "v" and msg["v"] == SCHEMA_VERSION, "v first, version 1"
    for field in ("robot_id", "obs_seq", "stamp", "planner", "subgoal", "trajectory"):
        assert field in msg, f"field {field}"
    key_id = int(key.split("/")[3])
    assert msg["robot_id"] == key_id, "robot_id matches the key"
    assert isinstance(msg["planner"], str) and len(msg["planner"]) <= 64
    x, y = msg["subgoal"]
    assert math.isfinite(x) and math.isfinite(y)
    last_t = -math.inf
    for s in msg["trajectory"]:
        assert set(s) == {"t", "p", "sigma"}, f"sample fields {set(s)}"
        assert s["t"] >= last_t, "samples sorted by t"
        last_t = s["t"]
        assert len(s["p"]) == 2 and all(math.isfinite(c) for c in s["p"])
        assert s["sigma"] >= 0.0
    return msg


TRAFFIC_CONSTRAINTS = ("free", "lane", "hold", "queue", "retreat", "give_way")


def check_traffic(msg):
    """Raises AssertionError unless msg is a Traffic message as schemas/README.md documents it."""
    assert isinstance(msg, dict), "payload is a map"
    assert msg["v"] == SCHEMA_VERSION, "version 1"
    for field in ("tick", "sim_time", "constraint", "goal", "segment", "direction"):
        assert field in msg, f"field {field}"
    assert math.isfinite(msg["sim_time"])
    assert msg["constraint"] in TRAFFIC_CONSTRAINTS, msg["constraint"]
    assert (msg["goal"] is None) == (msg["constraint"] == "free"), "goal exactly when constrained"
    if msg["goal"] is not None:
        assert len(msg["goal"]) == 2 and all(math.isfinite(c) for c in msg["goal"])
    if msg["constraint"] == "hold":
        assert msg["segment"] is not None, "a hold names its segment"
    if msg["constraint"] == "queue":
        assert msg.get("station") is not None, "a queue names its station"
    assert msg["direction"] in (None, 1, -1)
    return msg


def open_session(endpoint, config_file, timeout_s):
    if config_file is not None:
        # A secured site's observer config (gapfleet site init): mutual TLS with the
        # observer's certificate, its user and password; the site's router lets it read only.
        conf = zenoh.Config.from_file(config_file)
        # Fail fast on a refused connection (the config waits forever): retried below.
        conf.insert_json5("connect/timeout_ms", "2000")
        endpoint = config_file
    else:
        conf = zenoh.Config()
        conf.insert_json5("mode", '"client"')
        conf.insert_json5("connect/endpoints", json.dumps([endpoint]))
        conf.insert_json5("scouting/multicast/enabled", "false")
    deadline = time.time() + timeout_s
    while True:
        try:
            return zenoh.open(conf)
        except Exception as exc:  # the fleet may still be starting
            if time.time() > deadline:
                raise SystemExit(f"cannot connect to {endpoint}: {exc}")
            time.sleep(0.2)


def main():
    parser = argparse.ArgumentParser()
    where = parser.add_mutually_exclusive_group(required=True)
    where.add_argument("--connect", help="endpoint of an unsecured fleet, e.g. tcp/127.0.0.1:7447")
    where.add_argument("--config", help="a secured site's observer config (zenoh.json5)")
    parser.add_argument("--site", default="demo")
    parser.add_argument("--count", type=int, default=40)
    parser.add_argument("--timeout", type=float, default=30.0)
    args = parser.parse_args()

    session = open_session(args.connect, args.config, args.timeout)
    prefix = f"gapfleet/{args.site}"
    sub = session.declare_subscriber(f"{prefix}/robot/*/intent")
    traffic = session.declare_subscriber(f"{prefix}/robot/*/traffic")
    received, robots, planners, samples = 0, set(), set(), 0
    traffic_received, constraints = 0, set()
    deadline = time.time() + args.timeout
    # Traffic constraints come ten per robot per simulated second: wait for five times as many.
    while (received < args.count or traffic_received < 5 * args.count) and time.time() < deadline:
        t = traffic.try_recv()
        if t is not None:
            m = check_traffic(msgpack.unpackb(t.payload.to_bytes(), raw=False))
            traffic_received += 1
            constraints.add(m["constraint"])
        sample = sub.try_recv() if received < args.count else None
        if sample is None:
            if t is None:
                time.sleep(0.01)
            continue
        msg = msgpack.unpackb(sample.payload.to_bytes(), raw=False)
        check_intent(str(sample.key_expr), msg)
        received += 1
        robots.add(msg["robot_id"])
        planners.add(msg["planner"])
        samples = max(samples, len(msg["trajectory"]))

    obstacles = stations = None
    for reply in session.get(f"{prefix}/map", timeout=5.0):
        if reply.ok is not None:
            m = msgpack.unpackb(reply.ok.payload.to_bytes(), raw=False)
            assert m["v"] == SCHEMA_VERSION
            obstacles = len(m["obstacles"])
            stations = len(m["stations"])
            kinds = {next(iter(o)) for o in m["obstacles"]}
            assert kinds <= {"polygon", "wall"}, kinds
    session.close()
    json.dump(
        {
            "received": received,
            "robots": sorted(robots),
            "planners": sorted(planners),
            "max_samples": samples,
            "map_obstacles": obstacles,
            "map_stations": stations,
            "traffic_received": traffic_received,
            "traffic_constraints": sorted(constraints),
        },
        sys.stdout,
    )
    print()


if __name__ == "__main__":
    main()
