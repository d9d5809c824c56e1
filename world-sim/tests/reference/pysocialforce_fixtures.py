"""Generate Social Force reference trajectories with PySocialForce 1.1.2.

Writes world-sim/tests/fixtures/pysf_<scene>_<params>.json, read by
world-sim/tests/pysocialforce_crosscheck.rs. (The committed fixtures were generated before the
crowd moved from agent to world-sim, so their "generator" field names this script's old path,
agent/tests/reference/; they are kept byte for byte as generated.)

    python -m venv .venv && .venv/bin/pip install pysocialforce==1.1.2
    .venv/bin/python world-sim/tests/reference/pysocialforce_fixtures.py

Parameter sets:
  default  PySocialForce's default.toml (the simulated humans).
  table_i  the PGP paper's Table I for the Social Force agent: A = 5.1, lambda = 3.0,
           gamma = 0.35, n = 1, n' = 3.0, everything else default.
Both at step_width 0.1 s. PySocialForce's Config.load_config replaces whole sections, so
every key of every section is written out. (The group coherence and gaze forces it uses are
the Alt classes, which read [group_coherence_force_alt] / [group_gaze_force_alt]: absent, so
they act with factor 1.0 whatever [group_coherence_force] and [group_gaze_force] say.)
"""
import json
import pathlib
import tempfile

import numpy as np
import pysocialforce as psf

OUT = pathlib.Path(__file__).resolve().parent.parent / "fixtures"
STEP_WIDTH = 0.1
STEPS = 150

BASE = """
step_width = {step_width}
agent_radius = 0.35
max_speed_multiplier = 1.3
tau = 0.5
resolution = 10

[scene]
enable_group = true

[desired_force]
factor = 1.0
relaxation_time = 0.5
goal_threshold = 0.2

[social_force]
factor = 5.1
lambda_importance = {lam}
gamma = 0.35
n = {n}
n_prime = 3

[obstacle_force]
factor = 10.0
sigma = 0.2
threshold = 3.0

[group_coherence_force]
factor = 3.0

[group_repulsive_force]
factor = 1.0
threshold = 0.55

[group_gaze_force]
factor = 4.0
fov_phi = 90.0
"""

PARAMS = {"default": {"lam": 2.0, "n": 2}, "table_i": {"lam": 3.0, "n": 1}}

# Each scene: rows of (x, y, vx, vy, goal_x, goal_y), groups, obstacles as (x1, x2, y1, y2)
# in PySocialForce's own order.
SCENES = {
    "head_on_pair": (
        [[-5.0, 0.0, 1.0, 0.0, 5.0, 0.0], [5.0, 0.1, -1.0, 0.0, -5.0, 0.1]],
        [],
        [],
    ),
    "group_crossing_line": (
        [
            [-4.0, -0.4, 0.8, 0.0, 5.0, -0.4],
            [-4.0, 0.4, 0.8, 0.0, 5.0, 0.4],
            [-4.6, 0.0, 0.8, 0.0, 5.0, 0.0],
            [4.0, 2.5, -1.0, 0.0, -5.0, 2.5],
        ],
        [[0, 1, 2], [3]],
        [(0.0, 0.0, -3.0, -0.2)],
    ),
    "two_groups_passing": (
        [
            [-5.0, -0.5, 1.0, 0.0, 6.0, -0.5],
            [-5.0, 0.3, 1.0, 0.0, 6.0, 0.3],
            [-5.8, -0.1, 1.0, 0.0, 6.0, -0.1],
            [5.0, 0.0, -1.0, 0.0, -6.0, 0.0],
            [5.0, 0.8, -1.0, 0.0, -6.0, 0.8],
        ],
        [[0, 1, 2], [3, 4]],
        [],
    ),
}


def run(scene, params):
    state, groups, obstacles = SCENES[scene]
    with tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False) as f:
        f.write(BASE.format(step_width=STEP_WIDTH, **PARAMS[params]))
        config = f.name
    sim = psf.Simulator(np.array(state, dtype=float), groups=[list(g) for g in groups],
                        obstacles=list(obstacles) or None, config_file=config)
    sim.step(STEPS)
    states, _ = sim.get_states()
    fixture = {
        "scene": scene,
        "params": params,
        "generator": "world-sim/tests/reference/pysocialforce_fixtures.py with pysocialforce 1.1.2",
        "step_width": STEP_WIDTH,
        "lambda_importance": PARAMS[params]["lam"],
        "n": PARAMS[params]["n"],
        "initial": state,
        "groups": groups,
        "obstacles": [list(o) for o in obstacles],
        "positions": states[:, :, 0:2].tolist(),
    }
    path = OUT / f"pysf_{scene}_{params}.json"
    path.write_text(json.dumps(fixture, separators=(",", ":")))
    print(f"{path}: {states.shape[0]} states of {states.shape[1]} agents")


if __name__ == "__main__":
    OUT.mkdir(parents=True, exist_ok=True)
    for scene in SCENES:
        for params in PARAMS:
            run(scene, params)
