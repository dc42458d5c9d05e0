"""Model and Session: the flow the C++ core computes, reached from NumPy."""

import pickle
import subprocess
import threading
import time

import numpy as np
import pytest

import neuflow


def test_info_names_the_network_and_where_it_runs(cpu_model, checkpoint):
    info = cpu_model.info
    assert info["architecture"] == "NeuFlow-V2"
    assert info["parameters"] == 9_029_536
    assert info["checkpoint"] == str(checkpoint)
    assert info["backend"] == "cpu" and info["device"] == "cpu"
    assert info["warning"] is None
    assert "device='cpu'" in repr(cpu_model)


def test_compute_gives_the_clis_flow_bit_for_bit_on_the_cpu(cpu_model, cli, checkpoint, fixture_pair, tmp_path):
    frames = [str(checkpoint.parent / "frame0.png"), str(checkpoint.parent / "frame1.png")]
    out = tmp_path / "cli.flo"
    subprocess.run([cli, "flow", "--model", str(checkpoint), "--backend", "cpu", *frames, str(out)], check=True,
                   capture_output=True)
    session = cpu_model.session(frame_order="bgr")  # as OpenCV reads them; fed RGB, as the CLI feeds them
    flow = session.compute(*fixture_pair)
    assert flow.shape == (256, 320, 2) and flow.dtype == np.float32 and flow.flags["C_CONTIGUOUS"]
    np.testing.assert_array_equal(flow, neuflow.read_flow(out))


def test_vulkan_gives_the_cpus_flow_within_the_fixture_tolerance(cpu_model, vulkan_model, fixture_pair):
    cpu = cpu_model.session(frame_order="bgr").compute(*fixture_pair)
    session = vulkan_model.session(frame_order="bgr")
    assert session.device.startswith("vulkan device")
    gpu = session.compute(*fixture_pair)
    error = np.linalg.norm(gpu - cpu, axis=2)
    assert error.max() <= 1e-2 and error.mean() <= 1e-3, (error.max(), error.mean())


def test_frames_of_any_size_give_flow_of_that_size(cpu_model, camera_frames):
    a, b = (np.ascontiguousarray(f[:60, :100]) for f in camera_frames[:2])
    flow = cpu_model.session(iters_s8=2).compute(a, b)
    assert flow.shape == (60, 100, 2) and flow.dtype == np.float32
    assert np.isfinite(flow).all()


def test_the_frames_channel_order_is_what_the_session_says(cpu_model, camera_frames):
    bgr = camera_frames[:2]
    rgb = [np.ascontiguousarray(f[..., ::-1]) for f in bgr]
    from_bgr = cpu_model.session(iters_s8=2, frame_order="bgr").compute(*bgr)
    from_rgb = cpu_model.session(iters_s8=2).compute(*rgb)
    np.testing.assert_array_equal(from_bgr, from_rgb)
    # Fed BGR (channel_order, as the reference demo scripts feed it): another flow. Without a
    # frame_order the frames are taken to be in that order already.
    fed_bgr = cpu_model.session(iters_s8=2, channel_order="bgr", frame_order="rgb").compute(*rgb)
    assert not np.array_equal(fed_bgr, from_rgb)
    np.testing.assert_array_equal(cpu_model.session(iters_s8=2, channel_order="bgr").compute(*bgr), fed_bgr)
    assert cpu_model.session(channel_order="bgr").options["frame_order"] == "bgr"


def test_interleaved_frames_are_read_in_place_and_others_copied(cpu_model, camera_frames):
    frame = camera_frames[0]
    assert neuflow._takes_without_copy(frame)
    assert neuflow._takes_without_copy(frame[10:50, 20:120])  # a crop: strided rows
    assert not neuflow._takes_without_copy(frame[..., ::-1])  # channels reversed by a view
    assert not neuflow._takes_without_copy(np.asfortranarray(frame))
    assert not neuflow._takes_without_copy(frame[..., 0])  # grey
    # Copied or not, the same pixels give the same flow.
    a, b = camera_frames[:2]
    session = cpu_model.session(iters_s8=1)
    expected = session.compute(a, b)
    np.testing.assert_array_equal(session.compute(np.asfortranarray(a), np.asfortranarray(b)), expected)
    crop = cpu_model.session(iters_s8=1).compute(np.ascontiguousarray(a[8:72, 16:144]), np.ascontiguousarray(b[8:72, 16:144]))
    np.testing.assert_array_equal(session.compute(a[8:72, 16:144], b[8:72, 16:144]), crop)


