"""What a reader cannot render faithfully is a warning naming the file and the element; --strict refuses it."""

from fluidymation.pipeline import resolve
from fluidymation.stages.vector import Unsupported

from tests.scenes import blob_scene, write_scene


def _with_unsupported(monkeypatch):
    opened = resolve.open_document

    def open_document(path, **options):
        document = opened(path, **options)
        document.unsupported = (Unsupported('<animate id="spin">', "attributeName 'foo' is not animated; drawn still"),
                                Unsupported("<style>", "property 'filter' of @keyframes pulse is ignored"))
        return document

    monkeypatch.setattr(resolve, "open_document", open_document)


def test_check_and_render_warn_and_strict_refuses(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    scene = write_scene(tmp_path, blob_scene())
    _with_unsupported(monkeypatch)
    code, _, err = cli("check", scene)
    assert code == 0
    assert "warning: unsupported: " in err and "blob.svg: <animate id=\"spin\">: attributeName 'foo'" in err
    assert "blob.svg: <style>: property 'filter'" in err
    code, _, err = cli("--strict", "render", scene, "--until", "masks")
    assert code == 2 and "--strict: 2 unsupported element(s)" in err and "<animate id=\"spin\">" in err
    assert not (tmp_path / "out" / "masks").exists()


def test_a_faithful_input_gives_no_warning(cli, tmp_path):
    code, _, err = cli("--strict", "check", write_scene(tmp_path, blob_scene()))
    assert code == 0 and "warning" not in err
