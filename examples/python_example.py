"""proxima from Python: one query, tracking with a cache, and a batch.

Build and run from a fresh clone:
    make python
    PYTHONPATH=build/release/python /usr/bin/python3 examples/python_example.py
"""
import numpy as np

import proxima

rng = np.random.default_rng(7)
a = proxima.ConvexPolytope(rng.normal(size=(40, 3)))  # the hull of 40 points
b = proxima.ConvexPolytope(rng.uniform(-1, 1, size=(30, 3)))

# Poses: None (identity), a 4x4 matrix or (quaternion wxyz, translation).
r = proxima.distance(a, None, b, ((1, 0, 0, 0), (4, 0, 0)))
print(r.status, r.distance, r.point_a, r.point_b, r.feature_a, r.feature_b)

# Tracking: keep one cache per pair and pass it to every query of that pair.
cache = proxima.DistanceCache()
for x in np.linspace(4.0, 3.0, 11):
    r = proxima.distance(a, None, b, ((1, 0, 0, 0), (x, 0, 0)), cache=cache)
print("tracked, after 11 steps:", r.distance, "in", r.iterations, "iterations")

# A batch: 1000 poses of B, on all cores, without the GIL.
poses_b = np.tile(np.eye(4), (1000, 1, 1))
poses_b[:, 0, 3] = np.linspace(6.0, 0.0, 1000)
out = proxima.distance_batch(a, None, b, poses_b)
first_contact = np.argmax(out["status"] != "separated")
print("first contact at x =", poses_b[first_contact, 0, 3])

assert out["distance"][0] == proxima.distance(a, None, b, poses_b[0]).distance
