"""A ROS 2 robot that no one here wrote the middleware of: ROBOTIS's zenoh-ros2-sdk (pure-Python
rmw_zenoh) carries its topics. It stands in a walled 8 m x 7 m room with people walking through
it, never reacting to the robot, and:

- integrates `cmd_vel` (geometry_msgs/Twist) as a differential drive (1 m/s, 1 rad/s, 1.5 m/s^2,
  1.5 rad/s^2; stops when commands pause 0.5 s);
- publishes nav_msgs/Odometry (frame `map`: the room is the map), a 360-ray
  sensor_msgs/LaserScan of the walls and people, and people_msgs/People (unless --no-people);
- mounts its scanner 0.2 m ahead of the base's centre, facing backwards, and says so once, at
  start, on /tf_static (base_link -> base_scan) as rmw_zenoh publishes a transient-local topic:
  through a Zenoh AdvancedPublisher whose cache late subscribers query;
- with --localized, publishes odometry in an `odom` frame that drifted from the map (1 m,
  -0.5 m, 0.3 rad) and its map pose on `amcl_pose` (geometry_msgs/PoseWithCovarianceStamped),
  stamped with the previous odometry's time, as AMCL stamps with its scan's;
- logs every step as one JSON line: time, robot pose and speed, people, and contacts;
- once commands come, asks the ROS graph who publishes `cmd_vel` and who subscribes to `odom`
  (the SDK's `ros2 topic info --verbose`, from the liveliness tokens) and logs the answer.

    python tests/python/ros2_robot.py --namespace /robot1 --router 127.0.0.1:7447 --seconds 60 --log robot.jsonl

The message definitions the SDK needs (the types and their dependencies) are written from
rosbags' Jazzy store, people_msgs from schemas/ros2/fixtures/people_msgs, into a folder the SDK
reads, so that its type hashes are rmw_zenoh's (see ../shared/ros2/README.md).
"""

import argparse
import json
import math
import shutil
import sys
import tempfile
import threading
import time
from pathlib import Path

from rosbags.typesys import Stores, get_typestore

ROOT = Path(__file__).resolve().parents[2]
PEOPLE_MSGS = ROOT / "schemas" / "ros2" / "fixtures" / "people_msgs" / "msg"
TYPES = [
    "nav_msgs/msg/Odometry",
    "sensor_msgs/msg/LaserScan",
    "geometry_msgs/msg/Twist",
    "tf2_msgs/msg/TFMessage",
    "geometry_msgs/msg/PoseWithCovarianceStamped",
]
ROOM = (-2.0, -2.0, 6.0, 5.0)  # x0, y0, x1, y1: the walls' inner faces
ROBOT_RADIUS = 0.3
PERSON_RADIUS = 0.3
RAYS = 360
RANGE_MAX = 12.0
MAP_FROM_ODOM = (1.0, -0.5, 0.3)  # x, y, yaw of the odom frame in the map, with --localized
SCANNER_AHEAD = 0.2  # m along the base's heading; the scanner faces backwards (yaw pi)


def render(ts, name, out, seen):
    """Writes `name`'s .msg and those of every type it uses."""
    if name in seen or name.startswith("people_msgs/"):
        return
    seen.add(name)
    consts, fields = ts.fielddefs[name]
    lines = [f"{ctype} {cname}={value}" for cname, ctype, value in consts]

    def typestr(node):
        kind, detail = node
        if kind == 1:  # BASE
            return detail[0] if detail[1] == 0 else f"{detail[0]}<={detail[1]}"
        if kind == 2:  # NAME
            render(ts, detail, out, seen)
            return detail.replace("/msg/", "/")
        if kind == 3:  # ARRAY
            return f"{typestr(detail[0])}[{detail[1]}]"
        return f"{typestr(detail[0])}[{'<=' + str(detail[1]) if detail[1] else ''}]"

    for fname, node in fields:
        lines.append(f"{typestr(node)} {fname}")
    pkg, _, ty = name.split("/")
    path = out / pkg / "msg" / f"{ty}.msg"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")


