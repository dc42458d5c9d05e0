#!/usr/bin/env python3
"""What the Python binding adds to a compute() call: the same session's call from Python (frames
taken from NumPy, the flow handed back as an array) against the C++ call alone
(Session._time_compute, which loops in C++ with the GIL released), in the same run, alternating,
the least of each. Prints both and the overhead as a share of the C++ time.

    PYTHONPATH=build/release/python python3 bench/python_binding_overhead.py \\
        [--model ../shared/fixtures/neuflow-v2-seed0/checkpoint.pth] [--size 768x432] [--backend cpu] [--runs 8]
"""

import argparse
import pathlib
import sys
import time

import numpy as np

import neuflow


def main():
    root = pathlib.Path(__file__).resolve().parents[1]
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default=str(root.parent / "shared/fixtures/neuflow-v2-seed0/checkpoint.pth"))
    parser.add_argument("--size", default="768x432", help="WxH of the frames")
    parser.add_argument("--backend", default="cpu")
    parser.add_argument("--precision", default="fp32")
    parser.add_argument("--runs", type=int, default=8)
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.split("x"))

    rng = np.random.default_rng(0)
    frame0 = rng.integers(0, 256, (height, width, 3), dtype=np.uint8)
    frame1 = np.roll(frame0, (3, 5), axis=(0, 1))  # a shifted copy: flow to find
    session = neuflow.Model(args.model, backend=args.backend, precision=args.precision).session()
    session.compute(frame0, frame1)  # the plan for this size, made once
    cpp, python = [], []
    for _ in range(args.runs):
        cpp.append(session._time_compute(frame0, frame1, 1))
        start = time.perf_counter()
        session.compute(frame0, frame1)
        python.append(time.perf_counter() - start)
    c, p = min(cpp), min(python)
    print(f"{args.size} on {session.device}: C++ compute {c * 1e3:.1f} ms, from Python {p * 1e3:.1f} ms, "
          f"overhead {(p - c) * 1e3:+.2f} ms, {(p - c) / c * 100:+.2f} % (least of {args.runs} each, alternating)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
