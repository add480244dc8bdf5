"""PCD and KITTI files of the LiDAR sweeps (--formats), read back with Open3D and numpy."""

from __future__ import annotations

import numpy as np
import open3d as o3d

from raysim.cli import main
from tests.conftest import REPO


def test_pcd_and_kitti_files_hold_the_sweeps(tmp_path, capsys):
    out = tmp_path / "rec"
    args = ["render", str(REPO / "scenarios" / "busy_open_sea.yaml"), "-o", str(out), "--duration", "0.5",
            "--sensors", "lidar"]
    assert main(args + ["--formats", "pcd,kitti"]) == 0
    sweeps = sorted((out / "lidar" / "sweeps").glob("*.npz"))
    assert len(sweeps) == len(list((out / "lidar" / "pcd").glob("*.pcd"))) == len(list((out / "lidar" / "kitti").glob("*.bin")))
    with np.load(sweeps[2]) as sweep:
        cloud = o3d.t.io.read_point_cloud(str(out / "lidar" / "pcd" / f"{sweeps[2].stem}.pcd"))
        xyz = cloud.point.positions.numpy()
        np.testing.assert_array_equal(xyz, np.stack([sweep["x"], sweep["y"], sweep["z"]], axis=1))
        np.testing.assert_array_equal(cloud.point.intensity.numpy()[:, 0], sweep["intensity"].astype(np.float32))
        np.testing.assert_array_equal(cloud.point.ring.numpy()[:, 0], sweep["ring"])
        kitti = np.fromfile(out / "lidar" / "kitti" / f"{sweeps[2].stem}.bin", dtype="<f4").reshape(-1, 4)
        np.testing.assert_array_equal(kitti[:, :3], xyz)
        np.testing.assert_allclose(kitti[:, 3], sweep["intensity"] / 255.0, rtol=1e-6)
    # bird's-eye pictures: one per second of sweeps, with points drawn where the NPZ puts them
    from PIL import Image

    bev = sorted((out / "lidar" / "bev").glob("*.png"))
    assert [p.stem for p in bev] == [sweeps[0].stem]
    image = np.asarray(Image.open(bev[0]).convert("RGB"))
    with np.load(sweeps[0]) as sweep:
        near = (np.abs(sweep["x"]) < 99) & (np.abs(sweep["y"]) < 99)
        rows = np.floor(400 - sweep["x"][near] * 4).astype(int)
        cols = np.floor(400 - sweep["y"][near] * 4).astype(int)
    assert image.shape == (800, 800, 3) and (image[rows, cols].sum(axis=1) > 0).mean() > 0.99
    assert main(args + ["--formats", "ply"]) == 2
    assert "--formats" in capsys.readouterr().err
