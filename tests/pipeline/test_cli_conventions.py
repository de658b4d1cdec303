"""CLI conventions: global options before or after the command, one number for a square size, and a start-up
that imports only what the command needs."""

import os
import subprocess
import sys

import imageio.v3 as iio
import pytest

from tests.scenes import ROOT, blob_scene, write_scene


@pytest.mark.parametrize("words", [["-q", "check"], ["check", "-q"], ["check", "--json", "--strict"]])
def test_global_options_go_before_or_after_the_command(cli, tmp_path, words):
    scene = write_scene(tmp_path, blob_scene())
    code, out, err = cli(*words, scene)
    assert code == 0, err
    assert "blob" in out


def test_a_flag_before_the_command_is_not_undone_by_the_commands_defaults(cli, tmp_path, capsys):
    from fluidymation.pipeline.cli import build_parser

    argv = ["-q", "--debug", "check", "scene.yaml"]
    args = build_parser(argv).parse_args(argv)
    assert args.quiet and args.debug and not args.json and not args.strict


def test_one_number_is_a_square_size(cli, tmp_path):
    code, _, err = cli("-q", "exemplar", "make", "watercolor-dry", "-o", tmp_path / "dry", "--size", 24,
                       "--frames", 2, "--cache", tmp_path / "cache")
    assert code == 0, err
    assert iio.imread(tmp_path / "dry" / "rgb" / "00000.png").shape == (24, 24, 3)
    scene = write_scene(tmp_path / "scene", blob_scene().replace("size: [40, 40]", "size: 36"))
    code, out, err = cli("check", scene)
    assert code == 0 and "36x36" in out, err


def test_version_and_help_import_no_command_module_nor_numpy():
    probe = ("import sys\nfrom fluidymation.pipeline.cli import main\n"
             "for argv in (['--version'], ['--help']):\n"
             "    try:\n        main(argv)\n    except SystemExit:\n        pass\n"
             "loaded = [m for m in sys.modules if m.startswith('fluidymation.pipeline.commands.') or m in "
             "('numpy', 'numba', 'tqdm', 'cairosvg')]\n"
             "print('LOADED', loaded)\n")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout
    assert "LOADED []" in out
    assert "compare" in out and "render" in out  # --help still lists every command



def _check(scene, cache) -> tuple[str, list[str]]:
    """``check``'s output for ``scene`` and the heavy modules it loaded, in a fresh interpreter with the user cache
    ``cache``."""
    probe = ("import sys\nfrom fluidymation.pipeline.cli import main\n"
             f"main(['check', {str(scene)!r}])\n"
             "heavy = ('numba', 'scipy', 'cairocffi', 'imageio', 'fluidymation.engine._jit')\n"
             "print('LOADED', *sorted({h for h in heavy for m in sys.modules if m == h or m.startswith(h + '.')}))\n")
    env = {**os.environ, "FLUIDYMATION_CACHE": str(cache)}
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True, env=env).stdout
    text, loaded = out.rsplit("LOADED", 1)
    return text, loaded.split()


def test_check_loads_no_numerical_code_and_draws_an_unchanged_input_once(tmp_path):
    drawing = tmp_path / "blob.svg"
    drawing.write_text((ROOT / "examples/blob/blob.svg").read_text())
    scene = write_scene(tmp_path, blob_scene().replace(str(ROOT / "examples/blob/blob.svg"), str(drawing)))
    text, loaded = _check(scene, tmp_path / "cache")
    assert loaded == ["cairocffi"] and "file: #2a6fdb" in text  # the fill colours are drawn
    assert _check(scene, tmp_path / "cache") == (text, [])  # and remembered
    drawing.write_text(drawing.read_text().replace("#2a6fdb", "#123456"))
    text, loaded = _check(scene, tmp_path / "cache")
    assert loaded == ["cairocffi"] and "file: #123456" in text  # a changed input is drawn again
