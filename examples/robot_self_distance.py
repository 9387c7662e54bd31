"""A robot's self-distance from Python: examples/robot_self_distance.cpp, the same steps.

The Franka Emika Panda's seven links and hand, each the convex hull of its
collision mesh, placed by forward kinematics in a proxima.Scene; adjacent
links are excluded; the arm moves along a seeded trajectory within the joint
limits and each configuration prints the closest pair of non-adjacent links.
Some configurations are checked against scene.close_pairs_all_pairs() (cold
queries on every pair); a mismatch exits with status 1.

    make python
    PYTHONPATH=build/release/python /usr/bin/python3 examples/robot_self_distance.py [mesh directory]
"""
import pathlib
import sys
import time

import numpy as np

import proxima

MESH_DIR = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else (
    pathlib.Path(__file__).resolve().parent / "data" / "panda")

# The Panda's kinematics, copied from franka_description's franka_arm.xacro
# (franka_ros): joint i moves link i relative to link i-1; <origin xyz rpy>
# places the joint frame in the parent link's frame and the joint turns about
# its <axis> (z for all seven). Metres and radians. The limits are
# joint_limits.yaml's lower and upper.
PI = np.pi
JOINTS = [  # (xyz, rpy, lower, upper)
    ((0, 0, 0.333), (0, 0, 0), -2.8973, 2.8973),             # joint1: link0 -> link1
    ((0, 0, 0), (-PI / 2, 0, 0), -1.7628, 1.7628),           # joint2: link1 -> link2
    ((0, -0.316, 0), (PI / 2, 0, 0), -2.8973, 2.8973),       # joint3: link2 -> link3
    ((0.0825, 0, 0), (PI / 2, 0, 0), -3.0718, -0.0698),      # joint4: link3 -> link4
    ((-0.0825, 0.384, 0), (-PI / 2, 0, 0), -2.8973, 2.8973),  # joint5: link4 -> link5
    ((0, 0, 0), (PI / 2, 0, 0), -0.0175, 3.7525),            # joint6: link5 -> link6
    ((0.088, 0, 0), (PI / 2, 0, 0), -2.8973, 2.8973),        # joint7: link6 -> link7
]
# The fixed joint8 (franka_arm.xacro): link8 = link7 moved by z 0.107. The hand
# hangs from link8 turned by yaw -pi/4: franka_ros's robot xacros mount it with
# <xacro:franka_hand rpy="0 0 ${-pi/4}" connected_to="..._link8"/> (not in
# franka_arm.xacro).
LINK8_OFFSET = (0, 0, 0.107)
HAND_YAW = -PI / 4
LINK_NAMES = ["link0", "link1", "link2", "link3", "link4", "link5", "link6", "link7", "hand"]


def rot_x(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rot_z(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def transform(rotation=np.eye(3), translation=(0, 0, 0)):
    t = np.eye(4)
    t[:3, :3] = rotation
    t[:3, 3] = translation
    return t


def link_poses(q):
    """Each body's pose (world from body, 4x4) for joint angles q; link0 at the origin."""
    poses = [np.eye(4)]
    for (xyz, (roll, pitch, yaw), _, _), angle in zip(JOINTS, q):
        origin = transform(rot_z(yaw) @ rot_y(pitch) @ rot_x(roll), xyz)  # URDF rpy
        poses.append(poses[-1] @ origin @ transform(rot_z(angle)))
    link8 = poses[7] @ transform(translation=LINK8_OFFSET)
    poses.append(link8 @ transform(rot_z(HAND_YAW)))
    return np.array(poses)


def splitmix64(seed):
    """SplitMix64, as in the C++ example (same numbers): uniform doubles in [0, 1)."""
    mask = (1 << 64) - 1
    while True:
        seed = (seed + 0x9E3779B97F4A7C15) & mask
        z = seed
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & mask
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & mask
        yield ((z ^ (z >> 31)) >> 11) * 2.0**-53


def trajectory(seed, waypoints, steps):
    """Random waypoints inside the joint limits, joined by straight lines in joint space."""
    uniform = splitmix64(seed)
    points = [[lower + next(uniform) * (upper - lower) for _, _, lower, upper in JOINTS]
              for _ in range(waypoints)]
    path = []
    for w in range(waypoints - 1):
        for s in range(steps):
            t = s / steps
            path.append([(1 - t) * a + t * b for a, b in zip(points[w], points[w + 1])])
    return path


def same_pairs(fast, slow):
    return len(fast) == len(slow) and all(
        f.a == s.a and f.b == s.b
        and abs(f.result.distance - s.result.distance) <= 1e-9 * (1 + s.result.distance)
        for f, s in zip(fast, slow))


scene = proxima.Scene(margin=0.05)  # report pairs of links closer than 5 cm
home = link_poses([0, 0, 0, -1.5, 0, 1.5, 0])
ids = []
for name, pose in zip(LINK_NAMES, home):
    loaded = proxima.load_convex(str(MESH_DIR / f"{name}.stl"))  # the hull, in the link's frame
    print(f"{name:5} {loaded.input_points:4} points, hull of {loaded.polytope.vertex_count:3} vertices")
    ids.append(scene.add(loaded.polytope, pose))
for a, b in zip(ids, ids[1:]):  # adjacent links touch at their joint: never test them
    scene.exclude_pair(a, b)

path = trajectory(2026, 5, 40)
mismatches = checked = 0
seconds = 0.0
for c, q in enumerate(path):
    poses = link_poses(q)
    start = time.perf_counter()
    scene.set_poses(ids, poses)
    pairs = scene.step()
    seconds += time.perf_counter() - start
    if pairs:
        p = min(pairs, key=lambda p: p.result.distance)
        a, b = LINK_NAMES[ids.index(p.a)], LINK_NAMES[ids.index(p.b)]
        print(f"config {c:3}: closest {a}-{b} {p.result.status:12} {p.result.distance:.4f} m "
              f"({len(pairs)} pairs within 5 cm)")
    else:
        print(f"config {c:3}: no pair of non-adjacent links within 5 cm")
    if c % 20 == 0:  # check against the slow twin: cold queries on every tested pair
        checked += 1
        if not same_pairs(pairs, scene.close_pairs_all_pairs()):
            mismatches += 1
            print(f"config {c:3}: MISMATCH against close_pairs_all_pairs")
print(f"{len(path)} configurations, {1e6 * seconds / len(path):.2f} us per configuration "
      "(set 9 poses and step, tracked)")
print(f"{'ok' if mismatches == 0 else 'FAILED'}: {mismatches} mismatches in {checked} "
      "configurations checked against close_pairs_all_pairs")
sys.exit(1 if mismatches else 0)
