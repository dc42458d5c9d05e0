"""Bad input raises the documented exceptions with the core's message."""

import shutil

import numpy as np
import pytest

import neuflow

from conftest import require


def test_a_frame_that_is_not_uint8_hxwx3_is_a_value_error(cpu_model, camera_frames):
    session = cpu_model.session(iters_s8=1)
    a, b = camera_frames[:2]
    with pytest.raises(ValueError, match=r"frame0: expected a NumPy uint8 array .* got a float32 array of shape \(96, 160, 3\)"):
        session.compute(a.astype(np.float32), b)
    with pytest.raises(ValueError, match=r"frame1: .* got a uint8 array of shape \(96, 160, 4\)"):
        session.compute(a, np.zeros((96, 160, 4), np.uint8))
    with pytest.raises(ValueError, match="frame: expected a NumPy uint8 array .* got list"):
        session.push([[1, 2, 3]])


def test_a_frame_larger_than_the_network_takes_is_refused_before_it_is_copied(cpu_model):
    huge = np.broadcast_to(np.uint8(0), (100_000, 100_000))  # a grey view: copying it would take 30 GB
    with pytest.raises(ValueError, match="larger than the 16384 pixels a side"):
        cpu_model.session().compute(huge, huge)


def test_frames_of_different_sizes_are_a_value_error(cpu_model, camera_frames):
    a, b = camera_frames[:2]
    with pytest.raises(ValueError, match="size"):
        cpu_model.session(iters_s8=1).compute(a, np.ascontiguousarray(b[:64]))


def test_a_frame_too_small_for_the_network_is_a_value_error(cpu_model):
    with pytest.raises(ValueError):
        cpu_model.session().compute(np.zeros((8, 8, 3), np.uint8), np.zeros((8, 8, 3), np.uint8))


@pytest.mark.parametrize("options, says", [
    ({"iters_s8": 100}, "iters_s8: expected"),
    ({"iters_s16": -1}, "iters_s16: expected"),
    ({"model_size": (100, 64)}, "model_size: "),
    ({"channel_order": "grb"}, 'channel_order: expected rgb or bgr, got "grb"'),
    ({"frame_order": "yuv"}, 'frame_order: expected rgb or bgr, got "yuv"'),
])
def test_unusable_session_options_are_value_errors_naming_them(cpu_model, options, says):
    with pytest.raises(ValueError, match=says):
        cpu_model.session(**options)


@pytest.mark.parametrize("options, says", [
    ({"backend": "gpu"}, 'backend: expected auto, cpu or vulkan, got "gpu"'),
    ({"precision": "fp8"}, 'precision: expected fp32 or fp16, got "fp8"'),
    ({"threads": -2}, "threads: expected"),
    ({"device": 99}, "device: expected"),
])
def test_unusable_model_options_are_value_errors_naming_them(checkpoint, options, says):
    with pytest.raises(ValueError, match=says):
        neuflow.Model(checkpoint, **options)


def test_a_jpeg_renamed_pth_is_a_model_error(tmp_path):
    fake = tmp_path / "model.pth"
    shutil.copy(require("flow-gt/kitti/frame1.png"), fake)
    with pytest.raises(neuflow.ModelError, match="model.pth"):
        neuflow.Model(fake, backend="cpu")


def test_a_missing_checkpoint_is_a_file_not_found_error(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such file"):
        neuflow.Model(tmp_path / "missing.pth", backend="cpu")
    with pytest.raises(OSError) as raised:
        neuflow.Model(tmp_path, backend="cpu")  # a folder: there, but not a file
    assert not isinstance(raised.value, FileNotFoundError)


def test_flow_files_that_cannot_be_read_raise_os_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="missing.flo"):
        neuflow.read_flow(tmp_path / "missing.flo")
    (tmp_path / "folder.flo").mkdir()
    with pytest.raises(OSError, match="folder.flo") as raised:
        neuflow.read_flow(tmp_path / "folder.flo")
    assert not isinstance(raised.value, FileNotFoundError)
    (tmp_path / "bad.flo").write_bytes(b"PIEH\x00\x00")
    with pytest.raises(OSError, match="bad.flo"):
        neuflow.read_flow(tmp_path / "bad.flo")
    (tmp_path / "flow.txt").write_text("1 2\n")
    with pytest.raises(ValueError, match="flow.txt"):
        neuflow.read_flow(tmp_path / "flow.txt")
    with pytest.raises(OSError):
        neuflow.write_flow(tmp_path / "no-such-folder" / "f.flo", np.zeros((4, 4, 2), np.float32))


def test_flow_arrays_of_the_wrong_shape_are_value_errors():
    with pytest.raises(ValueError, match=r"flow: expected a float array of shape \(H, W, 2\), got a float32 array of shape \(4, 4, 3\)"):
        neuflow.flow_to_color(np.zeros((4, 4, 3), np.float32))
    with pytest.raises(ValueError, match="flow and gt differ in size"):
        neuflow.epe(np.zeros((4, 4, 2), np.float32), np.zeros((4, 5, 2), np.float32))
    with pytest.raises(ValueError, match="valid: expected a bool or integer array of shape \\(4, 4\\)"):
        neuflow.epe(np.zeros((4, 4, 2), np.float32), np.zeros((4, 4, 2), np.float32), valid=np.ones((3, 3), bool))
