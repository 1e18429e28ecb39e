"""The `plslam` Python module, run from ctest (Python.Pytest) against the build tree.

PLSLAM_CLI names the `plslam` command, PLSLAM_TEST_TMP a scratch folder kept between runs (the
rendered sequence is reused).
"""
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import plslam

CLI = os.environ["PLSLAM_CLI"]
TMP = Path(os.environ["PLSLAM_TEST_TMP"])


def render(name, *args):
    """A synthetic sequence rendered once per build (synth.json is written last)."""
    out = TMP / name
    if not (out / "mav0" / "synth" / "synth.json").exists():
        subprocess.run([CLI, "synth", "--out", str(out), *args], check=True, capture_output=True)
    return out


@pytest.fixture(scope="session")
def office_loop():
    # The README's demo sequence: the office loop, 480 frames at 20 Hz, exact ground truth.
    return render("office_loop", "--scene", "office", "--preset", "euroc", "--frames", "480", "--loop", "--seed", "1")


@pytest.fixture(scope="session")
def office_short():
    return render("office_short", "--scene", "office", "--preset", "euroc", "--frames", "40", "--seed", "1")


def read_tum(path):
    return np.loadtxt(path, ndmin=2)


def test_version_matches_the_cli():
    out = subprocess.run([CLI, "--version"], check=True, capture_output=True, text=True).stdout
    assert plslam.version() in out


def test_calibration_file_round_trip_and_errors(tmp_path):
    good = tmp_path / "stereo.yaml"
    good.write_text("width: 752\nheight: 480\nfx: 458.6\nfy: 457.3\ncx: 367.2\ncy: 248.4\nbaseline: 0.110\n")
    c = plslam.read_calibration(str(good))
    assert (c.width, c.height) == (752, 480)
    assert c.baseline == pytest.approx(0.110)
    bad = tmp_path / "bad.yaml"
    bad.write_text("width: 752\nheight: 480\nfx: 458.6\nfy: 457.3\ncx: 367.2\ncy: 248.4\nbaseline: -0.1\n")
    with pytest.raises(plslam.InputError, match="bad.yaml"):
        plslam.read_calibration(str(bad))
    with pytest.raises(plslam.InputError, match="missing.yaml"):
        plslam.read_calibration(str(tmp_path / "missing.yaml"))


def test_dataset_reads_frames_as_numpy(office_short):
    ds = plslam.Dataset(str(office_short))
    assert len(ds) == 40
    t, left, right = ds[0]
    c = ds.calibration
    assert left.shape == (c.height, c.width) and right.shape == left.shape
    assert left.dtype == np.uint8
    assert ds[-1][0] == pytest.approx(ds.timestamps[-1])
    assert ds.ground_truth.shape == (40, 8)
    with pytest.raises(IndexError):
        ds[40]


def test_track_refuses_wrong_images_and_timestamps(office_short):
    ds = plslam.Dataset(str(office_short))
    slam = plslam.System(ds.calibration, sequential=True)
    t, left, right = ds[0]
    with pytest.raises(plslam.InputError, match="calibration says"):
        slam.track(left[:-1], right[:-1], t)
    with pytest.raises(ValueError):
        slam.track(np.zeros((2, 2, 2, 2), np.uint8), right, t)
    f = slam.track(left, right, t)
    assert f.index == 0 and f.tracked and f.state == "tracking" and f.frame_state == "tracked"
    assert f.pose_covariance.shape == (6, 6) and not f.pose_covariance.any()  # the first frame is the world
    with pytest.raises(plslam.InputError, match="does not follow"):
        slam.track(left, right, t)
    g = slam.track(*ds[1][1:], ds[1][0])
    assert g.tracked and g.point_inliers > 0
    cov = g.pose_covariance
    assert np.allclose(cov, cov.T) and np.all(np.linalg.eigvalsh(cov) > 0)
    assert 0 < cov[0, 0] < 1e-4  # a standard deviation under 1 cm
    slam.shutdown()
    with pytest.raises(RuntimeError):
        slam.track(left, right, t + 1)


def test_tracking_releases_the_gil(office_short):
    """Another Python thread runs while a frame is tracked (the switch interval is set so long that
    it could not run otherwise)."""
    ds = plslam.Dataset(str(office_short))
    slam = plslam.System(ds.calibration, sequential=True)
    frames = [ds[i] for i in range(6)]
    count = [0]
    stop = threading.Event()

    def spin():
        # It sleeps between counts, so it hands the GIL back at once when track() wants it again
        # (a busy loop would keep it for the whole switch interval).
        while not stop.is_set():
            count[0] += 1
            time.sleep(0.0002)

    old = sys.getswitchinterval()
    sys.setswitchinterval(100.0)
    worker = threading.Thread(target=spin)
    worker.start()
    try:
        during = []
        for t, left, right in frames:
            before = count[0]
            slam.track(left, right, t)
            during.append(count[0] - before)
    finally:
        stop.set()
        sys.setswitchinterval(old)
        worker.join()
    slam.shutdown()
    assert sum(during) > 0, during


