"""The examples under examples/python run as the README says, and evaluate.py's figures are
`neuflow eval`'s."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from conftest import SOURCE_ROOT, require

EXAMPLES = SOURCE_ROOT / "examples" / "python"


def run(*args):
    result = subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True, env=os.environ)
    assert result.returncode == 0, result.stdout + result.stderr
    return result.stdout


def test_evaluate_gives_neuflow_evals_figures(checkpoint, cli, tmp_path):
    pytest.importorskip("cv2")
    sequence = require("flow-gt/middlebury/RubberWhale")
    for folder, names in (("other-data", ["frame10.png", "frame11.png"]), ("other-gt-flow", ["flow10.flo"])):
        (tmp_path / folder / "RubberWhale").mkdir(parents=True)
        for name in names:
            os.symlink(sequence / name, tmp_path / folder / "RubberWhale" / name)
    ours = json.loads(run(EXAMPLES / "evaluate.py", checkpoint, tmp_path, "--backend", "cpu", "--json"))
    theirs = subprocess.run([cli, "eval", "-d", "middlebury", "-m", str(checkpoint), "--backend", "cpu", "--json", "-",
                             str(tmp_path)], capture_output=True, text=True, check=True).stdout
    results = json.loads(theirs[theirs.index("{"):])["results"][0]
    assert ours["pairs"] == results["pairs"] == 1
    assert ours["valid_pixels"] == results["valid_pixels"]
    assert ours["epe"] == pytest.approx(results["epe"], rel=1e-6)


def test_flow_video_writes_the_flows_pictures_to_an_mp4(checkpoint, camera_frames, tmp_path):
    cv2 = pytest.importorskip("cv2")
    video = tmp_path / "in.avi"
    writer = cv2.VideoWriter(str(video), cv2.VideoWriter_fourcc(*"MJPG"), 10, (160, 96))
    for frame in camera_frames:
        writer.write(frame)
    writer.release()
    output = tmp_path / "flow.mp4"
    printed = run(EXAMPLES / "flow_video.py", checkpoint, video, "--output", output, "--backend", "cpu")
    assert "3 frames, 2 flows" in printed and "per second" in printed
    capture = cv2.VideoCapture(str(output))
    pictures = []
    while True:
        ok, picture = capture.read()
        if not ok:
            break
        pictures.append(picture)
    assert len(pictures) == 2
    assert pictures[0].shape == (96, 160, 3)
    assert np.std(pictures[0]) > 1  # a flow's colours, not a blank frame
