"""The ``fluidymation`` command: parses arguments and dispatches to a command module.

Each command lives in :mod:`fluidymation.pipeline.commands` as a module with
``add_parser(subparsers)`` (which registers its sub-parser and sets ``run``) and
``run(args) -> int``. Errors caused by user input end with a one-paragraph message on
stderr and exit code 2; the traceback is shown only with ``--debug``.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
import traceback

from fluidymation import __version__
from fluidymation.errors import FluidymationError
from fluidymation.pipeline.progress import CompileNotice, use_json_lines

#: The commands and their one-line help, in the order ``--help`` lists them. A command's module is
#: imported only when that command runs, so ``--version``, ``--help`` and light commands start fast.
COMMANDS = {
    "check": "validate a scene file and print the resolved scene",
    "masks": "rasterize each scene layer into a mask sequence",
    "guides": "write views of a layer's guidance channels (flow, ext+, ext-, shape, distance)",
    "synth": "guided synthesis of one image, EbSynth-style",
    "exemplar": "list or make the built-in moving exemplars",
    "render": "render a scene to a video (or up to a stage)",
    "ablate": "render a layer with each energy term switched off, side by side",
    "compare": "paint a layer with several stylizers, side by side, with quality figures",
    "resynth": "synthesize a new clip with a drawn clip's geometry and motion (Hao et al. 2019)",
    "cache": "show or prune a scene's stage cache",
}

EXIT_USAGE = 2
EXIT_INTERNAL = 1


class _ArgumentParser(argparse.ArgumentParser):
    """argparse that reports usage errors through the same path as input errors."""

    def error(self, message):
        self.print_usage(sys.stderr)
        raise _UsageError(f"{self.prog}: {message}")


class _UsageError(Exception):
    pass


def _global_options(parser: argparse.ArgumentParser, *, default) -> None:
    """The options every command takes, before or after its name (``default``: argparse.SUPPRESS on a
    command's parser, so a flag given before the command is not reset by the command's defaults)."""
    parser.add_argument("--debug", action="store_true", default=default, help="show tracebacks and detailed logs")
    parser.add_argument("--strict", action="store_true", default=default,
                        help="refuse inputs holding anything that cannot be rendered faithfully (by default a warning "
                             "names each such element)")
    parser.add_argument("-q", "--quiet", action="store_true", default=default, help="no progress bars")
    parser.add_argument("--json", action="store_true", default=default,
                        help='progress as JSON lines on stderr ({"stage", "layer", "done", "total"}) instead of bars')


class _CommandParsers:
    """The ``subparsers`` action as a command module sees it: each parser it adds also takes the global options."""

    def __init__(self, subparsers):
        self._subparsers = subparsers

    def add_parser(self, name, **kwargs):
        parser = self._subparsers.add_parser(name, help=COMMANDS[name], **kwargs)
        _global_options(parser, default=argparse.SUPPRESS)
        return parser


def command_of(argv: list[str]) -> str | None:
    """The command named in ``argv``: its first word that is not an option (the global options take no value)."""
    return next((word for word in argv if not word.startswith("-")), None)


def build_parser(argv: list[str] | None = None) -> argparse.ArgumentParser:
    """The parser for ``argv``: the named command's full parser (its module imported), the others listed by name
    and help only. Without ``argv``, every command's full parser."""
    parser = _ArgumentParser(
        prog="fluidymation",
        description="Make vector animations look as if real paint were moving on paper.",
    )
    parser.add_argument("--version", action="version", version=f"fluidymation {__version__}")
    _global_options(parser, default=False)
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_ArgumentParser)
    subparsers.required = True
    chosen = None if argv is None else command_of(argv)
    for name, help_text in COMMANDS.items():
        if argv is None or name == chosen:
            importlib.import_module(f"fluidymation.pipeline.commands.{name}").add_parser(_CommandParsers(subparsers))
        else:
            subparsers.add_parser(name, help=help_text, add_help=False)
    return parser


def _configure_logging(debug: bool) -> None:
    """Our messages (warnings; with ``--debug`` stage keys and cache hits) go to this run's stderr as
    ``warning: ...``; other libraries' (numba's compiler internals) only from warnings up."""
    logging.basicConfig(level=logging.WARNING, format="%(name)s: %(message)s")
    logger = logging.getLogger("fluidymation")
    for handler in [handler for handler in logger.handlers if getattr(handler, "cli", False)]:
        logger.removeHandler(handler)
    handler = logging.StreamHandler(sys.stderr)
    handler.cli = True
    handler.addFilter(lambda record: setattr(record, "level", record.levelname.lower()) or True)
    handler.setFormatter(logging.Formatter("%(level)s: %(message)s"))
    logger.addHandler(handler)
    logger.setLevel(logging.DEBUG if debug else logging.WARNING)
    logger.propagate = False


def main(argv: list[str] | None = None) -> int:
    """Run the CLI with ``argv`` (default: ``sys.argv[1:]``) and return the exit code."""
    argv = sys.argv[1:] if argv is None else list(argv)
    debug = "--debug" in argv
    _configure_logging(debug)
    try:
        args = build_parser(argv).parse_args(argv)
        use_json_lines(args.json)
        notice = CompileNotice(quiet=args.quiet).listen()
        try:
            return int(args.run(args) or 0)
        finally:
            notice.close()
    except _UsageError as exc:
        print(exc, file=sys.stderr)
        return EXIT_USAGE
    except FluidymationError as exc:
        if debug:
            traceback.print_exc()
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("interrupted; finished frames are kept", file=sys.stderr)
        return 130
    except Exception as exc:  # a bug, not bad input: say so and where to look
        if debug:
            traceback.print_exc()
        else:
            print(f"internal error: {type(exc).__name__}: {exc} (run with --debug for the traceback)", file=sys.stderr)
        return EXIT_INTERNAL
