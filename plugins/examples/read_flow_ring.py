#!/usr/bin/python3
"""Reads the newest optical flow from a neuflow flow ring (the shared-memory segment that the
`neuflowshmsink` GStreamer element writes) as an H x W x 2 float32 NumPy array, verified with
its CRC-32. Layout and protocol: docs/shm-ring.md. Needs NumPy; Linux (POSIX shared memory
lives in /dev/shm there).

    python3 read_flow_ring.py /neuflow-front                 # print the newest flow's metadata
    python3 read_flow_ring.py /neuflow-front --save f.npy    # and save it (H x W x 2 float32)

As a module:

    from read_flow_ring import FlowRing
    with FlowRing("/neuflow-front") as ring:
        info, uv = ring.latest()      # uv[y, x] = (u, v) in pixels of the grid
"""

import argparse
import mmap
import os
import struct
import sys
import time
import zlib

try:
    import numpy as np
except ImportError:
    sys.exit("read_flow_ring.py needs NumPy: apt install python3-numpy (or pip install numpy)")

MAGIC = b"NFLOWRNG"
LAYOUT_VERSION = 1
VALUE_LAYOUT_F32_UV = 1
STATE_INITIALIZING, STATE_LIVE, STATE_CLOSED = 0, 1, 2
NO_TIMESTAMP = 2**64 - 1

# Ring header at offset 0 (128 bytes), little-endian: see docs/shm-ring.md.
HEADER = struct.Struct("<8sIIIIQIIIIQQQQIIQ")
HEADER_FIELDS = ("magic", "version", "header_size", "slot_count", "slot_header_size", "slot_stride",
                 "grid_width", "grid_height", "value_layout", "state", "generation", "flows_published",
                 "segment_size", "data_bytes", "writer_pid", "reserved0", "created_realtime_ns")
STATE_OFFSET = 44
PUBLISHED_OFFSET = 56

# Slot header at the start of each slot (128 bytes); the flow data follows at slot_header_size.
SLOT = struct.Struct("<QQQQQQQIIIIIIIIIIQ")
SLOT_FIELDS = ("sequence", "from_frame", "to_frame", "from_pts_ns", "to_pts_ns", "inference_ns",
               "written_realtime_ns", "grid_width", "grid_height", "frame_width", "frame_height",
               "model_width", "model_height", "iters_s16", "iters_s8", "crc32", "reserved0", "data_bytes")

U64 = struct.Struct("<Q")
U32 = struct.Struct("<I")


class RingError(Exception):
    """The ring cannot be read: missing, not ready (retry), or not a flow ring."""

    def __init__(self, message, retryable=False):
        super().__init__(message)
        self.retryable = retryable


