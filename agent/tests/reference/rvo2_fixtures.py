"""Generate ORCA reference trajectories with RVO2 (C++ via pyrvo2-danieldugas).

Writes agent/tests/fixtures/rvo2_<scenario>.json, read by agent/tests/rvo2_crosscheck.rs.

    python -m venv .venv && .venv/bin/pip install cython numpy wheel setuptools
    .venv/bin/pip install --no-build-isolation pyrvo2-danieldugas==0.0.2   # needs cmake
    .venv/bin/python agent/tests/reference/rvo2_fixtures.py

Scenarios:
  circle   RVO2's examples/Circle.cpp as shipped (250 agents on a 200 m circle).
  blocks   RVO2's examples/Blocks.cpp (100 agents, four square obstacles); its rand()-based
           preferred-velocity jitter is replaced by a deterministic hash both sides compute.
  corridor PGP paper Table I parameters (d_neighbor 4 m, 5 neighbours, horizon 2.5 s,
           dt 0.25 s, v_max 1 m/s) with two walls (2-vertex obstacles) and a pillar.

Preferred velocities are computed in float64 exactly as the Rust harness does, then passed to
RVO2 (which rounds them to float32, as Rust's `as f32` does).
"""
import json
import math
import pathlib

import rvo2

OUT = pathlib.Path(__file__).resolve().parent.parent / "fixtures"


def jitter(i, step):
    """Deterministic stand-in for Blocks.cpp's rand() jitter (same formula in Rust)."""
    h = (i * 2654435761 + step * 40503 + 12345) % (1 << 32)
    angle = h / float(1 << 32) * 2.0 * math.pi
    dist = ((h >> 7) % 1000) / 1000.0 * 0.0001
    return dist * math.cos(angle), dist * math.sin(angle)


def pref_velocity(goal, pos, i, step, use_jitter):
    gx, gy = goal[0] - pos[0], goal[1] - pos[1]
    if gx * gx + gy * gy > 1.0:
        n = math.sqrt(gx * gx + gy * gy)
        gx, gy = gx / n, gy / n
    if use_jitter:
        jx, jy = jitter(i, step)
        gx, gy = gx + jx, gy + jy
    return gx, gy


def run(name, params, starts, goals, obstacles, steps, every, use_jitter):
    time_step, neighbor_dist, max_neighbors, horizon, horizon_obst, radius, max_speed = params
    sim = rvo2.PyRVOSimulator(time_step, neighbor_dist, max_neighbors, horizon, horizon_obst, radius, max_speed)
    for s in starts:
        sim.addAgent(tuple(s))
    for o in obstacles:
        sim.addObstacle([tuple(v) for v in o])
    sim.processObstacles()
    frames = []
    for step in range(steps + 1):
        if step % every == 0:
            frames.append({"step": step, "positions": [list(sim.getAgentPosition(i)) for i in range(len(starts))]})
        if step == steps:
            break
        for i in range(len(starts)):
            sim.setAgentPrefVelocity(i, pref_velocity(goals[i], sim.getAgentPosition(i), i, step, use_jitter))
        sim.doStep()
    fixture = {
        "scenario": name,
        "generator": "agent/tests/reference/rvo2_fixtures.py with pyrvo2-danieldugas 0.0.2 (RVO2 2.0.x, float32)",
        "time_step": time_step,
        "neighbor_dist": neighbor_dist,
        "max_neighbors": max_neighbors,
        "time_horizon": horizon,
        "time_horizon_obst": horizon_obst,
        "radius": radius,
        "max_speed": max_speed,
        "jitter": use_jitter,
        "starts": starts,
        "goals": goals,
        "obstacles": obstacles,
        "frames": frames,
    }
    path = OUT / f"rvo2_{name}.json"
    path.write_text(json.dumps(fixture, separators=(",", ":")))
    print(f"{path}: {len(frames)} frames, {len(starts)} agents")


def circle():
    starts, goals = [], []
    for i in range(250):
        # Circle.cpp computes the start in float; we pass doubles that RVO2 rounds to float.
        a = i * 2.0 * math.pi / 250.0
        starts.append([200.0 * math.cos(a), 200.0 * math.sin(a)])
        goals.append([-starts[-1][0], -starts[-1][1]])
    run("circle", (0.25, 15.0, 10, 10.0, 10.0, 1.5, 2.0), starts, goals, [], 1600, 40, False)


def blocks():
    starts, goals = [], []
    for i in range(5):
        for j in range(5):
            for sx, sy in ((1, 1), (-1, 1), (1, -1), (-1, -1)):
                starts.append([sx * (55.0 + i * 10.0), sy * (55.0 + j * 10.0)])
                goals.append([-sx * 75.0, -sy * 75.0])
    obstacles = [
        [[-10.0, 40.0], [-40.0, 40.0], [-40.0, 10.0], [-10.0, 10.0]],
        [[10.0, 40.0], [10.0, 10.0], [40.0, 10.0], [40.0, 40.0]],
        [[10.0, -40.0], [40.0, -40.0], [40.0, -10.0], [10.0, -10.0]],
        [[-10.0, -40.0], [-10.0, -10.0], [-40.0, -10.0], [-40.0, -40.0]],
    ]
    run("blocks", (0.25, 15.0, 10, 5.0, 5.0, 2.0, 2.0), starts, goals, obstacles, 1400, 40, True)


def corridor():
    starts, goals = [], []
    for k in range(4):
        y = -1.2 + 0.8 * k
        starts.append([-6.0, y]); goals.append([6.0, -y])
        starts.append([6.0, y + 0.4]); goals.append([-6.0, -y - 0.4])
    walls = [[[-8.0, 2.0], [8.0, 2.0]], [[8.0, -2.0], [-8.0, -2.0]]]
    pillar = [[[-0.3, -0.3], [0.3, -0.3], [0.3, 0.3], [-0.3, 0.3]]]
    run("corridor", (0.25, 4.0, 5, 2.5, 2.5, 0.3, 1.0), starts, goals, walls + pillar, 160, 4, False)


if __name__ == "__main__":
    OUT.mkdir(parents=True, exist_ok=True)
    circle()
    blocks()
    corridor()
