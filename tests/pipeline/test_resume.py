"""A render killed with SIGKILL and started again continues from its last finished frame."""

import json
import os
import signal
import subprocess
from pathlib import Path

import numpy as np
from fluidymation.engine.nnf import NNF
from fluidymation.pipeline.cache import StageCache
from fluidymation.pipeline.resume import FrameStates
from fluidymation.stages.fluidymation_stylizer import FluidymationStylizer
from fluidymation.stages.stylize import StylizedFrame

from tests.scenes import blob_scene, write_scene

FRAMES = 10

SCENE = blob_scene(size=48, frames=(0, FRAMES))


def _scene(folder: Path) -> Path:
    return write_scene(folder, SCENE)


def test_a_killed_render_resumes_without_redoing_frames_and_matches_an_uninterrupted_one(tmp_path, command_line):
    command, env = command_line("-q", "render", _scene(tmp_path / "whole"))
    assert subprocess.run(command, env=env, capture_output=True).returncode == 0

    scene = _scene(tmp_path / "killed")
    command, env = command_line("--json", "render", scene)
    render = subprocess.Popen(command, env=env, stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True)
    for line in render.stderr:
        step = json.loads(line)
        if step["stage"] == "stylize" and step["done"] >= FRAMES // 2:
            render.send_signal(signal.SIGKILL)
            break
    render.wait()
    render.stderr.close()
    assert render.returncode == -signal.SIGKILL
    folder = tmp_path / "killed" / "out" / "stylized" / "blob"
    finished = {path.name: (path.stat().st_ino, path.stat().st_mtime_ns) for path in folder.glob("*.png")}
    assert FRAMES // 2 <= len(finished) < FRAMES

    command, env = command_line("--debug", "-q", "render", scene)
    restarted = subprocess.run(command, env=env, capture_output=True, text=True)
    assert restarted.returncode == 0, restarted.stderr
    assert "stylize blob: resuming after frame" in restarted.stderr
    report = json.loads((tmp_path / "killed" / "out" / "report.json").read_text())
    resumed = next(entry["resumed"] for entry in report["stages"] if entry["stage"] == "stylize")
    # the last frame written may lack its state if the kill came in between: then it is redone
    assert len(finished) - 1 <= resumed <= len(finished)
    kept = {name: stamp for name, stamp in finished.items() if int(name[:5]) < resumed}
    assert all((folder / name).stat().st_ino == ino and (folder / name).stat().st_mtime_ns == mtime
               for name, (ino, mtime) in kept.items())

    whole = tmp_path / "whole" / "out"
    for index in range(FRAMES):
        name = f"stylized/blob/{index:05d}.png"
        assert (tmp_path / "killed" / "out" / name).read_bytes() == (whole / name).read_bytes(), name
    assert (tmp_path / "killed" / "out" / "film.mp4").read_bytes() == (whole / "film.mp4").read_bytes()
    assert not StageCache(tmp_path / "killed" / "out").state_dir("stylize", "blob").exists()


def _state(index, value):
    nnf = NNF(np.full((2, 2), index, np.int32), np.full((2, 2, 3), value, np.float32))
    rgba = np.full((2, 2, 4), value, np.float32)
    return StylizedFrame(index=index, rgba=rgba, nnf=nnf, backlog=np.full((2, 2), value, np.float32))


def test_the_resume_point_is_the_longest_finished_prefix_with_a_saved_state(tmp_path):
    states = FrameStates(tmp_path, FluidymationStylizer())
    states.save(_state(5, 0.5))
    states.save(_state(4, 0.25))  # processing in reverse: 5 then 4; 5's state is dropped
    assert sorted(path.name for path in tmp_path.iterdir()) == ["00004.npz"]
    order = [5, 4, 3, 2]
    count, (index, nnf, backlog, rgb) = states.resume_point(order, lambda frame: frame in (5, 4, 2))
    assert (count, index) == (2, 4) and nnf.frame[0, 0] == 4 and backlog[0, 0] == np.float32(0.25)
    assert rgb.shape == (2, 2, 3) and rgb[0, 0, 0] == np.float32(0.25)
    assert states.resume_point(order, lambda frame: frame == 5) is None  # frame 4's files are missing


def test_a_restart_under_another_key_starts_over(tmp_path):
    cache = StageCache(tmp_path)
    state = cache.begin("stylize", "blob", "key-a")
    (state / "00003.npz").write_bytes(b"state")
    assert cache.begin("stylize", "blob", "key-a") == state and (state / "00003.npz").exists()
    assert not any(cache.begin("stylize", "blob", "key-b").iterdir())
    cache.commit("stylize", "blob", "key-b", [])
    assert not state.exists() and cache.lookup("stylize", "blob")["key"] == "key-b"


def test_finished_files_get_the_mode_the_umask_gives_not_the_temporary_files(tmp_path):
    from fluidymation.stages.files import write_text

    umask = os.umask(0)
    os.umask(umask)  # only read
    write_text(tmp_path / "out.txt", "done")
    assert (tmp_path / "out.txt").stat().st_mode & 0o777 == 0o666 & ~umask
    assert list(tmp_path.iterdir()) == [tmp_path / "out.txt"]
