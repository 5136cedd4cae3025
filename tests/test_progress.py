"""Progress bars and lines count in whole numbers with thousands separators and say how long the rest takes."""
import io
import logging
import re

from tqdm import tqdm

from ngwear.runs import progress


class Clock:
    """A stand-in for the time module: ``monotonic`` gives the times in turn, then stays at the last."""

    def __init__(self, *times):
        self.times = list(times)

    def monotonic(self) -> float:
        return self.times.pop(0) if len(self.times) > 1 else self.times[0]


def test_lines_count_whole_numbers_and_tell_the_time_left(caplog, monkeypatch):
    monkeypatch.setattr(progress, "time", Clock(100.0, 100.0, 112.0))     # the start, then 12 s later
    with caplog.at_level(logging.INFO, logger="ngwear.progress"):
        lines = progress.Lines(total=60_000, desc="long", unit="step", initial=0)
        lines.update(42_000)
    first, second = caplog.messages
    assert first == "long: 0 of 60,000 steps [0.0 s]"
    assert second == "long: 42,000 of 60,000 steps [12.0 s, about 5.1 s left]"    # 12 s × 18,000 / 42,000


def test_a_resumed_count_takes_its_rate_from_where_it_started(caplog, monkeypatch):
    monkeypatch.setattr(progress, "time", Clock(0.0, 300.0))
    with caplog.at_level(logging.INFO, logger="ngwear.progress"):
        lines = progress.Lines(total=2_000_000, desc="r", unit="step", initial=1_000_000, disable=True)
        lines.disable = False
        lines.update(500_000)
    assert caplog.messages == ["r: 1,500,000 of 2,000,000 steps [5.0 min, about 5.0 min left]"]


def test_numbers_and_durations():
    assert [progress.number(v) for v in (0, 7, 42_000, 6e4, 0.4213, 1.0)] == ["0", "7", "42,000", "60,000", "0.4213",
                                                                              "1"]
    assert [progress.duration(s) for s in (5.06, 150, 5400, 9000)] == ["5.1 s", "2.5 min", "90.0 min", "2.5 h"]


def test_the_terminal_bar_counts_with_separators_and_an_eta():
    out = io.StringIO()
    with tqdm(total=60_000, initial=42_000, desc="long", unit="step", bar_format=progress.COUNTED, file=out,
              mininterval=0) as bar:
        bar.update(1_000)
    shown = out.getvalue().replace("\r", "\n").strip().splitlines()[-1]
    assert re.search(r"long: +72%\|.*\| 43,000 of 60,000 steps \[\d\d:\d\d<\d\d:\d\d, ", shown), shown
