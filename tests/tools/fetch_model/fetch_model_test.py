#!/usr/bin/env python3
"""`neuflow fetch-model` against an HTTP server on loopback.

The server runs in this process and serves a temporary directory holding the fixture
checkpoint under the published name, plus a few misbehaving variants of it (cut-off body,
no Content-Length, stalled body, redirect). Each case checks the exit code, the message, the
output directory (the file exactly, or nothing at all: no partial or temporary file) and, where
it matters, which requests reached the server.

Usage: fetch_model_test.py NEUFLOW_BINARY CASE   (CASE: one of the functions named case_*)
"""
import filecmp
import hashlib
import http.server
import os
import resource
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

SKIP = 77
NEUFLOW = sys.argv[1] if len(sys.argv) > 1 else ""
FILE = "neuflow_mixed.pth"
PINNED_MIXED = "2152e111910de87297af42923d6ed679958b713d"


class Failure(Exception):
    pass


class Skip(Exception):
    pass


def check(condition, message):
    if not condition:
        raise Failure(message)


def git_blob_sha1(data: bytes) -> str:
    return hashlib.sha1(b"blob %d\0" % len(data) + data).hexdigest()


def fixture_checkpoint() -> Path:
    shared = os.environ.get("NEUFLOW_SHARED_DIR") or str(Path(__file__).resolve().parents[4] / "shared")
    path = Path(shared) / "fixtures" / "neuflow-v2-seed0" / "checkpoint.pth"
    if not path.is_file():
        message = f"fixture not found: {path} (set NEUFLOW_SHARED_DIR)"
        if os.environ.get("NEUFLOW_REQUIRE_FIXTURES", "0") not in ("", "0"):
            raise Failure(message)
        raise Skip(message)
    return path


class Handler(http.server.SimpleHTTPRequestHandler):
    """/files/<name>: the file as is. /truncated/, /nolength/, /stall/, /redirect/<name>:
    the same file cut off half-way, without a Content-Length, stalling after 64 KiB, or
    through a 302 to /files/."""

    def __init__(self, request, client_address, server):
        super().__init__(request, client_address, server, directory=server.root)

    def log_message(self, *args):
        pass

    def do_GET(self):
        self.server.requests.append(self.path)
        _, kind, name = self.path.split("/", 2) if self.path.count("/") >= 2 else ("", "", "")
        body_path = Path(self.server.root) / name
        if kind == "files":
            self.path = "/" + name
            return super().do_GET()
        if kind == "redirect":
            self.send_response(302)
            self.send_header("Location", "/files/" + name)
            self.send_header("Content-Length", "0")
            return self.end_headers()
        if not body_path.is_file():
            return self.send_error(404)
        data = body_path.read_bytes()
        self.send_response(200)
        self.send_header("Content-Type", "application/octet-stream")
        if kind != "nolength":
            self.send_header("Content-Length", str(len(data)))
        self.end_headers()
        if kind == "nolength":
            self.wfile.write(data)
        elif kind == "truncated":
            self.wfile.write(data[: len(data) // 2])
        elif kind == "stall":
            self.wfile.write(data[:65536])
            self.wfile.flush()
            self.server.stalled.set()
            self.server.stop.wait(30)
        # HTTP/1.0: returning closes the connection, ending whatever body was sent.


class QuietServer(http.server.ThreadingHTTPServer):
    def handle_error(self, request, client_address):
        # The client hanging up mid-body is what several cases provoke on purpose.
        if not isinstance(sys.exc_info()[1], (ConnectionError, BrokenPipeError)):
            super().handle_error(request, client_address)


class Server:
    def __init__(self, root: Path):
        self.httpd = QuietServer(("127.0.0.1", 0), Handler)
        self.httpd.daemon_threads = True
        self.httpd.root = str(root)
        self.httpd.requests = []
        self.httpd.stalled = threading.Event()
        self.httpd.stop = threading.Event()
        self.thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)
        self.thread.start()

    def url(self, kind="files"):
        return f"http://127.0.0.1:{self.httpd.server_address[1]}/{kind}"

    @property
    def requests(self):
        return list(self.httpd.requests)

    def close(self):
        self.httpd.stop.set()
        self.httpd.shutdown()
        self.httpd.server_close()


def closed_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Case:
    """A scratch directory with served/ (what the server offers) and out/ (--output-dir)."""

    def __init__(self, serve_fixture=True):
        self.tmp = Path(tempfile.mkdtemp(prefix="neuflow-fetch-"))
        self.served = self.tmp / "served"
        self.out = self.tmp / "out"
        self.served.mkdir()
        self.fixture = None
        if serve_fixture:
            self.fixture = fixture_checkpoint()
            shutil.copyfile(self.fixture, self.served / FILE)
            self.fixture_sha1 = git_blob_sha1(self.fixture.read_bytes())
        self.server = Server(self.served)

    def close(self):
        self.server.close()
        shutil.rmtree(self.tmp, ignore_errors=True)

    def run(self, *args, env_extra=None, **popen):
        env = {k: v for k, v in os.environ.items() if "proxy" not in k.lower() and not k.startswith("NEUFLOW_MODEL")}
        env.update(env_extra or {})
        cmd = [NEUFLOW, "fetch-model", *args]
        result = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=60, **popen)
        print(f"$ {' '.join(cmd)}\n-> exit {result.returncode}\n{result.stdout}{result.stderr}")
        return result

    def out_entries(self):
        return sorted(p.name for p in self.out.iterdir()) if self.out.exists() else []

    def check_nothing_left(self):
        check(self.out_entries() == [], f"the output directory must stay empty, holds {self.out_entries()}")
        # A folder fetch-model created for the download goes too (out/ did not exist before).
        check(not self.out.exists(), f"{self.out} was created for a failed download and left behind")

    def check_fetched(self, result):
        check(result.returncode == 0, f"expected success, got exit {result.returncode}")
        check(self.out_entries() == [FILE], f"expected only {FILE}, found {self.out_entries()}")
        check(filecmp.cmp(self.out / FILE, self.fixture, shallow=False), "the fetched file differs from the served one")
        check(result.stdout.strip() == str(self.out / FILE), f"stdout must be the file's path, got {result.stdout!r}")


