#!/usr/bin/env python3
"""Optical flow of a video or a camera, live: OpenCV reads the frames, a neuflow session computes
the flow from each frame to the next (push), and its colour-wheel picture goes to a window or an
MP4 file. Prints the frame rate the flow kept.

    python3 examples/python/flow_video.py MODEL [SOURCE] [--output flow.mp4] [--backend auto]
        [--size 640x360] [--max-frames N]

SOURCE is a video file or a camera index (default 0). Without --output it opens a window
(q or Esc stops).
"""

import argparse
import sys
import time

import cv2
import numpy as np

import neuflow


def parse_size(text):
    width, height = (int(v) for v in text.lower().split("x"))
    return width, height


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("model", help="NeuFlow-V2 checkpoint (.pth)")
    parser.add_argument("source", nargs="?", default="0", help="video file or camera index (default 0)")
    parser.add_argument("--output", help="write the pictures to this MP4 instead of a window")
    parser.add_argument("--backend", default="auto", choices=["auto", "cpu", "vulkan"])
    parser.add_argument("--precision", default="fp32", choices=["fp32", "fp16"])
    parser.add_argument("--size", type=parse_size, help="WxH to resize the frames to first")
    parser.add_argument("--max-flow", type=float, default=None, help="px of full saturation (default: each frame's largest)")
    parser.add_argument("--max-frames", type=int, default=0, help="stop after this many frames (0: all)")
    args = parser.parse_args()

    capture = cv2.VideoCapture(int(args.source) if args.source.isdigit() else args.source)
    if not capture.isOpened():
        print(f"flow_video: cannot open {args.source}", file=sys.stderr)
        return 1
    model = neuflow.Model(args.model, backend=args.backend, precision=args.precision)
    session = model.session(frame_order="bgr")  # OpenCV's frames; the network is fed RGB
    print(f"flow_video: {model.info['device']}")
    fps = capture.get(cv2.CAP_PROP_FPS) or 25.0
    writer = None
    frames = flows = 0
    started = time.perf_counter()
    while args.max_frames == 0 or frames < args.max_frames:
        ok, frame = capture.read()
        if not ok:
            break
        if args.size:
            frame = cv2.resize(frame, args.size, interpolation=cv2.INTER_AREA)
        frames += 1
        flow = session.push(frame)
        if flow is None:
            continue
        flows += 1
        picture = cv2.cvtColor(neuflow.flow_to_color(flow, max_flow=args.max_flow), cv2.COLOR_RGB2BGR)
        if args.output:
            if writer is None:
                height, width = picture.shape[:2]
                writer = cv2.VideoWriter(args.output, cv2.VideoWriter_fourcc(*"mp4v"), fps, (width, height))
                if not writer.isOpened():
                    print(f"flow_video: cannot write {args.output}", file=sys.stderr)
                    return 1
            writer.write(picture)
        else:
            cv2.imshow("neuflow", np.hstack([frame, picture]))
            if cv2.waitKey(1) & 0xFF in (ord("q"), 27):
                break
        if flows % 25 == 0:
            print(f"flow_video: {flows} flows, {flows / (time.perf_counter() - started):.2f} per second")
    elapsed = time.perf_counter() - started
    if writer is not None:
        writer.release()
    print(f"flow_video: {frames} frames, {flows} flows in {elapsed:.1f} s: {flows / elapsed if elapsed else 0:.2f} flows "
          f"per second{f', written to {args.output}' if args.output else ''}")
    return 0 if flows > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
