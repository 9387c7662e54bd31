#!/usr/bin/python3
# proxima: a batch of K tracked pairs from Python against the same batch in
# C++, measured side by side in one run (issue 11, "Python at C++ speed").
# SPDX-License-Identifier: BSD-3-Clause
#
#   PYTHONPATH=build/release/python bench/python_pair_batch.py [--pairs 1000] [--steps 200]
#
# Each step moves every pair's B a little (tracking) and calls
# PairBatch.distance once. The Python time is the wall time of that call
# (pose conversion, the batch, the numpy result dict); the C++ time is
# PairBatch.last_call_seconds, the part of the same call spent in C++'s
# distance_batch. Prints the medians over the steps and their ratio, for
# threads = 1 (all in the calling thread) and threads = 0 (all cores).
import argparse
import statistics
import time

import numpy as np
import proxima


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--pairs", type=int, default=1000)
    parser.add_argument("--steps", type=int, default=200)
    args = parser.parse_args()
    rng = np.random.default_rng(2026)
    # Link-like hulls: 20 to 100 points each, radius about 1.
    shapes = [proxima.ConvexPolytope(rng.normal(size=(int(rng.integers(20, 100)), 3)) * 0.5)
              for _ in range(16)]
    k = args.pairs
    a = [shapes[i % 16] for i in range(k)]
    b = [shapes[(5 * i + 3) % 16] for i in range(k)]
    poses_a = np.tile(np.eye(4), (k, 1, 1))
    poses_b = np.tile(np.eye(4), (k, 1, 1))
    directions = rng.normal(size=(k, 3))
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    poses_b[:, :3, 3] = directions * 2.5
    print(f"pairs {k}, steps {args.steps}, proxima {proxima.__file__}")
    for threads in (1, 0):
        batch = proxima.PairBatch(a, b)
        python_s, cpp_s = [], []
        for step in range(args.steps):
            angle = 0.01 * step
            poses_b[:, :3, 3] = directions * (2.5 + 0.3 * np.sin(angle))
            start = time.perf_counter()
            out = batch.distance(poses_a, poses_b, threads=threads)
            python_s.append(time.perf_counter() - start)
            cpp_s.append(batch.last_call_seconds)
        py_us = statistics.median(python_s) * 1e6
        cpp_us = statistics.median(cpp_s) * 1e6
        print(f"threads {threads}: Python call {py_us:.0f} us, C++ batch {cpp_us:.0f} us "
              f"(median of {args.steps}), ratio {py_us / cpp_us:.2f}; "
              f"{cpp_us * 1e3 / k:.0f} ns per pair in C++, separated {np.mean(out['status'] == 'separated'):.2f}")


if __name__ == "__main__":
    main()
