"""Write the packed Lottie fixtures from the plain JSON fixtures in tests/data/lottie/.

- lottie/parenting.tgs    Telegram sticker form: gzip of parenting.json (plus "tgs": 1)
- lottie/precomp.lottie   dotLottie form: a zip with manifest.json and animations/anim.json
                          holding precomp.json

Plain Python, deterministic (gzip mtime 0, fixed zip timestamps), so re-running it gives
byte-identical files.  Run:  python tests/data/make_packed.py
"""
import gzip
import io
import json
import os
import zipfile

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "lottie")
ZIP_TIME = (1980, 1, 1, 0, 0, 0)


def _load(name):
    with open(os.path.join(HERE, name), encoding="utf-8") as f:
        return json.load(f)


def _compact(data):
    return json.dumps(data, separators=(",", ":"), sort_keys=False).encode("utf-8")


def write_tgs(src, dst):
    data = _load(src)
    data["tgs"] = 1
    buf = io.BytesIO()
    with gzip.GzipFile(filename="", mode="wb", fileobj=buf, mtime=0) as gz:
        gz.write(_compact(data))
    with open(os.path.join(HERE, dst), "wb") as f:
        f.write(buf.getvalue())


def write_dotlottie(src, dst, anim_id="anim"):
    manifest = {
        "version": "1",
        "generator": "fluidymation tests/data/make_packed.py",
        "animations": [{"id": anim_id, "speed": 1.0, "loop": True, "autoplay": True}],
    }
    members = [
        ("manifest.json", _compact(manifest)),
        (f"animations/{anim_id}.json", _compact(_load(src))),
    ]
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        for name, payload in members:
            info = zipfile.ZipInfo(name, date_time=ZIP_TIME)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            zf.writestr(info, payload)
    with open(os.path.join(HERE, dst), "wb") as f:
        f.write(buf.getvalue())


def main():
    write_tgs("parenting.json", "parenting.tgs")
    write_dotlottie("precomp.json", "precomp.lottie")


if __name__ == "__main__":
    main()
