"""Parameter studies on Dask: every case of a study run on a cluster, tabulated, nothing recomputed.

``sweep(study, client=None)`` runs the cases of a :class:`~ngwear.studies.study.Study` on a
``dask.distributed`` cluster — by default a ``LocalCluster`` of single-threaded worker processes, one
per usable core — and returns a pandas table with one row per case: ``case``, the varied parameters
under their dotted keys, the study's outputs (:mod:`ngwear.studies.outputs`), ``status``, ``error``,
``warnings``, ``wall_time`` (seconds on the worker), ``worker`` (its address), ``factorised``, ``case_id`` and the
provenance ``ngwear_version``, ``ngsolve_version``, ``python_version`` (of the worker) and ``scene_sha256``
(:mod:`ngwear.results.provenance`); ``table.attrs["summary"]`` says what the study did.  A varied key whose values
mix text with numbers (``contact.friction = [0.3, "0.2 + 0.1*x"]``) is a column of text, the others written as JSON
(``"0.3"``).

Reuse.  Cases are submitted grouped by mesh and material (:attr:`Case.group`).  A worker runs its
cases in a case process of its own (:class:`~ngwear.child.Child`, one per worker thread), which
keeps the discretizations of the last :data:`CACHED_GROUPS` groups it ran and passes them to
``simulate(scene, discretization=...)``, so a worker meshes and factorises once per group it meets.
A case ``factorised`` when the change from its group's last case rebuilt the stiffness (:meth:`Discretization.reuse`)
or it is the first of its group in its process; the summary counts them.

Files in ``out``: ``cases/<case_id>/`` holds the case's ``Result.save`` folder (written by the worker
into a temporary folder and shipped back, so workers need no shared file system) and ``row.json``,
written last; ``results.parquet``, ``results.csv``, ``summary.json`` and ``plots/``
(:mod:`ngwear.views.sweep_plots`).

Robustness.  A case whose scene is invalid, or that raises a SceneError while running (a layer too thin
to mesh), is ``rejected``; one whose Newton iteration fails is ``stopped`` (its completed steps are
kept); both carry their one-line message in ``error``.  A case that kills its case process (a
segmentation fault, ``os._exit``, the kernel's OOM killer) fails alone: the worker and the cases queued
on it live on, and the next case starts a new case process.  Such a death and any other exception are
retried by Dask (:data:`RETRIES`); what still fails is ``crashed`` with one line (``the process running
it died of SIGSEGV (Segmentation fault)``).  The cases of a worker that dies itself are rescheduled on
the others (the scheduler's ``allowed-failures``).  A re-run in the same ``out`` skips every case with
a ``row.json`` (completed, stopped or rejected), so an interrupted study resumes; crashed cases run
again.  A set ``stop`` (the CLI's SIGINT and SIGTERM) ends the study at the next case boundary: the cases under
way are cancelled (their case processes end with their workers), the finished ones kept, the table not written.
"""
from __future__ import annotations

import json
import logging
import sys
import tempfile
import threading
import uuid
from collections import OrderedDict
from contextlib import contextmanager
from pathlib import Path
from time import perf_counter, sleep
from typing import TYPE_CHECKING, Any

from ..child import Child, ChildError
from ..model.keys import Level
from ..model.scene import SceneError
from ..results.folder import hold, remove, replacing
from ..results.history_csv import headed
from ..results.provenance import COLUMNS as PROVENANCE
from ..results.provenance import columns
from ..runs.progress import bar as progress_bar
from ..runs.simulate import simulate
from .outputs import OUTPUTS, outputs
from .outputs import QUANTITIES as OUTPUT_QUANTITIES
from .study import Case, Study, StudyError, load_study, study_from_dict

RETRIES = 2
"""Dask re-runs a case whose task raised or whose process died (not a rejected or stopped case: those are
results) this often."""
CACHED_GROUPS = 2
"""Discretizations (mesh, factorisation) each worker process keeps, most recently used first."""
FINISHED = ("completed", "stopped", "rejected")
"""Statuses that a re-run in the same folder keeps instead of running the case again."""
UNFINISHED = ("crashed", "interrupted")
"""Statuses of cases that a re-run runs again (``interrupted``: not run, the study was stopped)."""
POLL = 0.1
"""Seconds between two looks for finished cases and at the stop event."""
COLUMNS = ("status", "error", "warnings", "wall_time", "worker", "factorised", "case_id", *PROVENANCE)
CONNECT_TIMEOUT = 30

