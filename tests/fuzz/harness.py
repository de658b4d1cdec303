"""The readers' fuzzing harness: mutate the project's own fixtures, run the CLI on each case in-process, and judge
the outcome. This module holds the scene, Lottie and SVG mutators and the running; tests/fuzz/packed.py and
rasters.py the other readers', tests/fuzz/readers.py names them all.

A case is the files of one tmp folder (``scene.yaml`` and its inputs) and the CLI arguments. The property:
exit code 0 or 2; with 2, stderr has an ``error:`` line naming the scene or one of its files; never exit 1
(internal error) nor an uncaught exception; under :data:`TIME_LIMIT` seconds; a peak resident size under
:data:`RSS_LIMIT`; nothing written outside the case's folder, nothing read outside it, the package, Python and the
system's files (audited with :func:`sys.addaudithook`, :data:`BAIT` files lie beside the folder), nothing
unpickled and no network access. Mutators take a :class:`random.Random` so the pytest subset (hypothesis
``randoms()``) and the long run (``python -m tests.fuzz``) share them.
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import os
import random
import re
import resource
import sys
import time
import traceback
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import yaml

ROOT = Path(__file__).parents[2]
TIME_LIMIT = 20.0
RSS_LIMIT = 2 * 2**30  # bytes: the peak resident size a case may reach
SMALL = {"size": [32, 32], "frames": {"start": 0, "end": 2}}

# ---------------------------------------------------------------------------------------------- seeds


def scene_seeds() -> list[tuple[str, dict]]:
    """Valid scene dicts: tests/scenes.py's blob scene and every example's scene.yaml, paths made absolute,
    made small (32² px, 2 frames) so ``check`` is quick."""
    from tests.scenes import blob_scene

    seeds = [("blob_scene", yaml.safe_load(blob_scene(size=32, frames=(0, 2))))]
    for path in sorted(ROOT.glob("examples/*/scene.yaml")):
        scene = yaml.safe_load(path.read_text())
        folder = path.parent

        def absolute(value):
            return str(folder / value) if isinstance(value, str) else value

        scene["input"] = absolute(scene["input"])
        for exemplar in (scene.get("exemplars") or {}).values():
            for key in ("image", "segments", "video", "images"):
                if key in exemplar:
                    exemplar[key] = absolute(exemplar[key])
            if exemplar.get("mask") not in (None, "auto", "full"):
                exemplar["mask"] = absolute(exemplar["mask"])
        for layer in scene.get("layers") or []:
            if isinstance(layer.get("keyframes"), dict):
                layer["keyframes"] = {k: absolute(v) for k, v in layer["keyframes"].items()}
        scene.update(copy.deepcopy(SMALL))
        seeds.append((path.parent.name, scene))
    return seeds


def lottie_seeds() -> list[tuple[str, bytes]]:
    paths = [ROOT / "examples/wave/wave.json", *sorted((ROOT / "tests/data/lottie").glob("*.json"))]
    return [(path.name, path.read_bytes()) for path in paths]


def svg_seeds() -> list[tuple[str, bytes]]:
    paths = [*sorted(ROOT.glob("examples/*/*.svg")), *sorted((ROOT / "tests/data/svg_animated").glob("*.svg"))]
    return [(path.name, path.read_bytes()) for path in paths]


# ---------------------------------------------------------------------------------------------- values

UNICODE = "ünï©ødé \u202e\u0000 ☃ \udcff"[:-1] + "𝔘"


def odd_value(rng: random.Random, depth: int = 0):
    """A value of a surprising type or size."""
    choices = [None, "", -1, 0, 1e308, -1e308, 10 ** 40, -(10 ** 40), [], {}, [1, 2, 3], {"a": {"b": [None]}},
               UNICODE, "#zzzzzz", "#12345", "red", "rgb(300, 0, 0)", "nan", "inf", "-inf", True, False, 0.5,
               "x" * 5000, 1.5, 65536, 2 ** 31, 2 ** 63, "../../../../etc/hostname", "/etc/hostname",
               "%04d", "*", "0:1", [0, "a"], [[1, 2], [3, 4]], float("nan"), float("inf"), -0.0]
    if depth < 2 and rng.random() < 0.1:
        return [odd_value(rng, depth + 1) for _ in range(rng.randint(0, 3))]
    return copy.deepcopy(rng.choice(choices))


def nodes(tree, path=()):
    """Every (path, value) below ``tree`` (dicts by key, lists by index), ``tree`` itself first."""
    yield path, tree
    if isinstance(tree, dict):
        for key, value in tree.items():
            yield from nodes(value, path + (key,))
    elif isinstance(tree, list):
        for index, value in enumerate(tree):
            yield from nodes(value, path + (index,))


def _parent(tree, path):
    for key in path[:-1]:
        tree = tree[key]
    return tree


def mutate_tree(rng: random.Random, tree, count: int | None = None, deep: bool = False):
    """``tree`` (a deep copy) with 1–3 of: a key or item deleted, a value replaced by :func:`odd_value` or by
    another node's value, an unknown key added, a value nested deep."""
    tree = copy.deepcopy(tree)
    for _ in range(count or rng.choice([1, 1, 1, 2, 3])):
        everything = list(nodes(tree))
        path, value = rng.choice(everything)
        action = rng.random()
        if not path:
            if isinstance(tree, dict):
                tree["unknown_" + str(rng.randint(0, 9))] = odd_value(rng)
            continue
        parent = _parent(tree, path)
        if action < 0.3:
            del parent[path[-1]]
        elif action < 0.75:
            parent[path[-1]] = odd_value(rng)
        elif action < 0.85:
            parent[path[-1]] = copy.deepcopy(rng.choice(everything)[1])
        elif action < 0.93 and isinstance(value, dict):
            value[rng.choice(["unknown", "colour", "Name", "z", "ty", "nm", "k"])] = odd_value(rng)
        elif deep:
            parent[path[-1]] = DEEP  # serialized as deep nesting (see :func:`deepen`)
        else:
            parent[path[-1]] = odd_value(rng)
    return tree


