"""Shared helpers of the ngwear benchmarks ("Fast: solve only what changes").

Every script in this folder:

* runs the paper scene (``geometries/paper_strip.toml``) at nominal sizes of ~2k, 10k, 50k, 200k
  *free* DOFs (``disc.body.free.sum()``), P1 and P2, with ``mesh.maxh`` chosen from a calibrated
  ``free ≈ C / maxh²`` law (the actual free DOF count is always reported);
* caches its meshes in ``benchmarks/results/mesh_cache`` (``$NGWEAR_CACHE``, unless already set),
  so the user's ``~/.cache/ngwear`` is neither read nor polluted;
* limits the BLAS thread pools (numpy's, scipy's and NGSolve's OpenBLAS) to ``--blas-threads``
  (default 1, the faster setting for the small dense per-step algebra on this 2-core machine;
  ``steps.py`` measures 1 vs 2);
* times with ``time.perf_counter``, takes medians over repetitions that are *interleaved* between
  the things compared (so a burst of load from other processes hits both), and reports ratios
  measured in the same run;
* prints a table headed by the machine description and writes ``results/NAME.csv`` (with the
  header as ``#`` comment lines: ``pandas.read_csv(path, comment="#")``) and ``results/NAME.png``
  (``NAME_quick.*`` with ``--quick``, so a check run does not overwrite the full results).
"""
from __future__ import annotations

import argparse
import csv
import gc
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import time
from contextlib import contextmanager, nullcontext
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
RESULTS = HERE / "results"
PAPER = ROOT / "geometries" / "paper_strip.toml"

os.environ.setdefault("NGWEAR_CACHE", str(RESULTS / "mesh_cache"))
if Path(os.environ["NGWEAR_CACHE"]) == RESULTS / "mesh_cache":
    (RESULTS / "mesh_cache").mkdir(parents=True, exist_ok=True)
    (RESULTS / "mesh_cache" / ".gitignore").write_text("*\n")

import matplotlib  # noqa: E402
import numpy as np  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402,F401
import ngsolve as ngs  # noqa: E402

import ngwear  # noqa: E402
from ngwear.model.materials import region_laws  # noqa: E402
from ngwear.model.scene_mesh import build_mesh  # noqa: E402
from ngwear.numerics.discrete import Discretization  # noqa: E402
from ngwear.numerics.forms import displacement_space, elastic_form, load_form  # noqa: E402

try:
    from threadpoolctl import threadpool_info, threadpool_limits
except ImportError:  # pragma: no cover - threadpoolctl is optional
    threadpool_info = threadpool_limits = None

perf = time.perf_counter

# free P1/P2 DOFs of the paper strip ≈ C / maxh² (fitted on maxh = 0.04, 0.018 and 0.08, 0.036)
DOF_CONSTANT = {1: 7.07, 2: 28.4}
SIZES = {"2k": 2_000, "10k": 10_000, "50k": 50_000, "200k": 200_000}
QUICK_SIZES = ("2k",)


# ---- command line and machine ------------------------------------------------------------
def parser(description: str) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description=description)
    p.add_argument("--quick", action="store_true", help="small sizes only (< 1 minute), for CI/review")
    p.add_argument("--reps", type=int, default=3, help="repetitions per measurement (median)")
    p.add_argument("--blas-threads", type=int, default=1, help="BLAS threads (threadpoolctl)")
    p.add_argument("--sizes", default=None, help="comma-separated nominal sizes (2k,10k,50k,200k)")
    p.add_argument("--orders", default="1,2", help="comma-separated polynomial orders")
    return p


def selected_sizes(args, default=tuple(SIZES)) -> list[str]:
    if args.sizes:
        return [s.strip() for s in args.sizes.split(",")]
    return list(QUICK_SIZES) if args.quick else list(default)


def selected_orders(args) -> list[int]:
    return [int(o) for o in args.orders.split(",")]


def blas_limit(threads: int | None):
    """Context limiting every BLAS pool (numpy, scipy, NGSolve's OpenBLAS) to ``threads``."""
    if threadpool_limits is None or threads is None:
        return nullcontext()
    return threadpool_limits(limits=threads, user_api="blas")


def cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def machine_lines(args=None) -> list[str]:
    """Machine description for table headers and CSV comments."""
    import scipy
    cores = os.cpu_count()
    try:
        affinity = len(os.sched_getaffinity(0))
    except AttributeError:
        affinity = cores
    lines = [f"machine: {cpu_model()}, {cores} logical cores ({affinity} usable), "
             f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}",
             f"python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}, "
             f"ngsolve {ngs.__version__}"]
    if threadpool_info is not None:
        pools = ", ".join(f"{p['internal_api']} {p.get('version')} ({Path(p['filepath']).parent.name}): "
                          f"{p['num_threads']} threads" for p in threadpool_info() if p["user_api"] == "blas")
        lines.append(f"BLAS pools (default): {pools}")
    else:
        lines.append("BLAS pools: threadpoolctl not installed (threads not controlled)")
    lines.append(f"ngwear: {git_state()}")
    if args is not None:
        lines.append(f"benchmark BLAS threads: {args.blas_threads}; repetitions: {args.reps} (median); "
                     f"quick: {args.quick}")
    return lines


def git_state() -> str:
    """Commit of the work tree and the ngwear/ files modified in it (others edit it concurrently)."""
    import subprocess
    try:
        sha = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                             text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--", "ngwear"], cwd=ROOT,
                               capture_output=True, text=True, check=True).stdout.split("\n")
        dirty = [line[3:] for line in dirty if line.strip()]
    except (OSError, subprocess.CalledProcessError):
        return "git state unknown"
    return f"git {sha}" + (f" + uncommitted changes in {', '.join(dirty)}" if dirty else " (clean)")


# ---- scenes and meshes ---------------------------------------------------------------------
def paper_scene():
    return ngwear.load_scene(PAPER)


LIFE = ROOT / "geometries" / "brake_pad_life.toml"
LIFE_SIZES = (None, 0.002, 0.00122)
"""``mesh.maxh`` of the life pad's shipped mesh (None), 46k and 202k DOFs."""


def life_pad(maxh: float | None) -> tuple:
    """``geometries/brake_pad_life.toml`` at ``mesh.maxh`` (None: the shipped mesh) and its discretization."""
    scene = ngwear.load_scene(LIFE)
    scene = scene.replace(**{"mesh.maxh": maxh}) if maxh else scene
    return scene, Discretization(scene)


def maxh_for(free_dofs: int, order: int) -> float:
    return round(math.sqrt(DOF_CONSTANT[order] / free_dofs), 5)


def scene_for(size: str, order: int, **overrides):
    """The paper scene at a nominal size/order (plus dotted overrides)."""
    settings = {"mesh.maxh": maxh_for(SIZES[size], order), "mesh.order": order}
    settings.update(overrides)
    return paper_scene().replace(**settings)


def mesh_for(scene):
    """Cached Netgen mesh of the scene (built on first use, see scene_mesh.build_mesh)."""
    return build_mesh(scene, use_cache=True)


def free_dofs(disc: Discretization) -> int:
    return int(disc.body.free.sum())


# ---- timing ---------------------------------------------------------------------------------
def median(xs):
    xs = [x for x in xs if x is not None and not (isinstance(x, float) and math.isnan(x))]
    return statistics.median(xs) if xs else float("nan")


def timed(fn, *a, **kw):
    """(seconds, return value) of one call (garbage collected before, collector off during)."""
    gc.collect()
    enabled = gc.isenabled()
    gc.disable()
    try:
        t = perf()
        out = fn(*a, **kw)
        return perf() - t, out
    finally:
        if enabled:
            gc.enable()


def interleaved(funcs: dict, reps: int) -> dict:
    """Run each function ``reps`` times in round-robin; {name: [seconds, ...]} (and last outputs)."""
    times = {k: [] for k in funcs}
    outs = {}
    for _ in range(reps):
        for name, fn in funcs.items():
            dt, outs[name] = timed(fn)
            times[name].append(dt)
    return times, outs


@contextmanager
def stopwatch(acc: dict, key: str):
    """Accumulate the wall time of a block into ``acc[key]``."""
    t = perf()
    try:
        yield
    finally:
        acc[key] = acc.get(key, 0.0) + perf() - t