if TYPE_CHECKING:  # pandas is imported where a table is made, not with ``import ngwear``
    import pandas as pd


def sweep(study, client=None, *, out=None, workers: int | None = None,
          overrides: dict[str, Any] | None = None, progress: bool = True, stop=None) -> pd.DataFrame:
    """Run every case of a study on Dask and tabulate it; see the module docstring.

    Parameters
    ----------
    study : Study, path or dict
        A :class:`Study`, a study TOML file or its nested dict (scene paths relative to the working
        directory).
    client : distributed.Client, str or None
        The cluster: a client, a scheduler address (``"tcp://host:8786"``), or None for a new
        ``LocalCluster`` (closed at the end).
    out : path, optional
        Output folder (default ``out/<study name>``); finished cases found there are not run again.
    workers : int, optional
        Worker processes of the local cluster (default: one per usable core); with an existing
        cluster, the number of workers to wait for before submitting.
    overrides : dict, optional
        Extra fixed scene overrides (dotted keys, like the study's ``[set]``) for a path or dict.
    progress : bool
        Show a progress bar over all cases (and the Dask dashboard's link when it has one); without a terminal,
        log lines (see :mod:`ngwear.runs.progress`).
    stop : threading.Event, optional
        When set, the study stops at the next case boundary: the cases under way are cancelled, the finished
        ones are kept in ``out`` (a re-run skips them) and the others are ``interrupted``.

    Returns
    -------
    pandas.DataFrame
        One row per case: its index, the varied keys, the outputs, status, error, warnings, wall time, worker;
        ``attrs["summary"]`` counts the cases by status.  Also written to ``out`` (``results.parquet``,
        ``results.csv``, ``summary.json``, plots, each case's result folder); an interrupted study writes only
        its finished cases.

    Raises
    ------
    StudyError
        The study or ``workers`` is invalid, or the scheduler cannot be reached (one line naming the field).
    FolderError
        ``out`` is in use by another study (held like a run's output folder, see :func:`ngwear.results.folder.hold`).
    """
    if isinstance(study, Study) and overrides:
        raise StudyError("overrides: only for a study file or dict (a Study is already built)")
    if not isinstance(study, Study):
        study = (load_study(study, overrides) if isinstance(study, (str, Path))
                 else study_from_dict(study, overrides=overrides))
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise StudyError(f"workers: must be a whole number >= 1 (got {workers!r})")
    out = Path(out) if out is not None else Path("out") / study.name
    start = perf_counter()
    rows = {c.index: _row(status="rejected", error=c.error, case_id=c.id) for c in study.cases if c.error}
    with hold(out, "out"):
        earlier = _finished(out, study.cases)
        rows.update(earlier)
        todo = [c for c in study.cases if c.index not in rows]
        ran = {}
        if todo:
            with _connect(client, workers) as dask_client:
                ran = _run(dask_client, todo, out, study.name, len(study.cases), progress, stop)
        rows.update(ran)
        rows.update({c.index: _row(status="interrupted", case_id=c.id) for c in todo if c.index not in ran})
        table = _table(study, rows)
        summary = _summary(study, rows, ran, earlier, perf_counter() - start, out)
        if not summary["interrupted"]:
            _write(out, study, table)
            with replacing(out / "summary.json") as tmp:
                tmp.write_text(json.dumps(summary, indent=2))
    table.attrs["summary"] = summary
    return table


def summary_text(summary: dict) -> str:
    """The summary as two lines (what ``ngwear sweep`` prints)."""
    counts = ", ".join(f"{summary[s]} {s}" for s in (*FINISHED, *UNFINISHED) if summary[s])
    return (f"{summary['cases']} cases ({counts}); {summary['skipped']} finished earlier, {summary['run']} run "
            f"on {summary['workers']} workers in {summary['wall_time']:.1f} s\n"
            f"{summary['factorisations']} factorisations for {summary['groups']} mesh/material groups; "
            f"results in {summary['out']}")


# ---------------------------------------------------------------- on the workers

_IDLE: list[tuple[Child, str]] = []
"""This worker's case processes that run no case now, each with the group of its last case."""
_IDLE_LOCK = threading.Lock()
_CACHE: OrderedDict = OrderedDict()


