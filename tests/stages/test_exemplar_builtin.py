import numpy as np
import pytest
from scipy import ndimage

from fluidymation.errors import StageError
from fluidymation.stages import exemplar_builtin as eb


def _params(preset="watercolor-bloom", **changes):
    values = dict(preset=preset, seed=1, size=(48, 40), frames=6, color="#2a6fdb", wetness=0.5)
    values.update(changes)
    return eb.Params(**values)


@pytest.mark.parametrize("preset", sorted(eb.PRESETS))
def test_presets_are_bit_identical_for_a_seed_and_well_formed(preset):
    params = _params(preset)
    first = eb.make_builtin_exemplar(params)
    again = eb.make_builtin_exemplar(params)
    assert first.rgb.shape == (6, 40, 48, 3) and first.rgb.dtype == np.float32
    assert first.mask.shape == (6, 40, 48) and first.mask.dtype == bool
    assert first.flow.shape == (6, 40, 48, 2) and first.flow.dtype == np.float32
    assert 0.0 <= first.rgb.min() and first.rgb.max() <= 1.0
    assert all(m.any() for m in first.mask)
    for name in ("rgb", "mask", "flow"):
        assert np.array_equal(getattr(first, name), getattr(again, name))
    other = eb.make_builtin_exemplar(_params(preset, seed=2))
    assert not np.array_equal(first.rgb, other.rgb)


def test_cache_hit_returns_identical_arrays_without_simulating(tmp_path, monkeypatch):
    params = _params("crumble")
    calls = []
    made = eb.make_builtin_exemplar(params, cache_dir=tmp_path, progress=lambda: calls.append(1))
    assert len(calls) == params.frames
    monkeypatch.setattr(eb, "generate", lambda *a, **k: pytest.fail("simulated again despite the cache"))
    cached = eb.make_builtin_exemplar(params, cache_dir=tmp_path)
    for name in ("rgb", "mask", "flow"):
        assert np.array_equal(getattr(made, name), getattr(cached, name))
    assert [p.name for p in tmp_path.iterdir()] == [params.cache_key()]


def test_cache_key_depends_on_every_parameter():
    base = _params()
    keys = {base.cache_key()}
    for change in (dict(seed=2), dict(size=(40, 48)), dict(frames=7), dict(color="#000000"), dict(wetness=0.4)):
        keys.add(_params(**change).cache_key())
    assert len(keys) == 6


def test_interrupted_cache_write_leaves_no_entry(tmp_path, monkeypatch):
    params = _params("crumble")
    real_save = np.save

    def failing_save(path, array):
        if str(path).endswith("mask.npy"):
            raise KeyboardInterrupt
        real_save(path, array)

    monkeypatch.setattr(eb.np, "save", failing_save)
    with pytest.raises(KeyboardInterrupt):
        eb.make_builtin_exemplar(params, cache_dir=tmp_path)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "size, frames",
    [((64, 64), 10), pytest.param((256, 256), 40, marks=pytest.mark.slow)],  # the slow case is the default size
)
def test_bloom_grows_with_outward_velocity_at_its_edge(size, frames):
    exemplar = eb.make_builtin_exemplar(_params("watercolor-bloom", size=size, frames=frames))
    areas = exemplar.mask.sum(axis=(1, 2))
    assert np.all(np.diff(areas) >= 0) and areas[-1] > areas[0]
    outward = total = 0
    for mask, flow in zip(exemplar.mask[1:], exemplar.flow[1:]):
        boundary = mask & ~ndimage.binary_erosion(mask)
        normal_y, normal_x = np.gradient(-ndimage.gaussian_filter(mask.astype(float), 1.5))
        dot = flow[..., 0] * normal_x + flow[..., 1] * normal_y
        outward += int((dot[boundary] > 0).sum())
        total += int(boundary.sum())
    assert outward >= 0.9 * total


def test_dry_wash_ends_with_darker_edges():
    exemplar = eb.make_builtin_exemplar(_params("watercolor-dry", size=(64, 64), frames=8))
    mask = exemplar.mask[-1]
    rgb = exemplar.rgb[-1].astype(np.float64)
    paper = rgb[~mask].mean(axis=0)
    density = -np.log(np.clip(rgb / paper, 1e-3, 1.0)).mean(axis=2)  # optical density of the pigment
    depth = ndimage.distance_transform_edt(mask)
    assert density[(depth > 0) & (depth <= 3)].mean() >= 1.3 * density[depth > 8].mean()


def test_crumble_mask_shrinks():
    exemplar = eb.make_builtin_exemplar(_params("crumble", frames=8))
    areas = exemplar.mask.sum(axis=(1, 2))
    assert np.all(np.diff(areas) < 0)


@pytest.mark.parametrize(
    "change, message",
    [(dict(preset="oil"), "valid"), (dict(color="blue"), "#rrggbb"), (dict(frames=1), "frames"),
     (dict(size=(8, 8)), "size"), (dict(wetness=2.0), "wetness")],
)
def test_bad_parameters_are_stage_errors(change, message):
    with pytest.raises(StageError, match=message):
        _params(**change)
