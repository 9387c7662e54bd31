# proxima: minimum distance between convex polyhedra.
# SPDX-License-Identifier: BSD-3-Clause
"""A robot from its URDF, run by `make test`: the Franka Emika Panda
(examples/data/panda) with a table in front of it, its minimum signed distance and gradient
along a short trajectory (tracked), then a batch of random configurations on
all cores, checked against one query per row; a mismatch exits 1.

    python3 examples/robot_urdf.py [panda folder]
"""
import pathlib
import sys

import numpy as np

import proxima

DATA = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else pathlib.Path(__file__).parent / "data" / "panda"

robot = proxima.Robot(str(DATA / "panda.urdf"), srdf=str(DATA / "panda.srdf"))
robot.set_environment([(proxima.box((0.25, 0.5, 0.02)), proxima.Pose.from_translation((0.75, 0, 0.18)))])
print(f"{robot.name}: joints {robot.joint_names}")

q = np.array([0, -0.785, 0, -2.356, 0, 1.571, 0.785, 0.01])
for step in range(10):
    q[1] += 0.08
    q[5] -= 0.12
    r = robot.distances(q, margin=0.05, gradients=True)
    print(f"step {step}: {r.min_signed_distance:.4f} m, {len(r.close_pairs)} pairs within 5 cm, "
          f"d/dq6 {r.gradient[5]:.4f}")

rng = np.random.default_rng(1)
qs = rng.uniform(robot.lower_limits, robot.upper_limits, size=(200, robot.dof))
minima, gradients = robot.distances_batch(qs)
robot.reset()
mismatches = sum(abs(minima[k] - robot.distances(qs[k]).min_signed_distance) > 1e-9 for k in range(len(qs)))
print(f"batch of {len(qs)}: {np.sum(minima < 0)} in collision, {mismatches} mismatches")
sys.exit(1 if mismatches else 0)