def case_verified_download(c: Case):
    result = c.run("mixed", "-o", str(c.out), "--base-url", c.server.url(), "--sha1", c.fixture_sha1.upper())
    c.check_fetched(result)
    check(f"{c.fixture_sha1} verified" in result.stderr, "the message must say the file was verified, and its hash")
    check(c.server.requests == [f"/files/{FILE}"], f"unexpected requests {c.server.requests}")


def case_redirect_and_env_base_url(c: Case):
    result = c.run("mixed", "-o", str(c.out), "--sha1", c.fixture_sha1,
                   env_extra={"NEUFLOW_MODEL_BASE_URL": c.server.url("redirect") + "/"})
    c.check_fetched(result)
    check(c.server.requests == [f"/redirect/{FILE}", f"/files/{FILE}"], f"unexpected requests {c.server.requests}")


def case_pinned_hash_mismatch(c: Case):
    result = c.run("mixed", "-o", str(c.out), "--base-url", c.server.url())
    check(result.returncode == 65, f"a hash mismatch must exit 65, got {result.returncode}")
    for needed in (c.server.url() + "/" + FILE, c.fixture_sha1, PINNED_MIXED, "nothing was saved"):
        check(needed in result.stderr, f"the message must mention {needed!r}")
    c.check_nothing_left()


def case_not_found(c: Case):
    result = c.run("things", "-o", str(c.out), "--base-url", c.server.url())
    check(result.returncode == 69, f"HTTP 404 must exit 69, got {result.returncode}")
    check("404" in result.stderr and "neuflow_things.pth" in result.stderr, "the message must name the URL and the 404")
    c.check_nothing_left()


def case_offline(c: Case):
    port = closed_port()
    result = c.run("mixed", "-o", str(c.out), "--base-url", f"http://127.0.0.1:{port}/x")
    check(result.returncode == 69, f"a refused connection must exit 69, got {result.returncode}")
    check(f"could not connect to 127.0.0.1:{port}" in result.stderr, "the message must say it could not connect")
    check("offline?" in result.stderr, "the message must suggest the machine may be offline")
    check("copied by hand" in result.stderr and str(c.out / FILE) in result.stderr,
          "the message must say the file can be copied into place by hand")
    c.check_nothing_left()


def case_unresolvable_host(c: Case):
    # .invalid never resolves (RFC 6761), with or without a network.
    result = c.run("mixed", "-o", str(c.out), "--base-url", "http://neuflow-models.invalid/x")
    check(result.returncode == 69, f"an unresolvable host must exit 69, got {result.returncode}")
    check("could not resolve neuflow-models.invalid" in result.stderr, "the message must name the host")
    c.check_nothing_left()


def case_already_present(c: Case):
    c.out.mkdir()
    shutil.copyfile(c.fixture, c.out / FILE)
    result = c.run("mixed", "-o", str(c.out), "--base-url", c.server.url(), "--sha1", c.fixture_sha1)
    c.check_fetched(result)
    check("already there" in result.stderr, "the message must say the file is already there")
    check(c.server.requests == [], f"no request may reach the server, got {c.server.requests}")


def case_existing_other_file(c: Case):
    c.out.mkdir()
    (c.out / FILE).write_bytes(b"someone else's file")
    result = c.run("mixed", "-o", str(c.out), "--base-url", c.server.url(), "--sha1", c.fixture_sha1)
    check(result.returncode == 73, f"an existing different file must exit 73, got {result.returncode}")
    check("--force" in result.stderr, "the message must point at --force")
    check((c.out / FILE).read_bytes() == b"someone else's file", "the existing file must be untouched")
    check(c.server.requests == [], f"no request may reach the server, got {c.server.requests}")
    # --force replaces it, but a failed --force leaves it as it was.
    result = c.run("mixed", "-o", str(c.out), "--base-url", c.server.url("truncated"), "--sha1", c.fixture_sha1,
                   "--force")
    check(result.returncode == 69, f"a cut-off download must exit 69, got {result.returncode}")
    check(c.out_entries() == [FILE] and (c.out / FILE).read_bytes() == b"someone else's file",
          "a failed --force must leave the existing file alone and no temporary")
    c.check_fetched(c.run("mixed", "-o", str(c.out), "--base-url", c.server.url(), "--sha1", c.fixture_sha1, "--force"))


