# proxima: minimum distance between convex polyhedra.
# SPDX-License-Identifier: BSD-3-Clause
"""A dataset of signed distances and their gradients for many robot
configurations (for learned collision checkers and distance fields), computed
on a Dask cluster: the configurations are a chunked Dask array, each chunk a
partition that one worker process turns into minima and gradients with
proxima's batch query (docs/robotics.md). Run by `make test` on a small K.

    python3 examples/robot_dataset_dask.py [--samples K] [--workers W]
        [--partitions P] [--scheduler ADDRESS] [--out dataset.npz]
        [--check] [--compare] [--urdf panda.urdf --srdf panda.srdf]

Without --scheduler it starts a local cluster of W worker processes (one
thread each); with --scheduler tcp://host:8786 it runs unchanged on an
existing cluster of any number of machines (each worker needs proxima
installed and the robot's files at the same paths). --check compares every
row with one robot.distances() per row in this process; --compare times the
same work on one worker process and on W, and prints both throughputs.
"""
import argparse
import pathlib
import sys
import time

import dask.array as da
import numpy as np
from distributed import Client, LocalCluster, get_worker

import proxima

DATA = pathlib.Path(__file__).parent / "data" / "panda"


def robot_of(urdf, srdf):
    """The robot, loaded once per worker process and kept on the worker."""
    try:
        holder = get_worker()
    except ValueError:  # not on a worker: this process
        holder = sys.modules[__name__]
    robots = getattr(holder, "proxima_robots", None)
    if robots is None:
        robots = {}
        setattr(holder, "proxima_robots", robots)
    if (urdf, srdf) not in robots:
        robots[(urdf, srdf)] = proxima.Robot(urdf, srdf=srdf or None)
    return robots[(urdf, srdf)]


def load(urdf, srdf):
    """Loads the robot on a worker (the answer stays there)."""
    robot_of(urdf, srdf)


def partition(qs, urdf, srdf):
    """One partition: K x dof configurations in, K x (1 + dof) out: each
    row's minimum signed distance, then its gradient. One thread per worker:
    the cluster's processes are the parallelism."""
    robot = robot_of(urdf, srdf)
    minima, gradients = robot.distances_batch(np.ascontiguousarray(qs), gradients=True, threads=1)
    return np.column_stack([minima, gradients])


def dataset(client, urdf, srdf, samples, partitions, seed):
    """The configurations (uniform within the limits, drawn on the workers)
    and their rows of minimum and gradient, computed on `client`'s cluster."""
    robot = robot_of(urdf, srdf)
    lower = np.where(np.isfinite(robot.lower_limits), robot.lower_limits, -np.pi)
    upper = np.where(np.isfinite(robot.upper_limits), robot.upper_limits, np.pi)
    rows = -(-samples // partitions)
    qs = da.random.RandomState(seed).uniform(lower, upper, size=(samples, robot.dof),
                                             chunks=(rows, robot.dof))
    answers = qs.map_blocks(partition, urdf, srdf, dtype=float,
                            chunks=(qs.chunks[0], (1 + robot.dof,)))
    return client.compute([qs, answers], sync=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--urdf", default=str(DATA / "panda.urdf"))
    parser.add_argument("--srdf", default=str(DATA / "panda.srdf"))
    parser.add_argument("--samples", type=int, default=100_000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--partitions", type=int, default=0, help="default: 4 per worker")
    parser.add_argument("--scheduler", default="", help="address of an existing Dask scheduler")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--out", default="", help="write q, minimum and gradient to this .npz")
    parser.add_argument("--check", action="store_true")
    parser.add_argument("--compare", action="store_true")
    args = parser.parse_args()
    if args.samples < 1 or args.workers < 1 or args.partitions < 0:
        parser.error("--samples and --workers must be >= 1, --partitions >= 0")
    partitions = args.partitions or 4 * args.workers

    def run(workers):
        if args.scheduler:
            client = Client(args.scheduler)
            cluster = None
        else:
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None)
            client = Client(cluster)
        try:
            client.run(load, args.urdf, args.srdf)  # each worker loads the robot before the clock starts
            start = time.perf_counter()
            qs, answers = dataset(client, args.urdf, args.srdf, args.samples, partitions, args.seed)
            return qs, answers, time.perf_counter() - start
        finally:
            client.close()
            if cluster is not None:
                cluster.close()

    qs, answers, seconds = run(args.workers)
    minima, gradients = answers[:, 0], answers[:, 1:]
    where = args.scheduler or f"{args.workers} local worker processes"
    print(f"{len(qs)} configurations on {where}, {partitions} partitions: {seconds:.2f} s, "
          f"{len(qs) / seconds:.0f} configurations/s, {np.sum(minima < 0)} in collision")
    if args.out:
        np.savez(args.out, q=qs, min_signed_distance=minima, gradient=gradients)
        print(f"written: {args.out}")
    if args.compare and not args.scheduler:
        _, _, one = run(1)
        print(f"throughput: 1 worker process {len(qs) / one:.0f} configurations/s, "
              f"{args.workers} worker processes {len(qs) / seconds:.0f} configurations/s "
              f"({one / seconds:.2f}x)")
    if args.check:
        robot = proxima.Robot(args.urdf, srdf=args.srdf or None)
        worst = 0.0
        for k in range(len(qs)):
            r = robot.distances(qs[k], gradients=True)
            worst = max(worst, abs(minima[k] - r.min_signed_distance))
            if r.gradient is not None and np.isfinite(minima[k]):
                worst = max(worst, float(np.max(np.abs(gradients[k] - r.gradient))))
        print(f"check against one query per row: largest difference {worst:.3g}")
        if not worst <= 1e-9:
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
