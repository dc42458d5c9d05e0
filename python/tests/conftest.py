"""What the pytest suite shares: the fixtures under ../shared (NEUFLOW_SHARED_DIR overrides where;
NEUFLOW_REQUIRE_FIXTURES=1 turns their absence from a skip into a failure, as in the C++ tests),
the CLI built beside the module (NEUFLOW_CLI), and Vulkan (NEUFLOW_REQUIRE_VULKAN=1 likewise)."""

import os
import pathlib

import numpy as np
import pytest

import neuflow

SOURCE_ROOT = pathlib.Path(__file__).resolve().parents[2]


def _flag(name):
    value = os.environ.get(name, "")
    return value not in ("", "0")


def shared_fixtures():
    root = pathlib.Path(os.environ.get("NEUFLOW_SHARED_DIR") or SOURCE_ROOT.parent / "shared")
    return root / "fixtures"


def require(path):
    """The fixture at `path` under the shared fixtures, or a skip (a failure when required)."""
    full = shared_fixtures() / path
    if not full.exists():
        message = (f"fixture '{path}' not found under {shared_fixtures()} (set NEUFLOW_SHARED_DIR to the folder "
                   "that holds fixtures/; NEUFLOW_REQUIRE_FIXTURES=1 makes this a failure)")
        if _flag("NEUFLOW_REQUIRE_FIXTURES"):
            pytest.fail(message)
        pytest.skip(message)
    return full


@pytest.fixture(scope="session")
def checkpoint():
    return require("neuflow-v2-seed0/checkpoint.pth")


@pytest.fixture(scope="session")
def cpu_model(checkpoint):
    return neuflow.Model(checkpoint, backend="cpu")


@pytest.fixture(scope="session")
def vulkan_model(checkpoint):
    try:
        return neuflow.Model(checkpoint, backend="vulkan")
    except neuflow.BackendError as e:
        message = f"no Vulkan device: {e} (NEUFLOW_REQUIRE_VULKAN=1 makes this a failure)"
        if _flag("NEUFLOW_REQUIRE_VULKAN"):
            pytest.fail(message)
        pytest.skip(message)


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("NEUFLOW_CLI")
    if not path or not os.access(path, os.X_OK):
        pytest.skip("NEUFLOW_CLI does not name the neuflow command (ctest sets it)")
    return path


def read_bgr(path):
    cv2 = pytest.importorskip("cv2")
    image = cv2.imread(str(path), cv2.IMREAD_COLOR)
    assert image is not None, path
    return image


@pytest.fixture(scope="session")
def fixture_pair():
    """The checkpoint fixture's frame pair (320×256), BGR as OpenCV reads it."""
    return (read_bgr(require("neuflow-v2-seed0/frame0.png")), read_bgr(require("neuflow-v2-seed0/frame1.png")))


@pytest.fixture(scope="session")
def camera_frames():
    """Three consecutive camera frames at 160×96, BGR."""
    cv2 = pytest.importorskip("cv2")
    folder = require("frames")
    names = sorted(p for p in folder.iterdir() if p.suffix == ".jpg")[:3]
    return [np.ascontiguousarray(cv2.resize(read_bgr(p), (160, 96), interpolation=cv2.INTER_AREA)) for p in names]
