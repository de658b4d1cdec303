"""The long run: ``python -m tests.fuzz --cases 10000 [--reader NAME ...] [--seed N] [--workers N] [--out DIR]``.

Cases run in worker processes (tests/fuzz/worker.py), so a native crash, a hang or a memory blow-up is reported
as the case's failure and the run goes on. Prints per reader the cases run and the distinct failures (exit code, exception type,
where, first line), each with a reproducer: the case's folder (scene.yaml, its input, argv.txt) kept under ``--out``.
"""

import argparse
import json
import multiprocessing
import random
import shutil
import sys
import tempfile
import time
from multiprocessing.connection import wait
from pathlib import Path

from tests.fuzz.readers import READERS
from tests.fuzz.worker import Worker

def run_reader(reader: str, args, out: Path, context) -> dict[str, list]:
    """Run ``args.cases`` cases of ``reader``; returns signature → [count, reproducer folder]."""
    maker, seeds_of, has_masks = READERS[reader]
    seeds = seeds_of()
    rng = random.Random(f"{args.seed}-{reader}")
    failures: dict[str, list] = {}
    start, run = time.monotonic(), 0
    workers = [Worker(context) for _ in range(args.workers)]
    with tempfile.TemporaryDirectory(prefix=f"fuzz-{reader}-") as work:
        index = 0
        while True:
            for worker in workers:
                if worker.job is None and index < args.cases and not (
                        args.minutes and time.monotonic() - start > 60 * args.minutes):
                    masks = has_masks and args.masks_every and index % args.masks_every == args.masks_every - 1
                    case = maker(rng, seeds, **({"masks": True} if masks else {}))
                    worker.submit(index, case, Path(work) / f"{index:06d}")
                    index += 1
            busy = [worker for worker in workers if worker.job is not None]
            if not busy:
                break
            ready = wait([worker.connection for worker in busy], timeout=0.5)
            for worker in busy:
                ended = worker.result(ready)
                if ended is None:
                    continue
                problem, key, restart = ended
                number, case, folder, _ = worker.job
                worker.job = None
                run += 1
                if problem:
                    _keep(failures, key, case, problem, folder, out / reader, f"[{reader} #{number}]")
                shutil.rmtree(folder, ignore_errors=True)
                if restart:
                    worker.restart()
    for worker in workers:
        worker.stop()
    print(f"{reader}: {run} cases, {len(failures)} distinct failures ({time.monotonic() - start:.0f} s)", flush=True)
    for key, (count, keep) in sorted(failures.items(), key=lambda item: -item[1][0]):
        print(f"  {count:5d}x {key}\n         reproducer: {keep}")
    return failures


def _keep(failures, key, case, problem, folder, out: Path, where: str) -> None:
    """Count a failure; keep the first case of each signature as a reproducer."""
    entry = failures.setdefault(key, [0, None])
    entry[0] += 1
    if entry[1] is not None:
        return
    keep = out / f"failure-{len(failures):03d}"
    shutil.rmtree(keep, ignore_errors=True)
    keep.mkdir(parents=True)
    for name, data in case.files.items():
        (keep / name).parent.mkdir(parents=True, exist_ok=True)
        (keep / name).write_bytes(data)
    (keep / "argv.txt").write_text(json.dumps(case.argv) + "\n" + case.label + "\n" + problem + "\n")
    entry[1] = keep
    print(f"  {where} new failure: {key}", flush=True)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tests.fuzz")
    parser.add_argument("--cases", type=int, default=1000, help="cases per reader")
    parser.add_argument("--reader", choices=list(READERS), action="append", help="default: all")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--workers", type=int, default=1, help="worker processes running cases at once")
    parser.add_argument("--masks-every", type=int, default=50,
                        help="every Nth vector case runs `masks` instead of `check` (0: never)")
    parser.add_argument("--out", type=Path, default=None, help="where reproducers go (default: a new tmp folder)")
    parser.add_argument("--minutes", type=float, default=None, help="stop each reader after this long")
    args = parser.parse_args(argv)
    out = args.out or Path(tempfile.mkdtemp(prefix="fluidymation-fuzz-"))
    out.mkdir(parents=True, exist_ok=True)
    print(f"reproducers under {out}", flush=True)
    context = multiprocessing.get_context("spawn")
    failed = False
    for reader in args.reader or list(READERS):
        failed |= bool(run_reader(reader, args, out, context))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
