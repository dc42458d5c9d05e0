#!/usr/bin/env python3
"""Accuracy of a NeuFlow-V2 checkpoint on pairs with ground truth, as `neuflow eval --dataset
middlebury` scores them: every ROOT/other-gt-flow/<sequence>/flowNN.flo against the flow from
ROOT/other-data/<sequence>/frameNN.png to frame(NN+1).png, each frame edge-padded (centred) to
multiples of 16 and the flow cropped back, the errors pooled over every valid pixel.

    python3 examples/python/evaluate.py MODEL ROOT [--backend auto] [--json]
"""

import argparse
import json
import pathlib
import re
import sys

import cv2
import numpy as np

import neuflow


def pairs(root):
    for flo in sorted((root / "other-gt-flow").glob("*/flow*.flo")):
        match = re.fullmatch(r"flow(\d{1,6})\.flo", flo.name)
        if not match:
            continue
        digits = match.group(1)
        frames = root / "other-data" / flo.parent.name
        yield (flo.parent.name, frames / f"frame{digits}.png",
               frames / f"frame{int(digits) + 1:0{len(digits)}d}.png", flo)


def padded(image, multiple=16):
    height, width = image.shape[:2]
    pad_h, pad_w = -height % multiple, -width % multiple
    top, left = pad_h // 2, pad_w // 2
    return np.pad(image, ((top, pad_h - top), (left, pad_w - left), (0, 0)), mode="edge"), (top, left)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("model", help="NeuFlow-V2 checkpoint (.pth)")
    parser.add_argument("root", type=pathlib.Path, help="the Middlebury layout: other-data/, other-gt-flow/")
    parser.add_argument("--backend", default="auto", choices=["auto", "cpu", "vulkan"])
    parser.add_argument("--json", action="store_true", help="print the results as JSON")
    args = parser.parse_args()

    session = neuflow.Model(args.model, backend=args.backend).session()
    error_sum, pixels, rows = 0.0, 0, []
    for sequence, image0, image1, flo in pairs(args.root):
        a, b = (cv2.cvtColor(cv2.imread(str(p), cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB) for p in (image0, image1))
        (a, (top, left)), (b, _) = padded(a), padded(b)
        gt = neuflow.read_flow(flo)
        height, width = gt.shape[:2]
        flow = session.compute(a, b)[top:top + height, left:left + width]
        m = neuflow.metrics(flow, gt)
        if m["valid_pixels"] == 0:  # no ground truth to score (its EPE is NaN): counts nothing
            continue
        error_sum += m["epe"] * m["valid_pixels"]
        pixels += m["valid_pixels"]
        rows.append({"sequence": sequence, "epe": m["epe"], "valid_pixels": m["valid_pixels"]})
        if not args.json:
            print(f"{sequence:20s} EPE {m['epe']:8.3f}  ({m['valid_pixels']} pixels)")
    if not rows:
        print(f"evaluate: no other-gt-flow/<sequence>/flowNN.flo under {args.root}", file=sys.stderr)
        return 1
    epe = error_sum / pixels
    if args.json:
        print(json.dumps({"pairs": len(rows), "valid_pixels": pixels, "epe": epe, "per_pair": rows}))
    else:
        print(f"{'all':20s} EPE {epe:8.3f}  ({len(rows)} pairs, {pixels} pixels, pooled)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
