"""Latency of the explorer app measured in the browser: first picture ≤ 5 s, slider → picture ≤ 0.5 s.

``ngwear explore geometries/paper_strip.toml`` (the explorer's default: the paper's resolution,
maxh 0.05 and 100 steps, an 800 × 330 picture) is opened in Debian's Chromium driven by Playwright,
with the helpers of the browser tests (``tests/browser.py``).  Times are taken in the page
(``performance.now()``): the first picture is the ``load`` event of the picture's ``<img>`` after
navigation start; a slider change is the ``keydown`` on the slider's handle to the ``load`` of the
new picture ("new picture", the target) and of the new plots ("all shown").  The mesh is cached
(one warm-up page first).

* ``first picture, first page``: the server is started and the page opened as soon as it prints its
  URL (once its first kernel is preheated); one per server start, ``--runs`` starts; the time from
  starting ``ngwear explore`` to its URL is a row too;
* ``first picture, later page``: a new page once the server's next kernel is preheated (the usual
  case: Voilà keeps one kernel preheated); ``--runs`` pages;
* one row per slider and for the time slider: ``--reps`` key presses alternating → and ← (← and → for time).

Medians; this machine has 2 cores and other work on it, so the spread is printed too.

    .venv/bin/python benchmarks/explore_browser.py [--quick] [--runs N] [--reps N]
"""
from __future__ import annotations

import statistics
import subprocess
import sys
import time

import common as C

sys.path.insert(0, str(C.ROOT / "tests"))
from browser import CHROMIUM, app_url, chromium, free_port, server  # noqa: E402  (the browser tests' helpers)

TARGET_FIRST, TARGET_SLIDER = 5.0, 0.5
SLIDERS = ("load", "speed", "wear", "friction", "gap", "steps")
TIMES = """
window.__loads = {}; window.__keys = [];
document.addEventListener('load', (e) => {
    const cls = e.target.classList;
    if (cls && (cls.contains('ngwear-picture') || cls.contains('ngwear-plots'))) {
        const key = cls.contains('ngwear-picture') ? 'picture' : 'plots';
        (window.__loads[key] = window.__loads[key] || []).push(performance.now());
    }
}, true);
document.addEventListener('keydown', () => window.__keys.push(performance.now()), true);
"""


def explore(port: int, log):
    argv = [sys.executable, "-m", "ngwear.cli", "explore", str(C.PAPER), "--port", str(port), "--kernel-timeout", "5",
            "--out", str(C.RESULTS / "explore_browser_saves")]
    return server(argv, port, log, ready="?token=")


def open_page(browser, url: str):
    """A new page on the app at ``url`` (with its token); seconds from navigation start to the first picture."""
    page = browser.new_page(viewport={"width": 1280, "height": 1100})
    page.add_init_script(TIMES)
    page.goto(url, wait_until="commit")
    page.wait_for_function("() => (window.__loads.picture || []).length > 0", timeout=120_000)
    return page, page.evaluate("() => window.__loads.picture[0]") / 1000


def slider_latency(page, name: str, key: str) -> tuple[float, float]:
    """Seconds from a key press on a slider to its new picture, and to its new plots."""
    counts = page.evaluate("() => [window.__loads.picture.length, (window.__loads.plots || []).length]")
    selector = ".ngwear-time .noUi-handle" if name == "time" else f".ngwear-slider-{name} .noUi-handle"
    page.focus(selector)
    page.keyboard.press(key)
    page.wait_for_function(
        """([p, q]) => window.__loads.picture.length > p && (window.__loads.plots || []).length > q &&
                       document.querySelector('.ngwear-progress').textContent.includes('ready')""",
        arg=counts, timeout=60_000)
    key_time, picture, plots = page.evaluate(
        "([p, q]) => [window.__keys[window.__keys.length - 1], window.__loads.picture[p], window.__loads.plots[q]]",
        counts)
    return (picture - key_time) / 1000, (plots - key_time) / 1000


def spread(values) -> str:
    return f"{min(values):.2f}-{max(values):.2f}" if values else "-"


def main():
    parser = C.parser(__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5, help="server starts and pages for the first picture")
    parser.set_defaults(reps=6)
    args = parser.parse_args()
    if args.quick:
        args.runs, args.reps = 2, 2
    logs = C.RESULTS / "explore_browser_logs"
    logs.mkdir(parents=True, exist_ok=True)
    startup, cold, warm, presses = [], [], [], {name: [] for name in (*SLIDERS, "time")}
    with chromium() as browser:
        for run in range(args.runs + 1):  # the first only caches the mesh
            port, start = free_port(), time.perf_counter()
            with explore(port, logs / f"server{run}.log"):
                if run > 0:
                    startup.append(time.perf_counter() - start)
                url = app_url(logs / f"server{run}.log")
                page, first = open_page(browser, url)
                if run > 0:
                    cold.append(first)
                if run < args.runs:
                    page.close()
                    continue
                for name in presses:
                    keys = ("ArrowLeft", "ArrowRight") if name == "time" else ("ArrowRight", "ArrowLeft")  # time: at its end
                    for i in range(args.reps):
                        presses[name].append(slider_latency(page, name, keys[i % 2]))
                page.close()
                for _ in range(args.runs):
                    time.sleep(12)  # longer than the next kernel's preheating; the closed page's kernel ends
                    page, first = open_page(browser, url)
                    warm.append(first)
                    page.close()
    rows = [{"measure": "ngwear explore started → URL printed", "n": len(startup),
             "median_s": statistics.median(startup), "range_s": spread(startup), "target": "-"},
            {"measure": "first picture, first page", "n": len(cold),
             "median_s": statistics.median(cold), "range_s": spread(cold),
             "target": C.verdict(statistics.median(cold) <= TARGET_FIRST)},
            {"measure": "first picture, later page (kernel preheated)", "n": len(warm),
             "median_s": statistics.median(warm), "range_s": spread(warm),
             "target": C.verdict(statistics.median(warm) <= TARGET_FIRST)}]
    for name, times in presses.items():
        picture = [t[0] for t in times]
        rows.append({"measure": f"{name} slider → new picture" if name != "time" else "time slider → new picture",
                     "n": len(times), "median_s": statistics.median(picture), "range_s": spread(picture),
                     "all_shown_s": statistics.median([max(t) for t in times]),
                     "target": C.verdict(statistics.median(picture) <= TARGET_SLIDER)})
    header = C.machine_lines(args) + [
        "ngwear explore geometries/paper_strip.toml (maxh 0.05, 100 steps, picture 800 x 330) in Chromium "
        f"{chromium_version()}; times in the page (performance.now); medians [s]; targets: first picture <= "
        f"{TARGET_FIRST:g} s, slider -> new picture <= {TARGET_SLIDER:g} s"]
    columns = [("measure", "measure", None), ("n", "n", "d"), ("median_s", "median", ".2f"), ("range_s", "range", None),
               ("all_shown_s", "+ plots", ".2f"), ("target", "target", None)]
    C.finish("explore_browser", "explorer app latency in the browser [s]", header, rows, columns, quick=args.quick)


def chromium_version() -> str:
    out = subprocess.run([str(CHROMIUM), "--version"], capture_output=True, text=True).stdout.split()
    return next((w for w in out if w[:1].isdigit()), "?")


if __name__ == "__main__":
    main()