def message_dir():
    out = Path(tempfile.mkdtemp(prefix="gapfleet-ros2-msgs-"))
    ts = get_typestore(Stores.ROS2_JAZZY)
    seen = set()
    for name in TYPES + ["std_msgs/msg/Header", "geometry_msgs/msg/Point"]:
        render(ts, name, out, seen)
    (out / "people_msgs" / "msg").mkdir(parents=True)
    for f in PEOPLE_MSGS.glob("*.msg"):
        shutil.copy(f, out / "people_msgs" / "msg" / f.name)
    return out


def walkers(t):
    """Two people crossing the room, back and forth along fixed lines, never reacting."""
    out = []
    for x0, y0, x1, y1, speed, phase in ((1.5, -1.5, 1.5, 4.5, 0.8, 0.0), (-1.5, 1.5, 5.5, 1.5, 1.0, 3.0)):
        length = math.hypot(x1 - x0, y1 - y0)
        s = (speed * t + phase) % (2 * length)
        forward = s < length
        d = s if forward else 2 * length - s
        ux, uy = (x1 - x0) / length, (y1 - y0) / length
        sign = 1.0 if forward else -1.0
        out.append(((x0 + ux * d, y0 + uy * d), (sign * ux * speed, sign * uy * speed)))
    return out


def cast(ox, oy, dx, dy, people):
    best = RANGE_MAX
    x0, y0, x1, y1 = ROOM
    for wall_t in (
        (x1 - ox) / dx if dx > 1e-12 else math.inf,
        (x0 - ox) / dx if dx < -1e-12 else math.inf,
        (y1 - oy) / dy if dy > 1e-12 else math.inf,
        (y0 - oy) / dy if dy < -1e-12 else math.inf,
    ):
        if 0 < wall_t < best:
            best = wall_t
    for (px, py), _ in people:
        fx, fy = ox - px, oy - py
        b = fx * dx + fy * dy
        disc = b * b - (fx * fx + fy * fy - PERSON_RADIUS**2)
        if disc >= 0:
            t = -b - math.sqrt(disc)
            if 0 < t < best:
                best = t
    return best if best < RANGE_MAX else math.inf


