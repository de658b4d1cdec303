"""The long run: ``python -m tests.fuzz --cases 10000 [--reader scene|lottie|svg] [--seed N] [--out DIR]``.

Prints per reader the cases run and the distinct failures (exit code, exception type, where, first line), each
with a reproducer: the case's folder (scene.yaml, its input, argv.txt) kept under ``--out``.
"""

import argparse
import json
import random
import shutil
import sys
import tempfile
import time
from pathlib import Path

from tests.fuzz.harness import MAKERS, lottie_seeds, run_case, scene_seeds, signature, svg_seeds


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tests.fuzz")
    parser.add_argument("--cases", type=int, default=1000, help="cases per reader")
    parser.add_argument("--reader", choices=sorted(MAKERS), action="append", help="default: all three")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--masks-every", type=int, default=50,
                        help="every Nth Lottie/SVG case runs `masks --frames 0:1` instead of `check` (0: never)")
    parser.add_argument("--out", type=Path, default=None, help="where reproducers go (default: a new tmp folder)")
    parser.add_argument("--minutes", type=float, default=None, help="stop each reader after this long")
    args = parser.parse_args(argv)
    out = args.out or Path(tempfile.mkdtemp(prefix="fluidymation-fuzz-"))
    out.mkdir(parents=True, exist_ok=True)
    print(f"reproducers under {out}", flush=True)
    seeds = {"scene": scene_seeds(), "lottie": lottie_seeds(), "svg": svg_seeds()}
    failed = False
    for reader in args.reader or ["scene", "lottie", "svg"]:
        rng = random.Random(f"{args.seed}-{reader}")
        failures: dict[str, list] = {}
        start, run = time.monotonic(), 0
        with tempfile.TemporaryDirectory(prefix=f"fuzz-{reader}-") as work:
            for index in range(args.cases):
                if args.minutes and time.monotonic() - start > 60 * args.minutes:
                    break
                masks = reader != "scene" and args.masks_every and index % args.masks_every == args.masks_every - 1
                case = MAKERS[reader](rng, seeds[reader], **({"masks": True} if masks else {}))
                folder = Path(work) / f"{index:06d}"
                outcome = run_case(case, folder)
                run += 1
                if outcome.problem(case, folder):
                    key = signature(case, outcome, folder)
                    entry = failures.setdefault(key, [0, None])
                    entry[0] += 1
                    if entry[1] is None:
                        keep = out / reader / f"failure-{len(failures):03d}"
                        shutil.rmtree(keep, ignore_errors=True)
                        keep.mkdir(parents=True)
                        for name, data in case.files.items():
                            (keep / name).write_bytes(data)
                        (keep / "argv.txt").write_text(json.dumps(case.argv) + "\n" + case.label + "\n")
                        (keep / "stderr.txt").write_text(outcome.stderr)
                        entry[1] = keep
                        print(f"  [{reader} #{index}] new failure: {key}", flush=True)
                shutil.rmtree(folder, ignore_errors=True)
        print(f"{reader}: {run} cases, {len(failures)} distinct failures ({time.monotonic() - start:.0f} s)")
        for key, (count, keep) in sorted(failures.items(), key=lambda item: -item[1][0]):
            print(f"  {count:5d}x {key}\n         reproducer: {keep}")
        failed |= bool(failures)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