# ---- the two things every script compares -----------------------------------------------------
def elastic_reference(scene, mesh, *, taskmanager: bool = False) -> dict:
    """One linear-elastic solve with NGSolve: assemble K and f, sparsecholesky, one solve.

    Returns the times of the parts and ``total``; the space is built outside the timing.
    """
    fes = displacement_space(mesh, scene)
    ctx = ngs.TaskManager() if taskmanager else nullcontext()
    with ctx:
        gc.collect()
        t0 = perf()
        a = elastic_form(fes, region_laws(scene))
        a.Assemble()
        f = load_form(fes, scene)
        f.Assemble()
        t1 = perf()
        inv = a.mat.Inverse(fes.FreeDofs(), inverse="sparsecholesky")
        t2 = perf()
        u = ngs.GridFunction(fes)
        u.vec.data = inv * f.vec
        t3 = perf()
        # a second back-substitution with the same factor (the marginal cost of one more solve)
        v = f.vec.CreateVector()
        v.data = inv * f.vec
        t4 = perf()
    return {"assemble": t1 - t0, "factorise": t2 - t1, "solve": t3 - t2, "total": t3 - t0,
            "backsub": t4 - t3, "ndof": fes.ndof}


def fast_run(scene, mesh, **simulate_kw):
    """Ngwear's fast path from a given mesh: Discretization + simulate (no output)."""
    disc = Discretization(scene, mesh)
    return ngwear.simulate(scene, discretization=disc, progress=False, **simulate_kw)


def newton_iterations(result) -> int:
    return int(sum(r.iterations for r in result.newton))


# ---- output ---------------------------------------------------------------------------------
def _fmt(v, spec):
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "-"
    if spec and not isinstance(v, str):
        return format(v, spec)
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def print_table(title: str, header_lines: list[str], rows: list[dict], columns: list[tuple]):
    """Print rows as an aligned table; ``columns`` = [(key, label, format spec or None)]."""
    cells = [[label for _, label, _ in columns]]
    cells += [[_fmt(r.get(k), spec) for k, _, spec in columns] for r in rows]
    widths = [max(len(c[i]) for c in cells) for i in range(len(columns))]
    bar = "-" * (sum(widths) + 2 * (len(widths) - 1))
    print()
    print(f"== {title} ==")
    for line in header_lines:
        print(f"   {line}")
    print(bar)
    for i, row in enumerate(cells):
        print("  ".join(c.ljust(w) if j == 0 and isinstance(rows[0].get(columns[0][0]) if rows else None, str)
                        else c.rjust(w) for j, (c, w) in enumerate(zip(row, widths))))
        if i == 0:
            print(bar)
    print(bar)
    sys.stdout.flush()


def write_csv(name: str, header_lines: list[str], rows: list[dict]) -> Path:
    RESULTS.mkdir(parents=True, exist_ok=True)
    path = RESULTS / f"{name}.csv"
    keys = []
    for r in rows:
        keys += [k for k in r if k not in keys]
    with path.open("w", newline="") as fh:
        for line in header_lines:
            fh.write(f"# {line}\n")
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in keys})
    return path


def new_figure(ncols: int = 1, width: float = 6.0):
    fig, axes = plt.subplots(1, ncols, figsize=(width * ncols, 4.5), squeeze=False)
    return fig, axes[0]


def save_figure(fig, name: str, header_lines: list[str]) -> Path:
    RESULTS.mkdir(parents=True, exist_ok=True)
    path = RESULTS / f"{name}.png"
    fig.suptitle(header_lines[0].removeprefix("machine: ") if header_lines else name, fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def finish(name: str, title: str, header_lines: list[str], rows: list[dict], columns, fig=None,
           quick: bool = False):
    """Print the table, write results/NAME.csv and .png (NAME_quick.* for --quick runs)."""
    name = f"{name}_quick" if quick else name
    print_table(title, header_lines, rows, columns)
    csv_path = write_csv(name, header_lines, rows)
    out = [str(csv_path.relative_to(ROOT))]
    if fig is not None:
        out.append(str(save_figure(fig, name, header_lines).relative_to(ROOT)))
    print("wrote " + ", ".join(out))


def in_subprocess(script, job: dict, blas_threads: int | None) -> dict:
    """Run ``script --job JOB`` in a fresh interpreter (its own peak memory); the JSON it prints last."""
    cmd = [sys.executable, str(script), "--job", json.dumps(job)]
    if blas_threads:
        cmd += ["--blas-threads", str(blas_threads)]
    out = subprocess.run(cmd, capture_output=True, text=True, cwd=HERE)
    lines = [line for line in out.stdout.splitlines() if line.startswith("{")]
    if out.returncode or not lines:
        raise RuntimeError(f"{job}: failed\n{out.stderr[-3000:]}")
    return json.loads(lines[-1])


def verdict(ok: bool | None) -> str:
    return "-" if ok is None else ("MET" if ok else "NOT MET")
