"""Safe reading of untrusted vector files: no entities, no external resources, no bombs.

Nothing named inside an input file is ever fetched: SVG references outside the document
(other than ``data:`` URIs) are refused with a clear error, and the rasterizer is given
a fetcher that refuses everything but ``data:``. A Lottie file's image assets may name
files beside it (:func:`file_beside`), never URLs or files elsewhere.
"""

from __future__ import annotations

import gzip
import io
import lzma
import re
import zipfile
import zlib
from pathlib import Path, PurePosixPath
from xml.etree import ElementTree

import defusedxml
import defusedxml.ElementTree as SafeElementTree

from fluidymation.errors import InputError

MAX_FILE_BYTES = 256 * 2**20
MAX_UNPACKED_BYTES = 64 * 2**20
XLINK_HREF = "{http://www.w3.org/1999/xlink}href"
_CSS_URL = re.compile(r"url\(\s*['\"]?\s*([^'\")\s]*)", re.IGNORECASE)
_CSS_IMPORT = re.compile(r"@import", re.IGNORECASE)
_URL_SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]+:")  # two letters at least: "C:" is a drive letter


def read_file(path: Path, *, limit: int = MAX_FILE_BYTES) -> bytes:
    """The bytes of ``path``; an InputError when missing, unreadable or over ``limit``."""
    try:
        size = path.stat().st_size
        if size > limit:
            raise InputError(f"{path}: the file is {size / 2**20:.0f} MiB, over the limit of {limit // 2**20} MiB")
        return path.read_bytes()
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise InputError(f"{path}: is a folder, not a file") from None
    except OSError as exc:
        raise InputError(f"{path}: cannot be read ({exc.strerror})") from None


def file_beside(folder: Path, reference: str, source: str, what: str, kind: str) -> Path:
    """The file that ``reference`` (a relative path named inside an input) names in the input's ``folder``.

    A URL, an absolute path, or a path that leaves ``folder`` (``..``, a link pointing
    elsewhere) is refused: an input may only use files beside it or in folders below.
    ``what`` names the referring element and ``kind`` the file (``image``) in the messages.
    """
    if _URL_SCHEME.match(reference) or reference.startswith("//"):
        raise InputError(f"{source}: {what} refers to the external {kind} '{reference}', a URL; Fluidymation never "
                         f"fetches URLs named inside an input: embed the {kind} or put it beside the input")
    root = folder.resolve()
    target = (root / reference).resolve()
    if PurePosixPath(reference.replace("\\", "/")).is_absolute() or not target.is_relative_to(root):
        raise InputError(f"{source}: {what} refers to the external {kind} '{reference}', outside the input's "
                         f"folder {folder}; refused: only files beside the input (or in folders below it) are read")
    if not target.is_file():
        raise InputError(f"{source}: {what} refers to the {kind} '{reference}', which is not a file in {folder}")
    return target


def gunzip_limited(data: bytes, source: str, *, limit: int = MAX_UNPACKED_BYTES) -> bytes:
    """Decompress gzip ``data``, refusing to inflate past ``limit`` bytes (gzip bombs)."""
    try:
        with gzip.GzipFile(fileobj=io.BytesIO(data)) as stream:
            out = stream.read(limit + 1)
    except (OSError, EOFError, zlib.error) as exc:
        raise InputError(f"{source}: not valid gzip data ({exc})") from None
    if len(out) > limit:
        raise InputError(f"{source}: unpacks to more than {limit // 2**20} MiB; refused (a gzip bomb?)")
    return out


def safe_zip_member_names(archive: zipfile.ZipFile, source: str) -> list[str]:
    """The member names of ``archive``; an InputError if any would escape its folder."""
    names = []
    total = 0
    for info in archive.infolist():
        path = PurePosixPath(info.filename.replace("\\", "/"))
        if path.is_absolute() or ".." in path.parts or re.match(r"^[A-Za-z]:", info.filename):
            raise InputError(f"{source}: the archive member '{info.filename}' points outside the archive; refused")
        total += info.file_size
        if total > MAX_UNPACKED_BYTES:
            raise InputError(f"{source}: unpacks to more than {MAX_UNPACKED_BYTES // 2**20} MiB; refused")
        names.append(info.filename)
    return names


