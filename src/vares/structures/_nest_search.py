"""The nesting search in a process of its own, so that its time bound can stop it.

Run as a script by :func:`vares.structures.nesting.nest_pieces` (the process loads spyrrow
alone, not vares); :func:`run` is the search itself, which that function runs in a thread where
it cannot start a Python process. Reads the instance as one JSON object from stdin; writes one
JSON line to stdout for every feasible nest the search reports on its way (``"feasible"``), then
the search's own result (``"final"``), or ``"error"`` with the message of a search that failed.
Each line has the nest's ``width`` (its length along the roll) and its ``placed`` pieces as
``[index, rotation, x, y]``; the final one also says whether the exploration ended by itself
(``"explored"``): after exactly ``failed_attempts`` failed attempts in a row (sparrow's early
termination), the last of them reported before the exploration's time was up. Only then did its
clock not decide where the exploration ended (the compression's clock is the whole bound, which
the caller stops the search at).
"""

import json
import sys
import threading
import time


def _record(kind: str, solution=None, message: str = "", **more) -> dict:
    record: dict = {"kind": kind, **more}
    if solution is not None:
        record["width"] = float(solution.width)
        record["placed"] = [
            [int(p.id), float(p.rotation), float(p.translation[0]), float(p.translation[1])]
            for p in solution.placed_items
        ]
    if message:
        record["message"] = message
    return record


def run(spec: dict, emit) -> None:
    """The search of ``spec`` (module docs), each record given to ``emit`` as it comes."""
    import spyrrow

    items = [
        spyrrow.Item(
            str(index),
            [tuple(point) for point in shape],
            demand=1,
            allowed_orientations=spec["orientations"],
        )
        for index, shape in enumerate(spec["shapes"])
    ]
    instance = spyrrow.StripPackingInstance("roll", strip_height=spec["height"], items=items)
    config = spyrrow.StripPackingConfig(
        early_termination=True,
        total_computation_time=None,
        exploration_time=spec["exploration_seconds"],
        compression_time=spec["compression_seconds"],
        min_items_separation=spec["separation"],
        num_workers=1,
        seed=spec["seed"],
    )
    progress = spyrrow.ProgressQueue()
    outcome: dict = {}

    def search() -> None:
        try:
            outcome["solution"] = instance.solve(config, progress=progress)
        except BaseException as exc:  # a panic in the Rust code arrives as a BaseException
            outcome["error"] = str(exc) or type(exc).__name__

    thread = threading.Thread(target=search, daemon=True)
    started = time.monotonic()  # before the search: its exploration's clock starts later
    thread.start()
    Report = spyrrow.ReportType
    failed, last_failure = 0, None  # failed attempts since the last feasible exploration
    while True:
        thread.join(0.02)
        for kind, solution in progress.drain():
            if kind == Report.ExplInfeas:
                failed += 1
                last_failure = time.monotonic() if failed == spec["failed_attempts"] else None
            elif kind in (Report.ExplFeas, Report.CmprFeas):
                failed = 0 if kind == Report.ExplFeas else failed
                emit(_record("feasible", solution))
        if not thread.is_alive():
            break
    if "error" in outcome:
        emit(_record("error", message=outcome["error"]))
        return
    explored = (
        failed == spec["failed_attempts"]
        and last_failure is not None
        and last_failure < started + spec["exploration_seconds"]
    )
    emit(_record("final", outcome["solution"], explored=explored))


def main() -> None:
    def emit(record: dict) -> None:
        sys.stdout.write(json.dumps(record) + "\n")
        sys.stdout.flush()

    run(json.load(sys.stdin), emit)


if __name__ == "__main__":
    main()