def test_frames_from_another_process_and_flipped_views_are_taken(cpu_model, camera_frames):
    a, b = camera_frames[:2]
    session = cpu_model.session(iters_s8=1)
    expected = session.compute(a, b)
    # Through pickle, as multiprocessing hands them over: equal arrays with dtype objects of their own.
    np.testing.assert_array_equal(session.compute(pickle.loads(pickle.dumps(a)), pickle.loads(pickle.dumps(b))),
                                  expected)
    flipped = session.compute(a[::-1], b[::-1])  # negative row strides: copied
    np.testing.assert_array_equal(flipped, session.compute(np.ascontiguousarray(a[::-1]), np.ascontiguousarray(b[::-1])))


def test_a_grey_frame_is_three_equal_channels(cpu_model, camera_frames):
    grey = [f[..., 1].copy() for f in camera_frames[:2]]
    session = cpu_model.session(iters_s8=1)
    np.testing.assert_array_equal(session.compute(*grey),
                                  session.compute(*[np.repeat(g[..., None], 3, axis=2) for g in grey]))


def test_push_over_a_sequence_equals_compute_on_each_pair(cpu_model, camera_frames):
    stream = cpu_model.session(iters_s8=2)
    pairs = cpu_model.session(iters_s8=2)
    assert stream.push(camera_frames[0]) is None
    for earlier, later in zip(camera_frames, camera_frames[1:]):
        np.testing.assert_array_equal(stream.push(later), pairs.compute(earlier, later))
    stream.reset()
    assert stream.push(camera_frames[0]) is None


def test_model_size_runs_the_network_at_that_size(cpu_model, camera_frames):
    session = cpu_model.session(iters_s8=1, model_size=(64, 48))
    assert session.options["model_size"] == (64, 48)
    flow = session.compute(*camera_frames[:2])
    assert flow.shape == (96, 160, 2)


def test_sessions_in_two_threads_run_together_and_give_each_its_flow(cpu_model, camera_frames):
    a, b, c = camera_frames
    expected = [cpu_model.session(iters_s8=2).compute(a, b), cpu_model.session(iters_s8=2).compute(b, c)]
    results = [None, None]

    def run(i, pair):
        session = cpu_model.session(iters_s8=2)
        results[i] = [session.compute(*pair) for _ in range(3)]

    threads = [threading.Thread(target=run, args=(0, (a, b))), threading.Thread(target=run, args=(1, (b, c)))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for i in range(2):
        for flow in results[i]:
            np.testing.assert_array_equal(flow, expected[i])


def test_the_gil_is_released_while_the_network_runs(checkpoint, fixture_pair):
    # While another thread computes, this one keeps running Python. With the GIL held for the
    # whole computation it could not: its longest pause would be the computation itself. One
    # inference thread leaves this one a core.
    session = neuflow.Model(checkpoint, backend="cpu", threads=1).session()
    session.compute(*fixture_pair)  # the plan for this size: made once, outside what is compared
    duration = session._time_compute(*fixture_pair, runs=1)
    worker = threading.Thread(target=session.compute, args=fixture_pair)
    pauses = []
    worker.start()
    last = time.perf_counter()
    while worker.is_alive():
        time.sleep(0.001)
        now = time.perf_counter()
        pauses.append(now - last)
        last = now
    worker.join()
    assert len(pauses) > 10
    assert max(pauses) < duration / 2, (max(pauses), duration)


def test_one_session_called_from_two_threads_takes_them_in_turn(cpu_model, camera_frames):
    a, b = camera_frames[:2]
    session = cpu_model.session(iters_s8=1)
    expected = session.compute(a, b)
    results = []
    threads = [threading.Thread(target=lambda: results.append(session.compute(a, b))) for _ in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(results) == 3
    for flow in results:
        np.testing.assert_array_equal(flow, expected)