DEEP = "\u2603deep\u2603"


def deepen(rng: random.Random, text: str) -> str:
    """``text`` (JSON) with each :data:`DEEP` string made a value nested 50 to 100000 deep."""
    def nested(_):
        depth = rng.choice([50, 500, 5000, 100000])
        opening, closing = rng.choice([("[", "]"), ('{"k":', "}")])
        return opening * depth + "1" + closing * depth
    return re.sub(json.dumps(DEEP, ensure_ascii=True).replace("\\", "\\\\"), nested, text)


def truncate(rng: random.Random, data: bytes) -> bytes:
    return data[:rng.randrange(len(data))] if data else data


# ---------------------------------------------------------------------------------------------- cases


@dataclass
class Case:
    """The files of one case (relative path → bytes, under its tmp folder), the CLI arguments (``{scene}`` is
    replaced by the scene's path, ``{case}`` by the folder's) and what it is, for reports."""
    reader: str
    label: str
    files: dict[str, bytes]
    argv: list[str] = field(default_factory=lambda: ["-q", "check", "{scene}"])
    input_name: str | None = None
    names: tuple[str, ...] = ()  # more that an error may name: patterns, folders


def small_scene(input_name: str, extra: dict | None = None) -> bytes:
    return yaml.safe_dump({"version": 1, "input": input_name, **copy.deepcopy(SMALL),
                           "output": {"dir": "out"}, **(extra or {})}).encode()


def scene_case(rng: random.Random, seeds=None) -> Case:
    seeds = seeds or scene_seeds()
    name, scene = rng.choice(seeds)
    kind = rng.random()
    if kind < 0.8:
        text = yaml.safe_dump(mutate_tree(rng, scene), allow_unicode=rng.random() < 0.5).encode("utf-8", "replace")
        label = f"{name}: tree mutation"
    else:
        text = yaml.safe_dump(scene).encode()
        tricks = [lambda t: truncate(rng, t), lambda t: t + b"\nversion: 1\n", lambda t: b"!!python/object:os.system {}\n",
                  lambda t: b"a: &a [*a]\n", lambda t: t.replace(b"input:", b"input: !!binary AAAA\nx:"),
                  lambda t: b"- just\n- a list\n", lambda t: b"", lambda t: b"\xff\xfe\x00garbage",
                  lambda t: t.replace(b":", b":\t", 1), lambda t: b"x: " + b"[" * 10000,
                  lambda t: t + b"\nversion: 99\n", lambda t: b"version: 1\ninput: {}\n" + b"a" * 100]
        text = rng.choice(tricks)(text)
        label = f"{name}: text mutation"
    return Case("scene", label, {"scene.yaml": text})


