"""`fluidymation guides` on a tiny scene: files, numbering, raw arrays, motion direction."""

import numpy as np
import pytest

from tests.pipeline.test_bad_input import scene_for
from tests.scenes import turning_gear_lottie, turning_gear_svg


def moving_disk_scene(tmp_path, frames=16):
    for index in range(frames):
        (tmp_path / f"f{index:02d}.svg").write_text(
            f'<svg xmlns="http://www.w3.org/2000/svg" width="64" height="48"><g id="disk">'
            f'<circle cx="{12 + 2 * index}" cy="24" r="8"/></g></svg>')
    return scene_for(tmp_path, "f%02d.svg", "layers:\n  - name: disk\n    params: {blur_sigma: 1, "
                                            "shape_radius: 4, border_width: 3}\n")


def test_guides_writes_views_and_raw_arrays_numbered_by_frame(cli, tmp_path):
    scene = moving_disk_scene(tmp_path)
    code, out, err = cli("-q", "guides", scene, "--layer", "disk", "--frames", "7:10", "--raw", "-o", tmp_path / "g")
    assert code == 0, err
    for channel in ("flow", "ext_plus", "ext_minus", "shape", "dist", "segments"):
        assert sorted(p.name for p in (tmp_path / "g" / channel).glob("*.png")) == ["00007.png", "00008.png", "00009.png"]
    flow = np.load(tmp_path / "g" / "flow" / "00008.npy")
    assert flow.shape == (48, 64, 2) and flow.dtype == np.float32
    leading, trailing = flow[24, 36], flow[24, 20]  # the disk at frame 8 spans x 20..36 at y 24
    for edge in (leading, trailing):  # moving right at 2 px/frame
        assert 1.4 < edge[0] < 2.6 and abs(edge[1]) < 0.4


def test_guides_default_folder_and_unknown_layer(cli, tmp_path):
    scene = moving_disk_scene(tmp_path, frames=3)
    assert cli("-q", "guides", scene, "--layer", "disk")[0] == 0
    assert (tmp_path / "out" / "scene" / "guides" / "disk" / "flow" / "00002.png").is_file()
    code, _, err = cli("guides", scene, "--layer", "nope")
    assert code == 2 and "no layer called 'nope'" in err


def test_guides_bad_layer_param(cli, tmp_path):
    scene = scene_for(tmp_path, "f%02d.svg", "layers:\n  - name: disk\n    params: {blur_sigma: -1}\n")
    (tmp_path / "f00.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" width="8" height="8"><g id="disk"/></svg>')
    code, _, err = cli("guides", scene, "--layer", "disk")
    assert code == 2 and "scene.yaml" in err and "blur_sigma" in err


def test_given_flows_replace_the_estimate(cli, tmp_path):
    scene = moving_disk_scene(tmp_path, frames=4)
    (tmp_path / "flows").mkdir()
    for index in range(4):
        np.save(tmp_path / "flows" / f"{index:03d}.npy", np.full((48, 64, 2), (0.5, -1.5), np.float32))
    code, _, err = cli("-q", "guides", scene, "--layer", "disk", "--raw", "-o", tmp_path / "g",
                       "--flow", tmp_path / "flows" / "%03d.npy")
    assert code == 0, err
    assert np.array_equal(np.load(tmp_path / "g" / "flow" / "00002.npy"), np.full((48, 64, 2), (0.5, -1.5), np.float32))
    code, _, err = cli("guides", scene, "--layer", "disk", "--flow", tmp_path / "none" / "%03d.npy")
    assert code == 2 and "no files match" in err


def turning_gear_scene(tmp_path, flow=None, make=turning_gear_svg):
    chosen = "" if flow is None else f"    flow: {flow}\n"
    return scene_for(tmp_path, make(tmp_path).name, "frames: {start: 0, end: 4}\nlayers:\n  - name: gear\n" + chosen)


@pytest.mark.parametrize("make", [turning_gear_svg, turning_gear_lottie])
def test_a_turning_gear_reads_its_motion_from_the_geometry_where_the_masks_see_almost_none(cli, tmp_path, make):
    omega = np.radians(360 / 72)  # rad/frame at 24 fps
    yy, xx = np.mgrid[:64, :64] + 0.5
    radius = np.hypot(xx - 32, yy - 32)
    hub = (radius > 3) & (radius < 14)  # inside the gear at every angle
    speeds = {}
    for flow in ("vector", "masks"):
        folder = tmp_path / flow
        folder.mkdir()
        scene = turning_gear_scene(folder, None if flow == "vector" else flow, make)
        code, _, err = cli("-q", "guides", scene, "--layer", "gear", "--raw", "-o", folder / "g")
        assert code == 0, err
        field = np.load(folder / "g" / "flow" / "00002.npy")
        speeds[flow] = np.hypot(field[..., 0], field[..., 1])[hub] / (omega * radius[hub])
    np.testing.assert_allclose(speeds["vector"], 1.0, rtol=0.05)  # flow: vector is the default
    assert np.median(speeds["masks"]) < 0.5


def test_an_unknown_flow_source_is_refused(cli, tmp_path):
    from tests.pipeline.test_masks_cli import EXAMPLES

    scene = scene_for(tmp_path, EXAMPLES / "wave" / "wave.json", "defaults: {flow: sideways}\n")
    code, _, err = cli("masks", scene)
    assert code == 2 and "'sideways' is not one of vector, masks" in err
