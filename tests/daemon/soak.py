#!/usr/bin/env python3
"""Soak: neuflowd with two streams for 15 minutes (by default), one of them with a files sink on
a full disk beside a healthy files sink and a video sink, the other healthy. Not a CI stage:
run it by hand before a release, as root (the full disk is a 1 MB tmpfs it mounts):

    sudo python3 tests/daemon/soak.py [--minutes 15] [--neuflowd build/release/daemon/neuflowd]
                                      [--plugins build/release/plugins]

Every 30 s it samples the daemon's resident memory, open files and threads, and the healthy
sinks' and streams' counters from its metrics. It passes when
  - the full-disk sink failed and was cut off, and the stream went on with its other sinks;
  - every healthy sink wrote in every interval after the first minute (none stalls);
  - resident memory at the end is within 5 % (+ 8 MB) of the second minute's, and the open
    files and threads within 2 of what they were then;
  - SIGTERM ends the daemon with exit 0 within 15 s.
It prints the samples as a table and exits 0 when it passes, 1 when not, 2 when it cannot run.
"""
import argparse
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def config_text(work, full, checkpoint, metrics_port):
    def source(pattern):
        return f'  type = "test"\n  pattern = "{pattern}"\n  width = 160\n  height = 128\n  framerate = 10'

    def flow():
        return f'  model = "{checkpoint}"\n  iters-s16 = 1\n  iters-s8 = 2\n  threads = 1\n  behaviour = "live"'

    def files(name, folder):  # retention keeps the healthy disk from filling over the soak
        return f'  type = "files"\n  name = "{name}"\n  directory = "{folder}"\n  max-files = 300'

    return f"""[metrics]
listen = "127.0.0.1:{metrics_port}"

[[stream]]
name = "a"
  [stream.source]
{source("ball")}
  [stream.flow]
{flow()}
  [[stream.sink]]
{files("healthy", os.path.join(work, "a-healthy"))}
  [[stream.sink]]
{files("full", full)}
  [[stream.sink]]
  type = "video"
  file = "{os.path.join(work, "a.mp4")}"

[[stream]]
name = "b"
  [stream.source]
{source("snow")}
  [stream.flow]
{flow()}
  [[stream.sink]]
{files("healthy", os.path.join(work, "b-healthy"))}
"""


def scrape(port):
    body = urllib.request.urlopen(f"http://127.0.0.1:{port}/metrics", timeout=10).read().decode()
    values = {}
    for line in body.splitlines():
        m = re.match(r'^(neuflow_\w+)\{([^}]*)\} (\S+)$', line)
        if m:
            labels = dict(re.findall(r'(\w+)="([^"]*)"', m.group(2)))
            values[(m.group(1), labels.get("stream"), labels.get("sink"))] = float(m.group(3))
    return values