def lottie_case(rng: random.Random, seeds=None, masks: bool = False) -> Case:
    seeds = seeds or lottie_seeds()
    name, data = rng.choice(seeds)
    if rng.random() < 0.8:
        tree = mutate_tree(rng, json.loads(data), deep=True)
        try:
            text = deepen(rng, json.dumps(tree, allow_nan=True)).encode()
        except (RecursionError, ValueError):
            text = data
        if rng.random() < 0.15:
            text = re.sub(rb'(?<=[:\[,])\s*-?\d+(\.\d+)?', lambda m: rng.choice([b"NaN", b"Infinity", b"-Infinity", b"1e999"]),
                          text, count=rng.randint(1, 20))
        label = f"{name}: tree mutation"
    else:
        text = rng.choice([truncate(rng, data), data.replace(b'"', b"'", 1), b"[" * 100000, b"{}", b"null", b"[]",
                           data + b"garbage", b'{"v":"5.5.2","fr":1e308,"ip":0,"op":1e308,"w":1e9,"h":1e9,"layers":[]}'])
        label = f"{name}: text mutation"
    argv = ["-q", "masks", "{scene}", "--frames", "0:1"] if masks else ["-q", "check", "{scene}"]
    return Case("lottie", label, {"anim.json": text, "scene.yaml": small_scene("anim.json")}, argv, "anim.json")


SMIL_ATTRS = {"dur": ["", "-1s", "indefinite", "1e308s", "nan", "1x", "0s", "2", "media"],
              "begin": ["", "click", "a.end+", "-1e308s", "x.begin; y.end", "1s;;", "indefinite", "wallclock(2020)",
                        "a.repeat(1e99)", "accessKey(a)"],
              "values": ["", ";", "a;b", "0;nan;1", "1,2;3", "M 0 0; L", "#12;red", "1e308;-1e308", "none"],
              "keyTimes": ["", "0;1;0.5", "1;0", "nan", "0;1", "0;0.5"], "keySplines": ["", "0 0 1", "2 0 0 1", "a b c d"],
              "calcMode": ["", "spline", "paced", "discrete", "bogus"], "repeatCount": ["", "-1", "nan", "1e308", "0"],
              "repeatDur": ["", "-1s", "indefinite"], "from": ["", "nan", "1 2 3 4 5"], "to": ["", "1e308", "M"],
              "by": ["", "x"], "type": ["", "rotate", "bogus", "scale"], "attributeName": ["", "d", "transform", "bogus"],
              "path": ["", "M", "M 0 0 L nan 1", "Z"], "rotate": ["", "auto", "nan"], "min": ["", "-1s"],
              "max": ["", "0s"], "restart": ["", "never", "bogus"], "fill": ["", "freeze", "bogus"],
              "additive": ["", "sum", "x"], "accumulate": ["", "sum", "x"], "href": ["", "#", "#nope", "http://x/"],
              "keyPoints": ["", "0;1;2", "nan"]}
CSS_BITS = ["@keyframes", "{", "}", "animation: a 1s;", "animation: a -1s infinite;", "animation-duration: nan;",
            "transform: rotate(1e308deg);", "transform: matrix(1,2);", "opacity: x;", "from {", "to {", "50% {",
            "1e308% {", "-5% {", "animation-timing-function: cubic-bezier(2, 0);", "steps(0)", "steps(1e308, end)",
            "animation-iteration-count: 1e308;", "transform-origin: 1e308px;", "fill: rgb(;", "var(--x)", "@import 'x';",
            "@media (x) {", "stroke-dasharray: -1;", "d: path('M');", "\\", "/*", "'", "url(x)", "calc(1/0)",
            "animation-delay: -1e308s;", "transform: translate(nan);", "animation-name: ;", ":not(", "*{animation:a 1s}"]
SVG_ATTR_VALUES = ["", "nan", "-1", "1e308", "inf", "M", "url(#nope)", "red;", "rotate(1e308)", "matrix(1)",
                   "translate(", "0 0 0", "100%", "-1e308", UNICODE, "#", "none", "a" * 5000]