class FlowRing:
    """A read-only mapping of one flow ring segment."""

    def __init__(self, name):
        if not name.startswith("/") or "/" in name[1:] or len(name) < 2:
            raise RingError(f'flow ring "{name}": expected a name like "/neuflow-front"')
        self.name = name
        try:
            fd = os.open("/dev/shm" + name, os.O_RDONLY)
        except FileNotFoundError:
            raise RingError(f'flow ring "{name}": no such shared-memory segment (is the writer running?)',
                            retryable=True) from None
        except PermissionError:
            raise RingError(f'flow ring "{name}": permission denied (the writer\'s shm-mode is 0640 by default: run '
                            "the reader as the writer's user or in its group, which is 'neuflow' under neuflowd's "
                            "systemd units, or give the writer shm-mode=0644)") from None
        try:
            size = os.fstat(fd).st_size
            if size < HEADER.size:
                raise RingError(f'flow ring "{name}": segment is {size} bytes, less than a header '
                                "(the writer is still creating it, or it is not a flow ring)", retryable=True)
            self._mm = mmap.mmap(fd, size, mmap.MAP_SHARED, mmap.PROT_READ)
        finally:
            os.close(fd)
        try:
            self._validate(size)
        except RingError:
            self._mm.close()
            raise

    def _validate(self, size):
        # `state` first: once it is live, every other header field is complete.
        state = U32.unpack_from(self._mm, STATE_OFFSET)[0]
        h = dict(zip(HEADER_FIELDS, HEADER.unpack_from(self._mm, 0)))
        if state != STATE_LIVE:
            if h["magic"] not in (MAGIC, b"\0" * 8):
                raise RingError(f'flow ring "{self.name}": not a neuflow flow ring (bad magic)')
            what = "closed by its writer" if state == STATE_CLOSED else "waiting for the writer's first flow"
            raise RingError(f'flow ring "{self.name}": {what}', retryable=True)
        if h["magic"] != MAGIC:
            raise RingError(f'flow ring "{self.name}": not a neuflow flow ring (bad magic)')
        if h["version"] != LAYOUT_VERSION:
            raise RingError(f'flow ring "{self.name}": layout version {h["version"]}, this reader supports '
                            f"version {LAYOUT_VERSION}")
        cells = h["grid_width"] * h["grid_height"]
        if (h["value_layout"] != VALUE_LAYOUT_F32_UV or cells == 0 or h["data_bytes"] != cells * 8
                or h["slot_count"] < 1 or h["slot_stride"] < h["slot_header_size"] + h["data_bytes"]
                or h["header_size"] + h["slot_count"] * h["slot_stride"] > size or h["segment_size"] != size):
            raise RingError(f'flow ring "{self.name}": inconsistent header {h}')
        self.header = h
        self.width, self.height = h["grid_width"], h["grid_height"]
        self.slot_count = h["slot_count"]
        self.generation = h["generation"]

    def close(self):
        self._mm.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def published(self):
        """Sequence number of the newest complete flow (0: none yet)."""
        return U64.unpack_from(self._mm, PUBLISHED_OFFSET)[0]

    def replaced(self):
        """True once the writer stopped or replaced this segment: open the name again."""
        return U32.unpack_from(self._mm, STATE_OFFSET)[0] != STATE_LIVE

    def read(self, sequence, max_attempts=16):
        """Flow `sequence` as (info dict, H x W x 2 float32 array), or (status, None) with status
        'not published', 'overwritten' or 'torn'. Seqlock protocol: read the slot's sequence
        word, copy, read the word again; the copy is good when both reads are 2 * sequence.
        The CRC-32 check then guards against what Python cannot order (it has no memory
        fences): a copy that passes both checks is whole."""
        if sequence < 1:
            return "not published", None
        h = self.header
        slot = h["header_size"] + ((sequence - 1) % h["slot_count"]) * h["slot_stride"]
        data = slot + h["slot_header_size"]
        wanted = 2 * sequence
        for _ in range(max_attempts):
            before = U64.unpack_from(self._mm, slot)[0]
            if before > wanted:
                return "overwritten", None
            if before < wanted:
                return "not published", None
            info = dict(zip(SLOT_FIELDS, SLOT.unpack_from(self._mm, slot)))
            raw = self._mm[data:data + h["data_bytes"]]  # a copy
            if U64.unpack_from(self._mm, slot)[0] != before:
                continue
            if zlib.crc32(raw) != info["crc32"]:
                continue  # overlapped a write after all: try again
            info["sequence"] = sequence
            uv = np.frombuffer(raw, dtype="<f4").reshape(self.height, self.width, 2)
            return info, uv
        return "torn", None

    def latest(self, max_attempts=16):
        """The newest flow as (info, array); raises RingError when there is none or the
        writer kept overwriting it."""
        status = "not published"
        for _ in range(max_attempts):
            newest = self.published()
            if newest == 0:
                break
            info, uv = self.read(newest)
            if uv is not None:
                return info, uv
            status = info
        raise RingError(f'flow ring "{self.name}": no flow read ({status})', retryable=True)


def open_ring(name, wait_s):
    """Opens the ring, waiting up to wait_s seconds for it to exist and hold a flow."""
    deadline = time.monotonic() + wait_s
    while True:
        try:
            ring = FlowRing(name)
            if ring.published() > 0:
                return ring
            ring.close()
            error = RingError(f'flow ring "{name}": no flow published yet', retryable=True)
        except RingError as e:
            if not e.retryable:
                raise
            error = e
        if time.monotonic() >= deadline:
            raise error
        time.sleep(0.02)


def seconds(ns):
    return "?" if ns == NO_TIMESTAMP else f"{ns / 1e9:.6f}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("name", help="shared-memory name, as neuflowshmsink's shm-name (e.g. /neuflow-front)")
    parser.add_argument("--save", metavar="FILE.npy", help="save the flow as an H x W x 2 float32 .npy file")
    parser.add_argument("--wait", type=float, default=5.0, metavar="S",
                        help="seconds to wait for the ring and its first flow (default 5)")
    args = parser.parse_args()
    try:
        with open_ring(args.name, args.wait) as ring:
            info, uv = ring.latest()
    except RingError as e:
        print(f"read_flow_ring: {e}", file=sys.stderr)
        return 2
    magnitude = np.hypot(uv[..., 0], uv[..., 1])
    print(f"seq={info['sequence']} generation={ring.generation} frames={info['from_frame']}->{info['to_frame']} "
          f"pts={seconds(info['from_pts_ns'])}->{seconds(info['to_pts_ns'])} "
          f"grid={info['grid_width']}x{info['grid_height']} frame={info['frame_width']}x{info['frame_height']} "
          f"mean|flow|={magnitude.mean():.4f} crc32={info['crc32']:08x}")
    if args.save:
        np.save(args.save, uv)
    return 0


if __name__ == "__main__":
    sys.exit(main())
