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
from fluidymation.pipeline.progress import use_json_lines

COMMANDS = ("check", "masks", "guides", "synth", "exemplar", "render", "ablate", "compare", "cache")

EXIT_USAGE = 2
EXIT_INTERNAL = 1


class _ArgumentParser(argparse.ArgumentParser):
    """argparse that reports usage errors through the same path as input errors."""

    def error(self, message):
        self.print_usage(sys.stderr)
        raise _UsageError(f"{self.prog}: {message}")


class _UsageError(Exception):
    pass


def build_parser() -> argparse.ArgumentParser:
    parser = _ArgumentParser(
        prog="fluidymation",
        description="Make vector animations look as if real paint were moving on paper.",
    )
    parser.add_argument("--version", action="version", version=f"fluidymation {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks and detailed logs")
    parser.add_argument("--strict", action="store_true",
                        help="refuse inputs holding anything that cannot be rendered faithfully (by default a warning "
                             "names each such element)")
    parser.add_argument("-q", "--quiet", action="store_true", help="no progress bars")
    parser.add_argument("--json", action="store_true",
                        help='progress as JSON lines on stderr ({"stage", "layer", "done", "total"}) instead of bars')
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_ArgumentParser)
    subparsers.required = True
    for name in COMMANDS:
        importlib.import_module(f"fluidymation.pipeline.commands.{name}").add_parser(subparsers)
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
        args = build_parser().parse_args(argv)
        use_json_lines(args.json)
        return int(args.run(args) or 0)
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