def _mutate_svg_tree(rng: random.Random, root: ET.Element) -> str:
    elements = list(root.iter())
    element = rng.choice(elements)
    action = rng.random()
    local = element.tag.rsplit("}", 1)[-1]
    anims = [e for e in elements if e.tag.rsplit("}", 1)[-1] in ("animate", "set", "animateTransform", "animateMotion")]
    styles = [e for e in elements if e.tag.rsplit("}", 1)[-1] == "style"]
    if anims and action < 0.35:
        anim = rng.choice(anims)
        attr = rng.choice(list(SMIL_ATTRS))
        anim.set(attr, rng.choice(SMIL_ATTRS[attr]))
        return f"SMIL {attr}"
    if styles and action < 0.55 or action < 0.1:
        style = rng.choice(styles) if styles else element
        if style is element and local != "style":
            element.set("style", " ".join(rng.choice(CSS_BITS) for _ in range(rng.randint(1, 4))))
            return "style="
        text = style.text or ""
        position = rng.randrange(len(text) + 1)
        bits = " ".join(rng.choice(CSS_BITS) for _ in range(rng.randint(1, 4)))
        style.text = rng.choice([text[:position] + bits + text[position:], text[:position],
                                 text.replace(rng.choice(["s", "%", "deg", ";", "{", "("]), rng.choice(["", "x", "e308"]))])
        return "CSS"
    if action < 0.7 and element is not root:
        for parent in elements:
            if element in list(parent):
                parent.remove(element)
                return f"removed <{local}>"
    attrs = [(e, a) for e in elements for a in e.attrib]
    if attrs:
        target, attr = rng.choice(attrs)
        other = [e.attrib[a] for e, a in attrs]
        target.set(attr, rng.choice(other) if rng.random() < 0.4 else rng.choice(SVG_ATTR_VALUES))
        return f"attribute {attr.rsplit('}', 1)[-1]}"
    return "unchanged"


def svg_case(rng: random.Random, seeds=None, masks: bool = False) -> Case:
    seeds = seeds or svg_seeds()
    name, data = rng.choice(seeds)
    if rng.random() < 0.8:
        root = ET.fromstring(data)
        what = [_mutate_svg_tree(rng, root) for _ in range(rng.choice([1, 1, 2, 3]))]
        text = ET.tostring(root)
        label = f"{name}: {', '.join(what)}"
    else:
        text = rng.choice([truncate(rng, data), data.replace(b"<svg", b"<!DOCTYPE svg [<!ENTITY x 'y'>]><svg", 1),
                           data.replace(b">", b">&#0;", 1), b"", b"<svg/>", b"<svg xmlns='http://www.w3.org/2000/svg'"
                           b" width='1e308' height='-1'/>", data.replace(b"<", b"<<", 1),
                           b"<svg xmlns='http://www.w3.org/2000/svg'>" + b"<g>" * 5000 + b"</g>" * 5000 + b"</svg>"])
        label = f"{name}: text mutation"
    argv = ["-q", "check", "{scene}"]
    if masks:
        argv = ["-q", "masks", "{scene}", "--frames", "0:1"]
        first = first_layer(text)
        if first:
            argv.append(f"--layer={first}")  # a name may start with "-"
    return Case("svg", label, {"anim.svg": text, "scene.yaml": small_scene("anim.svg")}, argv, "anim.svg")


def first_layer(text: bytes) -> str | None:
    try:
        root = ET.fromstring(text)
    except ET.ParseError:
        return None
    for child in root:
        name = child.get("{http://www.inkscape.org/namespaces/inkscape}label") or child.get("id")
        if name and re.fullmatch(r"[\w .-]+", name):
            return name
    return None


# ---------------------------------------------------------------------------------------------- running


@dataclass
class Outcome:
    """How a case ended: exit code, output, time, and what the audit hook and the resident size saw."""
    code: int | None
    stdout: str
    stderr: str
    seconds: float
    exception: str | None = None  # "Type: message" of an exception that escaped main()
    stray_writes: list[str] = field(default_factory=list)
    stray_reads: list[str] = field(default_factory=list)
    forbidden: list[str] = field(default_factory=list)  # unpickling, network access
    peak_rss: int = 0  # bytes, the process's peak resident size after the case
    rss_before: int = 0  # bytes, the peak before it

    def problem(self, case: Case, folder: Path) -> str | None:
        """What breaks the property, or None."""
        if self.exception is not None:
            return f"uncaught {self.exception}"
        if self.forbidden:
            return f"forbidden: {self.forbidden[:3]}"
        if self.seconds > TIME_LIMIT:
            return f"took {self.seconds:.1f} s (limit {TIME_LIMIT:g} s)"
        if self.peak_rss > RSS_LIMIT and self.peak_rss > self.rss_before:
            return f"resident size reached {self.peak_rss / 2**20:.0f} MiB (limit {RSS_LIMIT / 2**20:.0f} MiB)"
        if self.stray_writes:
            return f"wrote outside its folder: {self.stray_writes[:3]}"
        if self.stray_reads:
            return f"read outside its folder: {self.stray_reads[:3]}"
        if self.code not in (0, 2):
            return f"exit {self.code}: {first_line(self.stderr)}"
        if self.code == 2:
            if "Traceback" in self.stderr:
                return f"traceback with exit 2: {first_line(self.stderr)}"
            lines = [line for line in self.stderr.splitlines() if line.startswith("error:")]
            if not lines:
                return f"exit 2 without an 'error:' line: {first_line(self.stderr)}"
            message = self.stderr[self.stderr.index("error:"):]
            if not any(name in message for name in case_names(case)):
                return f"error names no file: {first_line(message)}"
        return None