def run_case(scene, group: str) -> tuple[dict, dict[str, bytes]]:
    """Run one case on this Dask worker, in a case process of the worker; (row, saved files).

    The case runs in a :class:`~ngwear.child.Child` of this worker that keeps the
    discretizations of its groups (one that ran ``group`` last is taken when idle), so a case that
    kills its process fails alone with :class:`~ngwear.child.ChildError`, and the worker, with
    the cases queued on it, lives on.
    """
    with _IDLE_LOCK:
        index = next((i for i, (_, last) in enumerate(_IDLE) if last == group), len(_IDLE) - 1)
        child = _IDLE.pop(index)[0] if _IDLE else Child()
    try:
        with tempfile.TemporaryDirectory() as tmp:
            row = child.call(simulate_case, scene, group, tmp)
            files = {p.relative_to(tmp).as_posix(): p.read_bytes() for p in sorted(Path(tmp).rglob("*"))
                     if p.is_file()}
    finally:
        with _IDLE_LOCK:
            _IDLE.append((child, group))
    return row | {"worker": _worker()}, files


def simulate_case(scene, group: str, folder: str) -> dict:
    """Run one case in this process, reusing the discretization of its group, and save it into ``folder``.

    Returns the row: every output of :data:`~ngwear.studies.outputs.OUTPUTS` and the bookkeeping.  A
    case process runs one case at a time.
    """
    with _quiet():
        start = perf_counter()
        cached = _CACHE.get(group)
        factorised = cached is None or cached.reuse(scene).rebuilt <= Level.STIFFNESS
        try:
            result = simulate(scene, discretization=cached, progress=False)
        except SceneError as err:
            return _row(status="rejected", error=str(err), wall_time=perf_counter() - start, factorised=False,
                        **columns(scene))
        disc = result.discretization
        _CACHE[group] = disc
        _CACHE.move_to_end(group)
        while len(_CACHE) > CACHED_GROUPS:
            _CACHE.popitem(last=False)
        result.save(folder)
        return _row(**outputs(result), status="completed" if result.completed else "stopped",
                    error=None if result.completed else result.status,
                    warnings="; ".join(result.warnings) or None, wall_time=perf_counter() - start,
                    factorised=factorised, **columns(scene))


@contextmanager
def _quiet():
    """Keep ngwear's per-run warnings out of the worker's log (they are in the row's ``warnings``)."""
    logger = logging.getLogger("ngwear")
    level = logger.level
    logger.setLevel(logging.ERROR)
    try:
        yield
    finally:
        logger.setLevel(level)


def _worker() -> str:
    from distributed import get_worker
    try:
        return get_worker().address
    except ValueError:  # called outside a Dask worker
        return "local"


# ---------------------------------------------------------------- on the client


@contextmanager
def _connect(client, workers):
    """A client for ``client`` (a Client, an address or None: a new LocalCluster) with workers joined."""
    from distributed import Client, LocalCluster
    if client is None:
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                          silence_logs=logging.CRITICAL) as cluster, Client(cluster) as local:
            yield local
        return
    if isinstance(client, str):
        try:
            remote = Client(client, timeout=CONNECT_TIMEOUT)
        except OSError as err:
            raise StudyError(f"scheduler: cannot connect to {client} ({err})") from None
        except ValueError as err:       # distributed's parser of addresses: no port, unknown scheme, ...
            raise StudyError(f"scheduler: {client!r} is not a scheduler address such as tcp://host:8786 "
                             f"({err})") from None
        with remote:
            _wait(remote, workers)
            yield remote
        return
    _wait(client, workers)
    yield client


def _wait(client, workers) -> None:
    try:
        client.wait_for_workers(workers or 1, timeout=CONNECT_TIMEOUT)
    except TimeoutError:
        have = len(client.scheduler_info(n_workers=-1)["workers"])
        raise StudyError(f"workers: {have} of {workers or 1} joined {client.scheduler.address} "
                         f"within {CONNECT_TIMEOUT} s") from None


def _run(client, cases: list[Case], out: Path, name: str, total: int, progress: bool, stop) -> dict[int, dict]:
    """Submit the cases grouped by mesh and material; save each as it completes, until ``stop``; rows by case index."""
    from distributed import as_completed

    token = uuid.uuid4().hex[:8]
    keys = {}
    futures = []
    for case in sorted(cases, key=lambda c: (c.group, c.index)):
        future = client.submit(run_case, case.scene, case.group, key=f"ngwear-{case.id}-{token}",
                               pure=False, retries=RETRIES)
        keys[future.key] = case
        futures.append(future)
    bar = progress_bar(total=total, initial=total - len(cases), desc=name, unit="case", disable=not progress)
    link = _dashboard(client)
    if link and progress:
        bar.write(f"Dask dashboard: {link}", file=sys.stderr)
    rows = {}
    finished = as_completed(futures)
    try:
        while not finished.is_empty() and not (stop is not None and stop.is_set()):
            if not finished.has_ready():
                sleep(POLL)
                continue
            future = next(finished)
            case = keys[future.key]
            try:
                row, files = future.result()
            except Exception as err:  # the task raised on every try, or its workers kept dying
                line = (str(err).strip().splitlines() or [""])[0]
                row, files = _row(status="crashed", error=line if isinstance(err, ChildError)
                                  else f"{type(err).__name__}: {line}"), {}
            rows[case.index] = _save_case(out, case, row, files)
            future.release()
            bar.update()
    finally:
        client.cancel([f for f in futures if not f.done()])
        bar.close()
    return rows