def test_deterministic_tracking_is_reproducible_and_with_a_one_frame_lag_sequential(office_short, tmp_path):
    """deterministic=True: mapping on its own thread, met at frames fixed in advance: two runs
    are identical; with the local BA met before the next frame (mapping.ba_merge_after_frames: 1,
    and ba_merge_ms_per_1000_observations: 0, so not later for a large window) and no loop, the
    final trajectory is sequential's."""
    ds = plslam.Dataset(str(office_short))
    lag1 = tmp_path / "lag1.yaml"
    lag1.write_text("mapping:\n  ba_merge_after_frames: 1\n  ba_merge_ms_per_1000_observations: 0\n")
    trajectories = []
    for kw in ({"deterministic": True}, {"deterministic": True},
               {"deterministic": True, "config": lag1}, {"sequential": True, "config": lag1}):
        slam = plslam.System(ds.calibration, **kw)
        for t, left, right in (ds[i] for i in range(30)):
            slam.track(left, right, t)
        slam.shutdown()
        trajectories.append(slam.trajectory())
    assert trajectories[0].shape == (30, 8)
    assert np.array_equal(trajectories[0], trajectories[1])
    assert np.array_equal(trajectories[2], trajectories[3])


def test_office_loop_poses_equal_the_cli_sequential_run(office_loop, tmp_path):
    """Python tracking of the office loop gives the CLI's poses (both --sequential, both with the
    render's IMU: the world turns gravity-aligned once it is initialised)."""
    ds = plslam.Dataset(str(office_loop))
    assert ds.has_imu
    with plslam.System(ds.calibration, preset=ds.preset, sequential=True) as slam:
        slam.use_imu(ds)
        for i in range(len(ds)):
            t, left, right = ds[i]
            slam.track(left, right, t)
    est = slam.trajectory()
    stats = slam.stats()
    assert stats["frames"] == len(ds) == 480
    assert stats["tracked"] == 480
    assert stats["loops"] >= 1
    assert stats["gravity_aligned"]

    out = tmp_path / "cli"
    subprocess.run([CLI, "run", str(office_loop), "--out", str(out), "--sequential", "--quiet"], check=True,
                   capture_output=True)
    cli = read_tum(out / "trajectory.tum")
    assert cli.shape == est.shape
    # trajectory.tum holds every digit of a pose (%.17g) and times to 1 ns: the same poses.
    np.testing.assert_allclose(est[:, 0], cli[:, 0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(est[:, 1:4], cli[:, 1:4], rtol=0, atol=1e-12)
    # A quaternion and its negative are the same rotation.
    dots = np.abs(np.sum(est[:, 4:] * cli[:, 4:], axis=1))
    np.testing.assert_allclose(dots, 1.0, atol=1e-12)

    errors = plslam.eval.ape(ds.ground_truth, est)
    cli_errors = plslam.eval.ape(ds.ground_truth, cli)
    assert errors["pairs"] == 480
    assert errors["ape_trans_m"]["rmse"] < 0.02
    assert errors["ape_trans_m"]["rmse"] == pytest.approx(cli_errors["ape_trans_m"]["rmse"], abs=1e-6)

    m = slam.map()
    assert m["points"].shape[1] == 3 and m["points"].shape[0] == stats["points"] > 1000
    assert m["lines"].shape[1] == 6 and m["lines"].shape[0] == stats["lines"] > 50
    assert m["keyframes"].shape == (stats["keyframes"], 8)

    saved = tmp_path / "office.plmap"
    slam.save_map(str(saved))
    info = subprocess.run([CLI, "map", "info", str(saved), "--json"], check=True, capture_output=True, text=True)
    assert '"keyframes"' in info.stdout


def test_eval_ape_of_identical_trajectories_is_zero(office_short):
    gt = plslam.Dataset(str(office_short)).ground_truth
    r = plslam.eval.ape(gt, gt)
    assert r["pairs"] == 40
    assert r["ape_trans_m"]["rmse"] == pytest.approx(0.0, abs=1e-9)
    with pytest.raises(ValueError):
        plslam.eval.ape(gt[:, :7], gt)
