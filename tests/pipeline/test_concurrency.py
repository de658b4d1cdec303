"""Two renders of one scene at once: both succeed, the work is done once, the cache stays whole."""

import contextlib
import subprocess

from fluidymation.pipeline.cache import StageCache

from tests.scenes import blob_scene, write_scene


SCENE = blob_scene(frames=(0, 4))


def test_two_renders_at_once_share_the_work_and_match_a_lone_render(cli, tmp_path, monkeypatch, command_line):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    for folder in ("alone", "shared"):
        write_scene(tmp_path / folder, SCENE)
    assert cli("-q", "render", tmp_path / "alone" / "scene.yaml")[0] == 0

    command, env = command_line("--debug", "-q", "render", tmp_path / "shared" / "scene.yaml")
    # each render logs to a file: a pipe read after the other render ended could fill and stall it
    log_files = [tmp_path / f"render-{k}.log" for k in range(2)]
    with contextlib.ExitStack() as stack:
        renders = [subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL,
                                    stderr=stack.enter_context(path.open("w"))) for path in log_files]
        for render in renders:
            render.wait()
    logs = [path.read_text() for path in log_files]
    assert [render.returncode for render in renders] == [0, 0], logs
    # each stage ran in one render; the other waited for it and took it from the cache
    for stage in ("masks blob", "stylize blob", "colorize blob", "encode"):
        assert sum(log.count(f"{stage}: running") for log in logs) == 1, stage
        assert sum(log.count(f"{stage}: cached") for log in logs) == 1, stage

    out = tmp_path / "shared" / "out"
    cache = StageCache(out)
    manifests = cache.manifests()
    assert len(manifests) == 5 and all(cache.hit(stage, layer, manifest["key"])
                                       for (stage, layer), manifest in manifests.items())
    assert not list(out.rglob("*.part*"))
    alone = tmp_path / "alone" / "out"
    for path in sorted(alone.glob("*/blob/*.png")) + [alone / "film.mp4"]:
        assert (out / path.relative_to(alone)).read_bytes() == path.read_bytes(), path
