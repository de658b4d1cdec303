import json

import imageio.v3 as iio
import numpy as np
import pytest

from fluidymation.stages import exemplar_builtin as eb


def test_list_shows_every_preset_with_defaults(cli):
    code, out, _ = cli("exemplar", "list")
    assert code == 0
    for name in eb.PRESETS:
        assert f"{name}: {eb.PRESETS[name].description}" in out
    assert "size=256x256" in out and "frames=60" in out


@pytest.mark.parametrize("size", [["40x32"], ["40", "32"]])  # a square: test_cli_conventions.py
def test_make_writes_frames_masks_flow_and_record(cli, tmp_path, size):
    out_dir = tmp_path / "bloom"
    code, _, err = cli("-q", "exemplar", "make", "watercolor-bloom", "-o", out_dir, "--seed", 3, "--size", *size,
                       "--frames", 4, "--color", "#aa3300", "--cache", tmp_path / "cache")
    assert code == 0, err
    assert sorted(p.name for p in (out_dir / "rgb").iterdir()) == [f"{i:05d}.png" for i in range(4)]
    rgb = iio.imread(out_dir / "rgb" / "00003.png")
    mask = iio.imread(out_dir / "mask" / "00003.png")
    flow = np.load(out_dir / "flow" / "00003.npy")
    assert rgb.shape == (32, 40, 3) and mask.shape == (32, 40)
    assert set(np.unique(mask)) == {0, 255}
    assert flow.shape == (32, 40, 2) and flow.dtype == np.float32
    record = json.loads((out_dir / "exemplar.json").read_text())
    assert record["name"] == "watercolor-bloom" and record["frames"] == 4 and record["size"] == [40, 32]
    assert record["params"]["seed"] == 3 and record["params"]["color"] == "#aa3300"
    expected = eb.make_builtin_exemplar(eb.Params(preset="watercolor-bloom", seed=3, size=(40, 32), frames=4,
                                                  color="#aa3300", wetness=0.5))
    assert np.array_equal(mask > 0, expected.mask[3])
    assert np.array_equal(flow, expected.flow[3])


def test_unknown_name_lists_the_valid_ones(cli, tmp_path):
    code, _, err = cli("exemplar", "make", "oil-paint", "-o", tmp_path / "x")
    assert code == 2
    assert "oil-paint" in err and all(name in err for name in eb.PRESETS)
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize(
    "option, message",
    [(["--size", "1", "2", "3"], "--size"), (["--color", "red"], "#rrggbb"), (["--frames", "1"], "frames")],
)
def test_bad_options_exit_2_with_a_message(cli, tmp_path, option, message):
    code, _, err = cli("exemplar", "make", "crumble", "-o", tmp_path / "x", "--no-cache", *option)
    assert code == 2
    assert message in err


def test_show_draws_a_contact_sheet(cli, tmp_path):
    out_dir = tmp_path / "crumble"
    assert cli("-q", "exemplar", "make", "crumble", "-o", out_dir, "--size", "32x24", "--frames", 5, "--no-cache")[0] == 0
    code, _, err = cli("-q", "exemplar", "show", out_dir, "-o", tmp_path / "sheet.png", "--count", 3)
    assert code == 0, err
    sheet = iio.imread(tmp_path / "sheet.png")
    assert sheet.shape == (3 * 24, 3 * 32 + 2 * 4, 3)
    outline = (sheet[24:48, :, 0] == 255) & (sheet[24:48, :, 1] == 0)
    assert outline.any()  # the mask outline is drawn in red in the second row
    assert sheet[48:, :32].any()  # the first frame's flow is not all zero


def test_show_without_frames_is_an_input_error(cli, tmp_path):
    code, _, err = cli("exemplar", "show", tmp_path, "-o", tmp_path / "sheet.png")
    assert code == 2 and "no frames" in err


def test_resolve_params_takes_defaults_and_checks_types():
    from fluidymation.errors import InputError
    from fluidymation.pipeline.presets import resolve_params

    params = resolve_params("crumble", size="64x32", seed=7)
    assert params.size == (64, 32) and params.seed == 7 and params.frames == 60 and params.color == "#2b2b2b"
    with pytest.raises(InputError, match="whole numbers"):
        resolve_params("crumble", seed=1.5)
    with pytest.raises(InputError, match="valid names"):
        resolve_params("sand")


def test_make_caches_where_render_looks(cli, tmp_path, monkeypatch):
    """`exemplar make` fills the user cache render reads ($FLUIDYMATION_CACHE), so a render after it
    does not simulate the medium again."""
    from fluidymation.pipeline import paths

    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "user-cache"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    code, _, err = cli("-q", "exemplar", "make", "crumble", "-o", tmp_path / "x", "--size", 24, "--frames", 3)
    assert code == 0, err
    assert paths.exemplar_cache_dir() == tmp_path / "user-cache" / "exemplars"
    assert any(paths.exemplar_cache_dir().iterdir())
    assert not (tmp_path / "xdg").exists()


def test_user_cache_falls_back_to_xdg_then_home(tmp_path, monkeypatch):
    from fluidymation.pipeline import paths

    monkeypatch.delenv("FLUIDYMATION_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert paths.cache_dir() == tmp_path / "xdg" / "fluidymation"
    monkeypatch.delenv("XDG_CACHE_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert paths.cache_dir() == tmp_path / "home" / ".cache" / "fluidymation"