def publish_scanner_mount(args, ns, common, store, T):
    """base_link -> base_scan on /tf_static, once, as rmw_zenoh publishes a transient-local topic:
    an AdvancedPublisher with a cache of one sample on the topic's key (the SDK declares the
    key, its liveliness token and the attachment; it has no advanced publisher of its own)."""
    import zenoh
    import zenoh.ext
    from zenoh_ros2_sdk import ROS2Publisher
    from zenoh_ros2_sdk.qos import QosDurability, QosProfile

    qos = QosProfile(durability=QosDurability.TRANSIENT_LOCAL, history_depth=1)
    sdk = ROS2Publisher(topic="/tf_static", msg_type="tf2_msgs/msg/TFMessage", qos=qos, **common)
    publish_scanner_mount.keep = zenoh.ext.declare_advanced_publisher(
        sdk.session_mgr.session,
        sdk.keyexpr,
        cache=zenoh.ext.CacheConfig(max_samples=1),
        publisher_detection=True,
    )
    msg = T["tf2_msgs/msg/TFMessage"](
        transforms=[
            T["geometry_msgs/msg/TransformStamped"](
                header=T["std_msgs/msg/Header"](
                    stamp=T["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id="base_link"
                ),
                child_frame_id="base_scan",
                transform=T["geometry_msgs/msg/Transform"](
                    translation=T["geometry_msgs/msg/Vector3"](x=SCANNER_AHEAD, y=0.0, z=0.2),
                    rotation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=1.0, w=0.0),
                ),
            )
        ]
    )
    publish_scanner_mount.keep.put(
        bytes(store.serialize_cdr(msg, "tf2_msgs/msg/TFMessage")),
        encoding=zenoh.Encoding("application/cdr"),
        attachment=sdk._create_attachment(1, time.time_ns()),
    )
    publish_scanner_mount.sdk = sdk


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--namespace", default="/robot1")
    ap.add_argument("--router", default="127.0.0.1:7447")
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--log", required=True)
    ap.add_argument("--no-people", action="store_true", help="leave the people out of the people topic")
    ap.add_argument(
        "--localized", action="store_true", help="odometry in a drifted odom frame; the map pose on amcl_pose"
    )
    args = ap.parse_args()

    import numpy as np
    from zenoh_ros2_sdk import ROS2Publisher, ROS2Subscriber, get_topic_info
    from zenoh_ros2_sdk.message_registry import get_registry

    get_registry(str(message_dir()))
    host, port = args.router.rsplit(":", 1)
    ns = args.namespace.rstrip("/")
    common = dict(node_name="sim_robot", router_ip=host, router_port=int(port))
    odom_pub = ROS2Publisher(topic=f"{ns}/odom", msg_type="nav_msgs/msg/Odometry", **common)
    scan_pub = ROS2Publisher(topic=f"{ns}/scan", msg_type="sensor_msgs/msg/LaserScan", **common)
    people_pub = ROS2Publisher(topic=f"{ns}/people", msg_type="people_msgs/msg/People", **common)
    amcl_pub = (
        ROS2Publisher(
            topic=f"{ns}/amcl_pose", msg_type="geometry_msgs/msg/PoseWithCovarianceStamped", **common
        )
        if args.localized
        else None
    )
    store = odom_pub.session_mgr.store
    T = store.types
    publish_scanner_mount(args, ns, common, store, T)

    cmd = {"v": 0.0, "w": 0.0, "at": -1.0}
    lock = threading.Lock()
    received = {"n": 0}

    def on_cmd(msg):
        with lock:
            cmd["v"], cmd["w"], cmd["at"] = float(msg.linear.x), float(msg.angular.z), time.monotonic()
            received["n"] += 1

    ROS2Subscriber(topic=f"{ns}/cmd_vel", msg_type="geometry_msgs/msg/Twist", callback=on_cmd, **common)

    def header(t, frame):
        return T["std_msgs/msg/Header"](
            stamp=T["builtin_interfaces/msg/Time"](sec=int(t), nanosec=int((t % 1) * 1e9)), frame_id=frame
        )

    def v3(x, y, z=0.0):
        return T["geometry_msgs/msg/Vector3"](x=x, y=y, z=z)

    def pt(x, y):
        return T["geometry_msgs/msg/Point"](x=x, y=y, z=0.0)

    x, y, yaw, v, w = 0.0, 0.0, 0.0, 0.0, 0.0
    dt = 0.05
    log = open(args.log, "w")
    start = time.monotonic()
    step = 0
    touching = set()
    graph_logged = False
    previous = None  # (t, x, y, yaw) at the last odometry, for amcl_pose

    def quat(a):
        return T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(a / 2), w=math.cos(a / 2))

    def in_odom(px, py, pyaw):
        """A map pose in the drifted odom frame (--localized), else unchanged."""
        if not args.localized:
            return px, py, pyaw
        mx, my, myaw = MAP_FROM_ODOM
        dx, dy = px - mx, py - my
        c, s_ = math.cos(-myaw), math.sin(-myaw)
        return c * dx - s_ * dy, s_ * dx + c * dy, pyaw - myaw

    while True:
        now = time.monotonic()
        t = now - start
        if t > args.seconds:
            break
        with lock:
            fresh = now - cmd["at"] < 0.5
            v_cmd, w_cmd = (cmd["v"], cmd["w"]) if fresh else (0.0, 0.0)
        v += max(-1.5 * dt, min(1.5 * dt, max(-1.0, min(1.0, v_cmd)) - v))
        w += max(-1.5 * dt, min(1.5 * dt, max(-1.0, min(1.0, w_cmd)) - w))
        yaw += w * dt
        x += v * math.cos(yaw) * dt
        y += v * math.sin(yaw) * dt
        people = walkers(t)
        contacts = []
        for i, ((px, py), (vx, vy)) in enumerate(people):
            gap = math.hypot(px - x, py - y) - ROBOT_RADIUS - PERSON_RADIUS
            if gap <= 0 and i not in touching:
                ux, uy = (px - x) / max(1e-9, math.hypot(px - x, py - y)), (py - y) / max(1e-9, math.hypot(px - x, py - y))
                toward = v * (math.cos(yaw) * ux + math.sin(yaw) * uy)
                contacts.append({"person": i, "robot_toward": toward})
            (touching.add if gap <= 0 else touching.discard)(i)
        x0, y0, x1, y1 = ROOM
        wall_gap = min(x - x0, x1 - x, y - y0, y1 - y) - ROBOT_RADIUS
        if step % 2 == 0:  # 10 Hz sensors, 20 Hz physics
            cov = np.zeros(36, dtype=np.float64)
            ox, oy, oyaw = in_odom(x, y, yaw)
            odom_pub.publish(
                header=header(t, "odom" if args.localized else "map"),
                child_frame_id="base_link",
                pose=T["geometry_msgs/msg/PoseWithCovariance"](
                    pose=T["geometry_msgs/msg/Pose"](position=pt(ox, oy), orientation=quat(oyaw)),
                    covariance=cov,
                ),
                twist=T["geometry_msgs/msg/TwistWithCovariance"](
                    twist=T["geometry_msgs/msg/Twist"](linear=v3(v, 0.0), angular=v3(0.0, 0.0, w)), covariance=cov
                ),
            )
            inc = 2 * math.pi / RAYS
            sx, sy, syaw = x + SCANNER_AHEAD * math.cos(yaw), y + SCANNER_AHEAD * math.sin(yaw), yaw + math.pi
            ranges = np.array(
                [cast(sx, sy, math.cos(syaw + k * inc), math.sin(syaw + k * inc), people) for k in range(RAYS)],
                dtype=np.float32,
            )
            scan_pub.publish(
                header=header(t, "base_scan"),
                angle_min=0.0,
                angle_max=float(2 * math.pi - inc),
                angle_increment=float(inc),
                time_increment=0.0,
                scan_time=0.1,
                range_min=0.05,
                range_max=RANGE_MAX,
                ranges=ranges,
                intensities=np.array([], dtype=np.float32),
            )
            if amcl_pub is not None and previous is not None and step % 10 == 0:  # 2 Hz
                pt_, px_, py_, pyaw_ = previous
                amcl_pub.publish(
                    header=header(pt_, "map"),
                    pose=T["geometry_msgs/msg/PoseWithCovariance"](
                        pose=T["geometry_msgs/msg/Pose"](position=pt(px_, py_), orientation=quat(pyaw_)),
                        covariance=cov,
                    ),
                )
            previous = (t, x, y, yaw)
            tracked = [] if args.no_people else people
            people_pub.publish(
                header=header(t, "map"),
                people=[
                    T["people_msgs/msg/Person"](
                        name=f"walker_{i}",
                        position=pt(px, py),
                        velocity=pt(vx, vy),
                        reliability=1.0,
                        tagnames=[],
                        tags=[],
                    )
                    for i, ((px, py), (vx, vy)) in enumerate(tracked)
                ],
            )
        log.write(
            json.dumps(
                {
                    "t": round(t, 3),
                    "x": x,
                    "y": y,
                    "yaw": yaw,
                    "v": v,
                    "people": [p for p, _ in people],
                    "contacts": contacts,
                    "wall_gap": wall_gap,
                    "commands": received["n"],
                }
            )
            + "\n"
        )
        if not graph_logged and received["n"] > 0:
            graph_logged = True

            def endpoints(infos):
                return [
                    {"node": e.node_name, "namespace": e.node_namespace, "type": e.topic_type, "hash": e.type_hash}
                    for e in infos
                ]

            cmd_info = get_topic_info(f"{ns}/cmd_vel", router_ip=host, router_port=int(port), verbose=True)
            odom_info = get_topic_info(f"{ns}/odom", router_ip=host, router_port=int(port), verbose=True)
            log.write(
                json.dumps(
                    {
                        "graph": {
                            "cmd_vel_publishers": endpoints(cmd_info.publishers if cmd_info else []),
                            "odom_subscribers": endpoints(odom_info.subscribers if odom_info else []),
                        }
                    }
                )
                + "\n"
            )
        log.flush()
        step += 1
        time.sleep(max(0.0, start + step * dt - time.monotonic()))
    log.close()
    print(f"robot: {received['n']} commands received, ended at ({x:.2f}, {y:.2f})", file=sys.stderr)


if __name__ == "__main__":
    main()