def case_truncated_body(c: Case):
    result = c.run("mixed", "-o", str(c.out), "--base-url", c.server.url("truncated"), "--sha1", c.fixture_sha1)
    check(result.returncode == 69, f"a cut-off body must exit 69, got {result.returncode}")
    size = c.fixture.stat().st_size
    check(f"of {size}" in result.stderr and "broke off" in result.stderr,
          "the message must say the connection broke off and how much was expected")
    c.check_nothing_left()


def case_no_content_length(c: Case):
    c.check_fetched(c.run("mixed", "-o", str(c.out), "--base-url", c.server.url("nolength"), "--sha1",
                          c.fixture_sha1))


def case_not_a_checkpoint(c: Case):
    junk = b"<html>a captive portal, not a checkpoint</html>" * 100
    (c.served / FILE).write_bytes(junk)
    result = c.run("mixed", "-o", str(c.out), "--base-url", c.server.url(), "--sha1", git_blob_sha1(junk))
    check(result.returncode == 65, f"a file that is no checkpoint must exit 65, got {result.returncode}")
    check("not a NeuFlow-V2 checkpoint" in result.stderr, "the message must say it is not a checkpoint")
    c.check_nothing_left()


def case_write_error(c: Case):
    # A 1 MiB file-size limit makes writes fail with EFBIG like a full disk would, once the
    # default action of SIGXFSZ (killing the process) is ignored.
    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (1 << 20, 1 << 20))

    result = c.run("mixed", "-o", str(c.out), "--base-url", c.server.url(), "--sha1", c.fixture_sha1,
                   preexec_fn=limit, restore_signals=False)
    check(result.returncode == 73, f"a write error must exit 73, got {result.returncode}")
    check("File too large" in result.stderr and ".part-" in result.stderr, "the message must name the file and errno")
    c.check_nothing_left()


def case_stalled_transfer(c: Case):
    started = time.monotonic()
    result = c.run("mixed", "-o", str(c.out), "--base-url", c.server.url("stall"), "--sha1", c.fixture_sha1,
                   "--stall-timeout", "2")
    check(result.returncode == 69, f"a stalled transfer must exit 69, got {result.returncode}")
    check("timed out" in result.stderr, "the message must say it timed out")
    check(time.monotonic() - started < 20, "the stall timeout must end the transfer early")
    c.check_nothing_left()


def case_interrupted(c: Case):
    env = {k: v for k, v in os.environ.items() if "proxy" not in k.lower()}
    proc = subprocess.Popen([NEUFLOW, "fetch-model", "mixed", "-o", str(c.out), "--base-url", c.server.url("stall"),
                             "--sha1", c.fixture_sha1], env=env, stderr=subprocess.PIPE, text=True)
    check(c.server.httpd.stalled.wait(20), "the download never started")
    time.sleep(0.3)
    temporaries = c.out_entries()
    check(len(temporaries) == 1 and ".part-" in temporaries[0], f"expected one temporary, found {temporaries}")
    proc.send_signal(signal.SIGINT)
    _, stderr = proc.communicate(timeout=20)
    print(stderr)
    check(proc.returncode == 130, f"Ctrl-C must exit 130, got {proc.returncode}")
    check("interrupted" in stderr, "the message must say the download was interrupted")
    c.check_nothing_left()


def case_bad_usage(c: Case):
    check(c.run("tiny", "-o", str(c.out)).returncode != 0, "an unknown model name must fail")
    result = c.run("mixed", "-o", str(c.out), "--sha1", "1234")
    check(result.returncode != 0 and "40 hex digits" in result.stderr, "a malformed --sha1 must fail with a hint")
    check(c.server.requests == [], "bad usage must not download")
    c.out.write_text("a file where the directory should be")
    result = c.run("mixed", "-o", str(c.out), "--base-url", c.server.url())
    check(result.returncode == 73 and str(c.out) in result.stderr, "an output directory that is a file must exit 73")
    check(c.server.requests == [], "no download when the output cannot be created")


FIXTURE_FREE = {"offline", "unresolvable_host", "not_found", "bad_usage"}


def main():
    if len(sys.argv) != 3 or not callable(globals().get("case_" + sys.argv[2])):
        cases = [n[5:] for n in globals() if n.startswith("case_")]
        print(f"usage: {sys.argv[0]} NEUFLOW_BINARY CASE, CASE one of {', '.join(cases)}")
        return 2
    name = sys.argv[2]
    try:
        c = Case(serve_fixture=name not in FIXTURE_FREE)
    except Skip as e:
        print(e)
        return SKIP
    except Failure as e:
        print(f"FAIL: {e}")
        return 1
    try:
        globals()["case_" + name](c)
    except Failure as e:
        print(f"FAIL: {e}")
        return 1
    finally:
        c.close()
    print(f"{name}: passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