def case_names(case: Case) -> set[str]:
    """What an error about ``case`` may name: the scene, its input, the case's files (path or name), its extra
    ``names`` (patterns, folders)."""
    files = {name for path in case.files for name in (path, Path(path).name)}
    return {"scene.yaml", *([case.input_name] if case.input_name else []), *_named_input(case), *files, *case.names}


def _named_input(case: Case) -> list[str]:
    """The ``input:`` a (mutated) scene names, as written and as its file name, and the file names of the other
    paths it names (an exemplar's, in any form): an error may name them."""
    try:
        scene = yaml.safe_load(case.files.get("scene.yaml", b""))
    except (yaml.YAMLError, RecursionError, ValueError):
        return []
    if not isinstance(scene, dict):
        return []
    value = scene.get("input")
    named = [str(value), Path(str(value)).name] if isinstance(value, str) and value.strip() else []
    exemplars = scene.get("exemplars")
    for _, text in nodes(exemplars if isinstance(exemplars, dict) else {}):
        if isinstance(text, str) and Path(text).name.strip():
            named.append(Path(text).name)
    return named


def first_line(text: str) -> str:
    for line in text.splitlines():
        if line.strip() and not line.startswith("warning:"):
            return line.strip()[:300]
    return text.strip()[:300]


_watch: dict = {"folder": None}
_TMPFILE = getattr(os, "O_TMPFILE", -1) & ~os.O_DIRECTORY if hasattr(os, "O_TMPFILE") else 1 << 40
_WRITABLE = [os.devnull, "/dev/", "/proc/"]
#: Besides the case's folder and the user cache: the package and its fixtures, Python, the venv, the numba
#: cache, and the system's own files.
_READABLE = [*(f"{ROOT / name}/" for name in ("fluidymation", "pipeline", "stages", "engine", "configs", "tests",
                                              "examples", "fluidymation.egg-info")),
             f"{sys.prefix}/", f"{sys.base_prefix}/", "/proc/", "/dev/", "/usr/", "/etc/"]
_NETWORK = ("socket.connect", "socket.getaddrinfo", "urllib.Request")


def _numba_cache() -> str:
    return os.environ.get("NUMBA_CACHE_DIR", str(ROOT / ".numba-cache")) + "/"


def _numba_caching() -> bool:
    """Whether numba is the caller: it unpickles its own cache of compiled functions."""
    frame = sys._getframe(2)
    while frame is not None:
        if frame.f_code.co_filename.endswith(("numba/core/caching.py", "numba/core/serialize.py")):
            return True
        frame = frame.f_back
    return False


def _audit(event, args):
    if _watch["folder"] is None:
        return
    if event == "pickle.find_class" and not _numba_caching():
        _watch["forbidden"].append(f"unpickled {args[0]}.{args[1]}")
    elif event in _NETWORK:
        _watch["forbidden"].append(f"{event} {str(args[1])[:80]}")
    elif event == "open":
        _audit_open(*args)