def read_zip_member(archive: zipfile.ZipFile, name: str, source: str) -> bytes:
    """The bytes of member ``name``; an InputError when it is damaged, encrypted, compressed by an unknown method
    or over :data:`MAX_UNPACKED_BYTES`."""
    try:
        with archive.open(name) as member:
            data = member.read(MAX_UNPACKED_BYTES + 1)
    except (zipfile.BadZipFile, zlib.error, lzma.LZMAError, OSError, EOFError, ValueError) as exc:
        raise InputError(f"{source}: the archive member '{name}' is damaged ({exc})") from None
    except NotImplementedError:
        raise InputError(f"{source}: the archive member '{name}' is compressed by a method Python's zipfile does "
                         "not read (use deflate)") from None
    except RuntimeError as exc:  # zipfile's "File ... is encrypted, password required for extraction"
        raise InputError(f"{source}: the archive member '{name}' cannot be read ({exc})") from None
    if len(data) > MAX_UNPACKED_BYTES:
        raise InputError(f"{source}: '{name}' unpacks to more than {MAX_UNPACKED_BYTES // 2**20} MiB; refused")
    return data


def parse_xml(data: bytes, source: str) -> ElementTree.Element:
    """Parse untrusted XML: DTDs, entities and external references are refused."""
    try:
        return SafeElementTree.fromstring(data, forbid_dtd=True)
    except defusedxml.DefusedXmlException as exc:
        raise InputError(f"{source}: the file declares a DTD or XML entities ({type(exc).__name__}); "
                         "refused for safety: remove the <!DOCTYPE ...> / <!ENTITY ...> declarations") from None
    except ElementTree.ParseError as exc:
        line, column = exc.position
        raise InputError(f"{source}, line {line}, column {column}: malformed XML ({_xml_reason(exc)})") from None


def _xml_reason(exc: ElementTree.ParseError) -> str:
    return str(exc).split(":")[0]


def check_svg_references(root: ElementTree.Element, source: str) -> None:
    """Refuse any reference to a resource outside the document (files, URLs)."""
    for element in root.iter():
        tag = local_name(element.tag)
        for attribute in (XLINK_HREF, "href"):
            target = element.get(attribute)
            if target is not None and not is_internal_reference(target):
                raise InputError(f"{source}: <{tag}> refers to the external resource '{target}'; "
                                 "Fluidymation never fetches files or URLs named inside an input: "
                                 "embed it as a data: URI or remove it")
        for text in (element.get("style"), element.text if tag == "style" else None):
            if not text:
                continue
            if tag == "style" and _CSS_IMPORT.search(text):
                raise InputError(f"{source}: <style> uses @import, which would load an external file; refused")
            for target in _CSS_URL.findall(text):
                if not is_internal_reference(target):
                    raise InputError(f"{source}: <{tag}> style refers to the external resource '{target}'; refused")
        for name, value in element.attrib.items():
            if name in (XLINK_HREF, "href", "style"):
                continue
            for target in _CSS_URL.findall(value):
                if not is_internal_reference(target):
                    raise InputError(f"{source}: <{tag} {local_name(name)}> refers to the external resource "
                                     f"'{target}'; refused")


def is_internal_reference(target: str) -> bool:
    """Whether a reference stays inside the document: a fragment (``#id``), a ``data:`` URI or nothing."""
    target = target.strip()
    return target.startswith("#") or target.startswith("data:") or target == ""


def refuse_fetch(url, resource_type):
    """URL fetcher for cairosvg: inline ``data:`` URIs only."""
    if url.startswith("data:"):
        from cairosvg.url import fetch

        return fetch(url, resource_type)
    raise InputError(f"refused to fetch '{url}': inputs may not load external resources")


def local_name(tag: str) -> str:
    """'{namespace}name' -> 'name'."""
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else str(tag)