def _dashboard(client) -> str | None:
    """The dashboard's link when the scheduler serves one (it needs bokeh)."""
    services = client.scheduler_info(n_workers=0).get("services", {})
    return client.dashboard_link if "dashboard" in services else None


def _row(**values) -> dict:
    """A table row: NaN outputs and empty bookkeeping, updated with ``values``."""
    row = {name: float("nan") for name in OUTPUTS}
    row.update({"error": None, "warnings": None, "wall_time": 0.0, "worker": None, "factorised": False,
                **dict.fromkeys(PROVENANCE)})
    return row | values


def _save_case(out: Path, case: Case, row: dict, files: dict[str, bytes]) -> dict:
    """Write the case's result folder and, last, its ``row.json`` (not for crashed cases)."""
    row = dict(row, case_id=case.id)
    if row["status"] in FINISHED:
        folder = out / "cases" / case.id
        remove(folder)                              # a new folder of its own: nothing planted in it
        folder.mkdir(parents=True)
        for name, data in files.items():
            (folder / name).parent.mkdir(parents=True, exist_ok=True)
            (folder / name).write_bytes(data)
        with replacing(folder / "row.json") as tmp:
            tmp.write_text(json.dumps(row, indent=1))
    return row


def _finished(out: Path, cases) -> dict[int, dict]:
    """Rows of the cases finished by an earlier run in ``out`` (by case id)."""
    rows = {}
    for case in cases:
        path = out / "cases" / case.id / "row.json"
        if case.error is None and path.is_file():
            try:
                row = json.loads(path.read_text())
            except (OSError, ValueError):
                continue
            if row.get("status") in FINISHED:
                rows[case.index] = row
    return rows


def _table(study: Study, rows: dict[int, dict]) -> pd.DataFrame:
    import pandas as pd

    records = [{"case": c.index, **{key: c.params.get(key) for key in study.varied},
                **{name: rows[c.index].get(name) for name in (*study.outputs, *COLUMNS)}} for c in study.cases]
    table = pd.DataFrame.from_records(records)
    for key in study.varied:
        given = [v for v in table[key] if v is not None and not (isinstance(v, float) and v != v)]   # v != v: NaN
        if any(isinstance(v, str) for v in given) and not all(isinstance(v, str) for v in given):
            table[key] = [v if isinstance(v, str) or v not in given else json.dumps(v) for v in table[key]]
    return table


def _summary(study: Study, rows, ran, earlier, wall_time: float, out: Path) -> dict:
    statuses = [rows[c.index]["status"] for c in study.cases]
    return {
        "study": study.name, "cases": len(study.cases),
        **{status: statuses.count(status) for status in (*FINISHED, *UNFINISHED)},
        "skipped": len(earlier), "run": len(ran),
        "groups": len({c.group for c in study.cases if c.scene is not None}),
        "factorisations": sum(bool(row["factorised"]) for row in ran.values()),
        "workers": len({row["worker"] for row in ran.values() if row["worker"]}),
        "wall_time": round(wall_time, 3), "out": str(out),
    }


def _write(out: Path, study: Study, table: pd.DataFrame) -> None:
    from ..views.sweep_plots import against, heat_map

    with replacing(out / "results.parquet") as tmp:
        table.to_parquet(tmp, index=False)
    with replacing(out / "results.csv") as tmp:          # headed by the rule of every CSV: name [unit]
        headed(study.base, table, OUTPUT_QUANTITIES).to_csv(tmp, index=False)
    for key in study.varied:
        against(table, key, [k for k in study.varied if k != key], study.outputs, out / "plots" / f"{key}.png")
    if len(study.varied) == 2 and study.grid == study.varied:
        heat_map(table, study.varied, study.outputs, out / "plots" / "heat_map.png")