def _audit_open(path, mode, flags):
    """Note a file written or read outside the places a case may use."""
    if not isinstance(path, (str, bytes, os.PathLike)):
        return  # a file descriptor
    writing = (isinstance(mode, str) and any(c in mode for c in "wax+")) or \
        (isinstance(flags, int) and flags & (os.O_WRONLY | os.O_RDWR | os.O_CREAT | os.O_APPEND))
    if writing and isinstance(flags, int) and flags & _TMPFILE == _TMPFILE:
        return  # tempfile.TemporaryFile: an anonymous file, nothing named is left behind
    path = os.path.abspath(os.fsdecode(path))
    inside = [_watch["folder"], _numba_cache()]
    if writing:
        _watch["written"].add(path)
        if not any(path.startswith(prefix) for prefix in inside + _WRITABLE):
            _watch["stray"].append(path)
    elif not any(path.startswith(prefix) for prefix in inside + _READABLE + [_watch["cache"]]) \
            and path not in _watch["written"] and os.path.isfile(path):
        _watch["reads"].append(path)  # a folder opened by name (os.scandir, rmtree) reads nothing


sys.addaudithook(_audit)

#: Files beside each case's folder that no reader may open (a path traversal would): ``../secret.*``.
BAIT = {"secret.png": b"\x89PNG\r\n\x1a\nbait", "secret.json": b'{"bait": 1}', "secret.svg": b"<svg/>"}


def _peak_rss() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def run_case(case: Case, folder: Path, debug: bool = False) -> Outcome:
    """Write ``case`` into ``folder/case`` (:data:`BAIT` beside it) and run the CLI on it in-process, cwd and user
    cache in that folder."""
    from fluidymation.pipeline import paths
    from fluidymation.pipeline.cli import main

    root = folder / "case"
    root.mkdir(parents=True, exist_ok=True)
    for name, data in BAIT.items():
        (folder / name).write_bytes(data)
    for name, data in case.files.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_bytes(data)
    argv = [arg.replace("{scene}", str(root / "scene.yaml")).replace("{case}", str(root)) for arg in case.argv]
    argv += ["--debug"] if debug else []
    out, err = io.StringIO(), io.StringIO()
    old_cwd, old_cache = os.getcwd(), os.environ.get("FLUIDYMATION_CACHE")
    os.environ["FLUIDYMATION_CACHE"] = str(root / "cache")
    os.chdir(root)
    _watch.update(folder=f"{root.resolve()}/", cache=f"{paths.cache_dir().resolve()}/", stray=[], reads=[],
                  written=set(), forbidden=[])
    rss_before = _peak_rss()
    start = time.perf_counter()
    code, exception = None, None
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(argv)
    except BaseException as exc:  # the property: nothing escapes main()
        exception = f"{type(exc).__name__}: {exc}"[:500]
        err.write(traceback.format_exc())
    finally:
        seconds = time.perf_counter() - start
        # temporary files (tempfile's probes, a worker's stderr) are gone by now: what is left was written
        stray = [path for path in dict.fromkeys(_watch["stray"]) if os.path.isfile(path)]
        reads, forbidden = list(dict.fromkeys(_watch["reads"])), _watch["forbidden"]
        _watch.update(folder=None)
        os.chdir(old_cwd)
        if old_cache is None:
            os.environ.pop("FLUIDYMATION_CACHE", None)
        else:
            os.environ["FLUIDYMATION_CACHE"] = old_cache
    return Outcome(code, out.getvalue(), err.getvalue(), seconds, exception, stray, reads, forbidden, _peak_rss(),
                   rss_before)


def signature(case: Case, outcome: Outcome, folder: Path) -> str:
    """A failure's identity: exit code, exception type and where it was raised (from a ``--debug`` rerun)."""
    kind = outcome.exception.split(":", 1)[0] if outcome.exception else ""
    where = ""
    if outcome.code == 1 or outcome.exception:
        rerun = run_case(case, folder / "debug", debug=True) if outcome.exception is None else outcome
        frames = re.findall(r'File "([^"]+)", line (\d+), in (\w+)', rerun.stderr)
        ours = [f for f in frames if f[0].startswith(str(ROOT)) and "/.venv/" not in f[0]] or frames
        if ours:
            where = f"{Path(ours[-1][0]).relative_to(ROOT) if ours[-1][0].startswith(str(ROOT)) else ours[-1][0]}:{ours[-1][1]}"
        match = re.search(r"^(\w+(?:\.\w+)*(?:Error|Exception|Warning|Exit)\w*):", rerun.stderr, re.M)
        kind = kind or (match.group(1) if match else "")
    problem = outcome.problem(case, folder) or ""
    problem = re.sub(r"/tmp/\S+|\d+(\.\d+)?|'[^']*'", "#", problem)[:160]
    return f"exit {outcome.code} {kind} {where} | {problem}"
