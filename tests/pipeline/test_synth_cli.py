import imageio.v3 as iio
import numpy as np
import pytest
from scipy.ndimage import gaussian_filter


@pytest.fixture
def job(tmp_path):
    rng = np.random.default_rng(0)
    style = gaussian_filter(rng.random((32, 36, 3)), (1, 1, 0))
    style = ((style - style.min()) / (style.max() - style.min()) * 255).astype(np.uint8)
    ys, xs = np.mgrid[0:32, 0:36]
    gradient = np.stack([xs * 7, ys * 7, np.zeros_like(xs)], axis=2).astype(np.uint8)
    grey = (xs * 7).astype(np.uint8)
    paths = {name: tmp_path / f"{name}.png" for name in ("style", "src", "tgt", "srcgrey", "tgtgrey", "small")}
    iio.imwrite(paths["style"], style)
    iio.imwrite(paths["src"], gradient)
    iio.imwrite(paths["tgt"], gradient)
    iio.imwrite(paths["srcgrey"], grey)
    iio.imwrite(paths["tgtgrey"], grey)
    iio.imwrite(paths["small"], gradient[:10, :10])
    return tmp_path, paths, style


def test_synth_reproduces_the_style_when_guides_agree(cli, job):
    tmp_path, paths, style = job
    out, nnf = tmp_path / "out" / "result.png", tmp_path / "nnf.npy"
    code, stdout, stderr = cli(
        "synth", "--style", paths["style"], "--guide", paths["src"], paths["tgt"], "--weight", 4,
        "--guide", paths["srcgrey"], paths["tgtgrey"], "--patch-size", 5, "--uniformity", 0,
        "--seed", 1, "-o", out, "--nnf", nnf, "--report",
    )
    assert code == 0, stderr
    result = iio.imread(out)
    assert result.shape == style.shape and result.dtype == np.uint8
    mse = np.mean((result.astype(float) - style) ** 2) / 255**2
    assert mse < 1e-4  # PSNR > 40 dB
    field = np.load(nnf)
    assert field.shape == (32, 36, 4) and field.dtype == np.float32
    assert "mean patch error:" in stdout
    assert not any(p.name.endswith(".part.png") for p in out.parent.iterdir())


def test_same_seed_same_bytes(cli, job):
    tmp_path, paths, _ = job
    outputs = []
    for name in ("a.png", "b.png"):
        code, _, stderr = cli("-q", "synth", "--style", paths["style"], "--guide", paths["src"], paths["tgt"],
                              "--search-vote-iters", 2, "--seed", 3, "-o", tmp_path / name)
        assert code == 0, stderr
        outputs.append((tmp_path / name).read_bytes())
    assert outputs[0] == outputs[1]


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--patch-size", "4"], "--patch-size"),
        (["--search-alpha", "1.5"], "--search-alpha"),
        (["--guide", "{src}", "{small}"], "small.png"),
        (["--guide", "{small}", "{tgt}"], "small.png"),
        (["--guide", "{src}", "{tmp}/missing.png"], "missing.png"),
    ],
)
def test_bad_input_names_the_option_or_file(cli, job, extra, message):
    tmp_path, paths, _ = job
    extra = [e.format(tmp=tmp_path, **{k: str(v) for k, v in paths.items()}) for e in extra]
    code, _, stderr = cli("synth", "--style", paths["style"], "--guide", paths["src"], paths["tgt"], *extra,
                          "-o", tmp_path / "x.png")
    assert code == 2
    assert message in stderr
    assert not (tmp_path / "x.png").exists()


def test_weight_must_follow_style_or_guide(cli, job):
    tmp_path, paths, _ = job
    code, _, stderr = cli("synth", "--weight", 2, "--style", paths["style"], "--guide", paths["src"], paths["tgt"],
                          "-o", tmp_path / "x.png")
    assert code == 2 and "--weight" in stderr
