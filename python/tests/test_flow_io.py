"""Flow files, the colour wheel and the measures on NumPy arrays."""

import numpy as np
import pytest

import neuflow

from conftest import require


def random_flow(h=37, w=53, seed=0):
    rng = np.random.default_rng(seed)
    return (rng.standard_normal((h, w, 2)) * 20).astype(np.float32)


@pytest.mark.parametrize("extension", [".flo", ".npy"])
def test_flo_and_npy_read_back_bit_for_bit_with_invalid_pixels_nan(tmp_path, extension):
    flow = random_flow()
    flow[3, 4] = np.nan
    path = tmp_path / f"flow{extension}"
    neuflow.write_flow(path, flow)
    back = neuflow.read_flow(path)
    assert back.shape == flow.shape and back.dtype == np.float32
    np.testing.assert_array_equal(back, flow)  # NaN where NaN
    assert np.isnan(back[3, 4]).all()


def test_kitti_png_reads_back_bit_for_bit_at_its_precision(tmp_path):
    flow = np.round(random_flow() * 64) / 64  # KITTI keeps 1/64 px
    valid = np.ones(flow.shape[:2], dtype=bool)
    valid[0, :5] = False
    path = tmp_path / "flow.png"
    neuflow.write_flow(path, flow, valid=valid)
    back = neuflow.read_flow(path)
    expected = flow.copy()
    expected[~valid] = np.nan
    np.testing.assert_array_equal(back, expected)


def test_an_npy_file_is_one_numpy_reads(tmp_path):
    flow = random_flow()
    neuflow.write_flow(tmp_path / "f.npy", flow)
    np.testing.assert_array_equal(np.load(tmp_path / "f.npy"), flow)
    np.save(tmp_path / "g.npy", flow)
    np.testing.assert_array_equal(neuflow.read_flow(tmp_path / "g.npy"), flow)


def test_ground_truth_files_of_the_benchmarks_read(tmp_path):
    middlebury = neuflow.read_flow(require("flow-gt/middlebury/RubberWhale/flow10.flo"))
    assert middlebury.shape == (388, 584, 2)
    assert np.isnan(middlebury).any() and np.isfinite(middlebury).any()  # unknown pixels are NaN
    kitti = neuflow.read_flow(require("flow-gt/kitti/flow_gt.png"))
    assert kitti.shape == (375, 1242, 2)
    assert 0 < np.isfinite(kitti[..., 0]).mean() < 1  # sparse


def test_any_nonzero_mask_value_is_valid(tmp_path):
    flow = random_flow(4, 4)
    valid = np.full((4, 4), 256, dtype=np.int32)  # nonzero, though 0 modulo 256
    valid[0, 0] = 0
    neuflow.write_flow(tmp_path / "f.flo", flow, valid=valid)
    back = neuflow.read_flow(tmp_path / "f.flo")
    assert np.isnan(back[0, 0]).all() and np.isfinite(back[1:]).all()


def test_float64_flow_is_taken_as_float32(tmp_path):
    flow = random_flow().astype(np.float64)
    neuflow.write_flow(tmp_path / "f.flo", flow)
    np.testing.assert_array_equal(neuflow.read_flow(tmp_path / "f.flo"), flow.astype(np.float32))


def test_epe_and_the_rates_against_known_errors():
    gt = random_flow(20, 30)
    flow = gt + np.array([6.0, 8.0], dtype=np.float32)  # 10 px everywhere
    assert neuflow.epe(flow, gt) == pytest.approx(10.0, abs=1e-5)
    m = neuflow.metrics(flow, gt)
    assert m["valid_pixels"] == 600
    assert m["within_1px"] == 0 and m["within_3px"] == 0 and m["within_5px"] == 0
    assert m["fl_all"] == pytest.approx(np.mean(10.0 > 0.05 * np.linalg.norm(gt, axis=2)))
    # Only where gt is finite, and where `valid` says so.
    gt[0] = np.nan
    assert neuflow.metrics(flow, gt)["valid_pixels"] == 570
    valid = np.zeros((20, 30), dtype=bool)
    valid[5:10] = True
    flow[5:10] = gt[5:10]
    assert neuflow.epe(flow, gt, valid=valid) == 0.0
    assert neuflow.metrics(flow, gt, valid=valid)["valid_pixels"] == 150


def test_flow_to_color_draws_the_wheel():
    flow = np.zeros((8, 10, 2), dtype=np.float32)
    picture = neuflow.flow_to_color(flow)
    assert picture.shape == (8, 10, 3) and picture.dtype == np.uint8
    assert (picture == 255).all()  # no motion: white
    flow[..., 0] = 5.0  # rightwards: red in the standard wheel
    flow[0, 0] = np.nan
    right = neuflow.flow_to_color(flow, max_flow=5.0)
    assert tuple(right[4, 4]) == (255, 0, 0)
    assert tuple(right[0, 0]) == (0, 0, 0)  # invalid: black
    faint = neuflow.flow_to_color(flow, max_flow=50.0)
    assert faint[4, 4, 1] > 200  # a tenth of full saturation: nearly white
