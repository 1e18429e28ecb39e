#!/usr/bin/env python3
"""Per-frame overhead of tracking from Python over the C++ call underneath.

  PYTHONPATH=build/python python3 bench/python_overhead.py <sequence> [--runs 3]

The frames are read into memory first, so image I/O is not timed. For every frame it takes the wall
time of `slam.track()` as Python sees it (numpy in, TrackedFrame out, the GIL released and taken
back) and the `tracking_ms` that System::process measures inside C++ (images in to pose out), and
reports the median over the frames of (wall - tracking_ms) / tracking_ms, per run, then the median
of the runs. Local mapping runs in its own thread as in a live run (--sequential would run it
inside track() after tracking_ms is taken, which would count mapping as overhead).
"""
import argparse
import statistics
import time

import plslam


def one_run(ds, frames):
    slam = plslam.System(ds.calibration, preset=ds.preset)
    walls, inner = [], []
    for t, left, right in frames:
        start = time.perf_counter()
        f = slam.track(left, right, t)
        walls.append((time.perf_counter() - start) * 1e3)
        inner.append(f.tracking_ms)
    slam.shutdown()
    overheads = [(w - c) / c for w, c in zip(walls, inner)]
    return statistics.median(overheads), statistics.median(walls), statistics.median(inner)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("sequence")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--frames", type=int, default=0, help="at most this many frames (0: all)")
    a = ap.parse_args()
    ds = plslam.Dataset(a.sequence)
    n = len(ds) if a.frames <= 0 else min(a.frames, len(ds))
    frames = [ds[i] for i in range(n)]
    results = []
    for r in range(a.runs):
        ov, wall, inner = one_run(ds, frames)
        results.append(ov)
        print(f"run {r + 1}/{a.runs}: median per frame {wall:.3f} ms from Python, {inner:.3f} ms in C++, "
              f"overhead {100 * ov:.3f} %", flush=True)
    print(f"median overhead over {a.runs} runs: {100 * statistics.median(results):.3f} % per frame")


if __name__ == "__main__":
    main()
