"""proxima from Python: one query, tracking with a cache, a batch, a compound body, a scene.

Build and run from a fresh clone:
    make python
    PYTHONPATH=build/release/python /usr/bin/python3 examples/python_example.py
"""
import numpy as np

import proxima

rng = np.random.default_rng(7)
a = proxima.ConvexPolytope(rng.normal(size=(40, 3)))  # the hull of 40 points
b = proxima.ConvexPolytope(rng.uniform(-1, 1, size=(30, 3)))

# Poses: None (identity), a 4x4 or 3x4 matrix, a scipy Rotation, a Pose, or
# (rotation matrix, translation). A quaternion names its order: ROS and scipy
# write (x, y, z, w), Pose.from_xyzw(q, t); Eigen (w, x, y, z), Pose.from_wxyz.
r = proxima.distance(a, None, b, proxima.Pose.from_translation((4, 0, 0)))
r = proxima.distance(a, None, b, proxima.Pose.from_xyzw((0, 0, 0, 1), (4, 0, 0)))  # the same pose
print(r.status, r.distance, r.point_a, r.point_b, r.feature_a, r.feature_b)

# Tracking: keep one cache per pair and pass it to every query of that pair.
cache = proxima.DistanceCache()
for x in np.linspace(4.0, 3.0, 11):
    r = proxima.distance(a, None, b, proxima.Pose.from_translation((x, 0, 0)), cache=cache)
print("tracked, after 11 steps:", r.distance, "in", r.iterations, "iterations")

# A batch: 1000 poses of B, on all cores, without the GIL.
poses_b = np.tile(np.eye(4), (1000, 1, 1))
poses_b[:, 0, 3] = np.linspace(6.0, 0.0, 1000)
out = proxima.distance_batch(a, None, b, poses_b)

pairs = proxima.PairBatch([a, a, b], [b, b, b])   # K different pairs, caches kept inside
out = pairs.distance(None, poses_b[:3])          # one call; out["distance"] has K rows
first_contact = np.argmax(out["status"] != "separated")
print("first contact at x =", poses_b[first_contact, 0, 3])

assert out["distance"][0] == proxima.distance(a, None, b, poses_b[0]).distance

# A non-convex body as a union of convex pieces (here two boxes making an L;
# CompoundBody.from_file reads one piece per OBJ group).
box = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
ell = proxima.CompoundBody([box * [3, 1, 1], box * [1, 3, 1]])
cache = proxima.CompoundCache()
r = proxima.distance(ell, None, ell, proxima.Pose.from_translation((2.5, 2.5, 0)), cache=cache)
print("compound:", r.status, r.distance, "pieces", r.piece_a, r.piece_b)
assert abs(r.distance - 1.5) < 1e-12  # bar to bar, across the gap in y

# A scene: 200 bodies moved each step; step() returns the pairs within the
# margin, each tracked with its own cache across steps.
scene = proxima.Scene(margin=0.1)
positions = rng.uniform(0, 12, size=(200, 3))
ids = np.array([scene.add(b if i % 2 else ell, proxima.Pose.from_translation(p))
                for i, p in enumerate(positions)])
poses = np.tile(np.eye(4), (200, 1, 1))
for step in range(10):
    positions += rng.normal(scale=0.02, size=positions.shape)
    poses[:, :3, 3] = positions
    scene.set_poses(ids, poses)
    pairs = scene.step()
print("scene:", len(pairs), "close pairs of", scene.stats.candidate_pairs, "candidates")
assert [(p.a, p.b) for p in pairs] == [(p.a, p.b) for p in scene.close_pairs_all_pairs()]