def process_state(pid):
    status = open(f"/proc/{pid}/status").read()
    rss_kb = int(re.search(r"VmRSS:\s+(\d+)", status).group(1))
    threads = int(re.search(r"Threads:\s+(\d+)", status).group(1))
    return rss_kb / 1024, len(os.listdir(f"/proc/{pid}/fd")), threads


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--minutes", type=float, default=15)
    parser.add_argument("--neuflowd", default=os.path.join(ROOT, "build", "release", "daemon", "neuflowd"))
    parser.add_argument("--plugins", default=os.path.join(ROOT, "build", "release", "plugins"),
                        help="the folder of libgstneuflow.so, put on GST_PLUGIN_PATH (default: the release build's)")
    shared = os.environ.get("NEUFLOW_SHARED_DIR", os.path.join(ROOT, "..", "shared"))
    parser.add_argument("--checkpoint", default=os.path.join(shared, "fixtures", "neuflow-v2-seed0", "checkpoint.pth"))
    args = parser.parse_args()
    for path, what in [(args.neuflowd, "neuflowd (build it, or give --neuflowd)"),
                       (args.checkpoint, "a checkpoint (give --checkpoint, or set NEUFLOW_SHARED_DIR)")]:
        if not os.path.exists(path):
            print(f"soak: no {what}: {path}", file=sys.stderr)
            return 2
    if os.geteuid() != 0:
        print("soak: run it as root: the full disk is a 1 MB tmpfs it mounts", file=sys.stderr)
        return 2

    work = tempfile.mkdtemp(prefix="neuflow-soak-")
    full = os.path.join(work, "full")
    os.makedirs(full)
    subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1m", "tmpfs", full], check=True)
    metrics_port = free_port()
    config = os.path.join(work, "soak.toml")
    with open(config, "w") as f:
        f.write(config_text(work, full, args.checkpoint, metrics_port))
    log = open(os.path.join(work, "neuflowd.log"), "w+")
    env = dict(os.environ)
    env["GST_PLUGIN_PATH"] = os.pathsep.join(p for p in (args.plugins, env.get("GST_PLUGIN_PATH")) if p)
    daemon = subprocess.Popen([args.neuflowd, "--config", config], stdout=log, stderr=subprocess.STDOUT, env=env)
    failures = []
    samples = []
    try:
        start = time.monotonic()
        end = start + args.minutes * 60
        print("| min | RSS MB | fds | threads | flows a | flows b | a healthy | b healthy | a full failures |")
        print("|---|---|---|---|---|---|---|---|---|")
        while time.monotonic() < end:
            time.sleep(min(30, max(0.0, end - time.monotonic())))
            if daemon.poll() is not None:
                failures.append(f"neuflowd exited {daemon.returncode} during the soak")
                break
            rss, fds, threads = process_state(daemon.pid)
            m = scrape(metrics_port)
            sample = {
                "minute": (time.monotonic() - start) / 60, "rss": rss, "fds": fds, "threads": threads,
                "flows_a": m.get(("neuflow_flows_total", "a", None), 0),
                "flows_b": m.get(("neuflow_flows_total", "b", None), 0),
                "a_healthy": m.get(("neuflow_sink_flows_written_total", "a", "healthy"), 0),
                "b_healthy": m.get(("neuflow_sink_flows_written_total", "b", "healthy"), 0),
                "a_full_failures": m.get(("neuflow_sink_failures_total", "a", "full"), 0),
            }
            samples.append(sample)
            print("| {minute:.1f} | {rss:.1f} | {fds} | {threads} | {flows_a:.0f} | {flows_b:.0f} | {a_healthy:.0f} | "
                  "{b_healthy:.0f} | {a_full_failures:.0f} |".format(**sample), flush=True)
        if not failures:
            after_first = [s for s in samples if s["minute"] > 1]
            for sink in ("a_healthy", "b_healthy"):
                for before, now in zip(after_first, after_first[1:]):
                    if now[sink] <= before[sink]:
                        failures.append(f"{sink} wrote nothing between minute {before['minute']:.1f} and "
                                        f"{now['minute']:.1f}")
            if not samples or samples[-1]["a_full_failures"] < 1:
                failures.append("the full-disk sink never failed")
            settled = next((s for s in samples if s["minute"] >= 2), None)
            if settled and samples[-1] is not settled:
                last = samples[-1]
                if last["rss"] > settled["rss"] * 1.05 + 8:
                    failures.append(f"resident memory grew from {settled['rss']:.1f} MB to {last['rss']:.1f} MB")
                for key in ("fds", "threads"):  # a connection or a retention pass may be open at a sample
                    if abs(last[key] - settled[key]) > 2:
                        failures.append(f"{key}: {settled[key]} at minute 2, {last[key]} at the end")
    finally:
        if daemon.poll() is None:
            daemon.send_signal(signal.SIGTERM)
            try:
                code = daemon.wait(timeout=15)
                if code != 0:
                    failures.append(f"neuflowd exited {code} after SIGTERM")
            except subprocess.TimeoutExpired:
                daemon.kill()
                failures.append("neuflowd did not end within 15 s of SIGTERM")
        log.seek(0)
        text = log.read()
        if not re.search(r"stream a: sink full failed: .*other sinks", text):
            failures.append("the log does not say that the full sink failed and the stream went on")
        subprocess.run(["umount", full], check=False)
        if failures:
            print(f"soak: the daemon's log is kept in {work}/neuflowd.log")
        else:
            shutil.rmtree(work, ignore_errors=True)
    for f in failures:
        print("FAIL:", f)
    print("soak passed" if not failures else f"soak failed ({len(failures)})")
    return 0 if not failures else 1


if __name__ == "__main__":
    sys.exit(main())
