"""Worker processes of the long run (tests/fuzz/__main__.py): each runs cases in-process, as the test suite does;
one that crashes, hangs past :data:`HANG_LIMIT` or whose processes grow past :data:`RSS_KILL` resident bytes is
killed and replaced, and its case reported."""

import resource
import time
from pathlib import Path

from tests.fuzz.harness import RSS_LIMIT, TIME_LIMIT, run_case, signature

HANG_LIMIT = 3 * TIME_LIMIT  # seconds before a worker is killed (its case already failed at TIME_LIMIT)
RSS_KILL = 2 * RSS_LIMIT  # bytes resident in a worker and its children before it is killed


def _serve(connection) -> None:
    """A worker: run each case sent, reply with its outcome, problem and failure signature."""
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    while (job := connection.recv()) is not None:
        case, folder = job
        outcome = run_case(case, folder)
        problem = outcome.problem(case, folder)
        connection.send((outcome, problem, signature(case, outcome, folder) if problem else None))


def tree_rss(pid: int) -> int:
    """Resident bytes of process ``pid`` and its descendants (0 once it is gone)."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
        rss = next((int(line.split()[1]) * 1024 for line in status.splitlines() if line.startswith("VmRSS:")), 0)
        children = [int(child) for task in Path(f"/proc/{pid}/task").iterdir()
                    for child in (task / "children").read_text().split()]
    except (OSError, ValueError):
        return 0
    return rss + sum(tree_rss(child) for child in children)


class Worker:
    """A worker process and the case it is running (``job``: index, case, folder, start time)."""

    def __init__(self, context):
        self.context = context
        self.start()

    def start(self) -> None:
        self.connection, child = self.context.Pipe()
        self.process = self.context.Process(target=_serve, args=(child,), daemon=True)
        self.process.start()
        child.close()
        self.job = None

    def submit(self, index, case, folder) -> None:
        self.connection.send((case, folder))
        self.job = (index, case, folder, time.monotonic())

    def restart(self) -> None:
        self.process.kill()
        self.process.join()
        self.connection.close()
        self.start()

    def stop(self) -> None:
        self.connection.send(None)
        self.process.join(10)
        self.process.kill()

    def result(self, ready) -> tuple[str | None, str | None, bool] | None:
        """(problem, signature, whether to restart) once the job ends, else None; kills a hung or swollen worker."""
        seconds = time.monotonic() - self.job[3]
        if self.connection in ready:
            try:
                outcome, problem, key = self.connection.recv()
            except EOFError:
                self.process.join()
                code = self.process.exitcode
                reason = f"signal {-code}" if code and code < 0 else f"exit {code}"
                return f"the worker died ({reason})", f"crash | worker died ({reason})", True
            return problem, key, outcome.peak_rss > RSS_LIMIT / 2  # a fresh peak keeps the next cases measurable
        if seconds > HANG_LIMIT:
            return f"no answer after {seconds:.0f} s", f"hang | no answer after {HANG_LIMIT:g} s", True
        rss = tree_rss(self.process.pid)
        if rss > RSS_KILL:
            return f"{rss / 2**20:.0f} MiB resident", f"memory | over {RSS_KILL / 2**20:.0f} MiB resident", True
        return None
