#!/usr/bin/python3
# proxima: a batch of K tracked pairs from Python against the same batch in
# C++, measured side by side in one run (issue 11, "Python at C++ speed").
# SPDX-License-Identifier: BSD-3-Clause
#
#   PYTHONPATH=build/release/python /usr/bin/python3 bench/python_pair_batch.py [--pairs 1000] [--steps 200]
#
# Each step moves every pair's B a little (tracking) and calls
# PairBatch.distance once on each of two twin batches, in turns: one filling
# the arrays of its previous answer again (out=, the loop a planner writes),
# one returning new arrays (the default). The Python time is the wall time
# of a call (pose conversion, the batch, the numpy result); the C++ time is
# PairBatch.last_call_seconds, the part of the same call spent in C++'s
# distance_batch, which is what the same batch costs from C++. Prints the
# medians over the steps and their ratios, for threads = 1 (all in the
# calling thread) and threads = 0 (all cores).
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
    print(f"pairs {k}, steps {args.steps}, proxima {proxima.__version__ if hasattr(proxima, '__version__') else 'module'} from the build tree")
    for threads in (1, 0):
        reused, fresh = proxima.PairBatch(a, b), proxima.PairBatch(a, b)
        out = None
        seconds = {"out": ([], []), "new": ([], [])}  # (Python, C++) per call
        for step in range(args.steps):
            angle = 0.01 * step
            poses_b[:, :3, 3] = directions * (2.5 + 0.3 * np.sin(angle))
            for kind in ("out", "new") if step % 2 == 0 else ("new", "out"):
                start = time.perf_counter()
                if kind == "out":
                    out = reused.distance(poses_a, poses_b, threads=threads, out=out)
                else:
                    fresh_out = fresh.distance(poses_a, poses_b, threads=threads)
                python_s = time.perf_counter() - start
                seconds[kind][0].append(python_s)
                seconds[kind][1].append((reused if kind == "out" else fresh).last_call_seconds)
        assert all(np.array_equal(out[key], fresh_out[key]) for key in out)  # the same answers
        us = {kind: [statistics.median(s) * 1e6 for s in seconds[kind]] for kind in seconds}
        print(f"threads {threads}: Python call {us['out'][0]:.0f} us with out=, {us['new'][0]:.0f} us "
              f"with new arrays; C++ batch {us['out'][1]:.0f} and {us['new'][1]:.0f} us (medians of "
              f"{args.steps}); ratio {us['out'][0] / us['out'][1]:.2f} with out=, "
              f"{us['new'][0] / us['new'][1]:.2f} with new arrays; "
              f"{us['out'][1] * 1e3 / k:.0f} ns per pair in C++, "
              f"separated {np.mean(out['status'] == 'separated'):.2f}")


if __name__ == "__main__":
    main()
