"""Braking programmes: the ``[programme]`` keys, their one-line errors and the compiled schedule.

The schedule of blocks of identical stops: the stops' start times (a block's stops the same problem shifted in
time, to the bit), T and the steps, the factors s_v, s_F on each stop's grid and by time, and their
piecewise-linear tables read by :func:`~ngwear.model.keys.piecewise_linear` as the scene's time tables are.
"""
import math
import os
import re

import numpy as np
import pytest
from conftest import PAPER

import ngwear
from ngwear.model.keys import piecewise_linear
from ngwear.model.programme import Schedule, exact_prefix_sums
from ngwear.model.scene import SceneError, parse_override

BLOCKS = [{"count": 3, "duration": 5.0, "speed": [1.0, 0.0], "dwell": 2.0},
          {"count": 2, "duration": 4.0, "load": [0.5, 1.5]},
          {"count": 4, "duration": 0.1, "speed": 0.5, "dwell": 0.7}]
CSV = """count,duration,speed,load,dwell
3,5.0,"[1.0, 0.0]",,2.0
2,4,,"[0.5, 1.5]",
4,0.1,0.5,1,0.7
"""


def strip(**programme):
    data = ngwear.load_scene(PAPER).to_dict()
    data.pop("time")
    data["output"].pop("every")
    return ngwear.Scene.from_dict({**data, "programme": programme})


@pytest.fixture(scope="module")
def scene():
    return strip(stops=BLOCKS, steps_per_stop=4)


def test_a_programme_sets_the_time_and_its_blocks_run_one_after_the_other(scene):
    s = Schedule.of(scene.programme)
    assert scene.time.T == s.end == 3 * 7 + 2 * 4 + 4 * 0.8
    assert scene.time.steps == 9 * 4 and scene.output.every == scene.time.T / 4
    assert s.count == 9 and list(s.first) == [0, 3, 5, 9]
    assert np.allclose(s.start, [0, 7, 14, 21, 25, 29, 29.8, 30.6, 31.4], rtol=1e-15)
    assert list(s.block) == [0, 0, 0, 1, 1, 2, 2, 2, 2] and s.last_of_block(3) == 4
    for b in range(3):    # the stops of a block are one problem shifted in time, to the bit
        stops = range(s.first[b], s.first[b + 1])
        grids, factors = [s.local(i) for i in stops], [np.array(s.factors(i)) for i in stops]
        assert all(np.array_equal(g, grids[0]) for g in grids) and all(np.array_equal(f, factors[0]) for f in factors)
        assert grids[0][0] == 0 and grids[0][-1] == BLOCKS[b]["duration"] and len(grids[0]) == 5
        assert np.allclose(s.times(stops[-1]), s.start[stops[-1]] + grids[0], rtol=1e-15)


def test_the_file_is_the_inline_programme(scene, tmp_path):
    (tmp_path / "blocks.csv").write_text(CSV)
    toml = PAPER.read_text().split("[time]")[0] + '[programme]\nfile = "blocks.csv"\nsteps_per_stop = 4\n'
    (tmp_path / "life.toml").write_text(toml)
    from_file = ngwear.load_scene(tmp_path / "life.toml")
    assert from_file.programme.blocks == scene.programme.blocks
    assert from_file.time == scene.time
    a, b = Schedule.of(from_file.programme), Schedule.of(scene.programme)
    assert all(np.array_equal(getattr(a, k), getattr(b, k)) for k in ("start", "speed", "load", "dwell", "block"))


def test_factors_on_a_stop_and_by_time(scene):
    s = Schedule.of(scene.programme)
    speed, load = s.factors(1)                       # a stop to rest: 1 → 0, linear, its end the stop's own
    assert np.allclose(speed, [1, 0.75, 0.5, 0.25, 0]) and np.all(load == 1)
    speed, load = s.factors(4)
    assert np.allclose(load, [0.5, 0.75, 1, 1.25, 1.5]) and np.all(speed == 1)
    # by time: the ramp inside a stop, 0 in a dwell, right-continuous at the jumps (a stop's end into its dwell)
    t = np.array([0.0, 2.5, 5.0, 6.0, 7.0, 21.0, 23.0, 25.0, 29.05, 29.5, 33.0])
    assert np.allclose(s.speed_at(t), [1, 0.5, 0, 0, 1, 1, 1, 1, 0.5, 0, 0])
    assert np.allclose(s.load_at(t), [1, 1, 0, 0, 1, 0.5, 1, 0.5, 1, 0, 0])


@pytest.mark.parametrize("which", ["speed", "load"])
def test_the_tables_are_the_factors_through_piecewise_linear(scene, which):
    s = Schedule.of(scene.programme)
    table = s.table(which)
    assert np.all(np.diff(table[:, 0]) >= 0) and table[0, 0] == 0 and table[-1, 0] == s.end
    rows = tuple(map(tuple, table))                   # the form of foundation.speed_table, loads.time_table
    t = np.concatenate([np.linspace(0, s.end, 1001), s.start, s.start + s.duration])
    at = s.speed_at(t) if which == "speed" else s.load_at(t)
    assert np.array_equal([piecewise_linear(rows, x) for x in t], at)


def test_keys_round_trip_and_set(scene):
    again = ngwear.Scene.from_dict(scene.to_dict())
    assert again == scene and "T" not in scene.to_dict()["time"]
    longer = scene.replace(**dict([parse_override('programme.stops=[{count = 2, duration = 3.0, dwell = 1.0}]')]),
                           **{"output.every": 2.0})
    assert (longer.time.T, longer.time.steps) == (8.0, 8)
    assert scene.replace(**{"programme.steps_per_stop": 10}).time.steps == 90
    plain = ngwear.load_scene(PAPER).replace(**{"output.every": 1.0, "programme.stops": [{"count": 2, "duration": 0.5}]})
    assert (plain.time.T, plain.time.steps) == (1.0, 40), "a programme given to a scene without one sets its time"


ERRORS = [
    ({"stops": [{"count": 0, "duration": 1.0}]}, "programme.stops: block 1: count", "[1, 1000000]"),
    ({"stops": [{"duration": 1.0}, {"count": 2}]}, "programme.stops: block 2: duration", "missing"),
    ({"stops": [{"duration": 1.0, "spead": 2}]}, "programme.stops: block 1: spead", "unknown"),
    ({"stops": [{"duration": 1.0, "speed": [1, 0, 2]}]}, "programme.stops: block 1: speed", "[start, end]"),
    ({"stops": [{"duration": -1.0}]}, "programme.stops: block 1: duration", "> 0"),
    ({"stops": [{"duration": 1.0, "dwell": -1.0}]}, "programme.stops: block 1: dwell", ">= 0"),
    ({"stops": []}, "programme.stops", "neither"),
    ({"stops": "fast"}, "programme.stops", "a list of blocks"),
    ({"stops": [{"duration": 1.0}], "steps_per_stop": 0}, "programme.steps_per_stop", "[1, 10000]"),
    ({"stops": [{"count": 60_000, "duration": 1.0}]}, "programme.steps_per_stop", "more than 1000000"),
    ({"stops": [{"duration": 1.0}], "jump_tolerance": 0.0}, "programme.jump_tolerance", "(0, 1)"),
    ({"stops": [{"duration": 1.0}], "jump": "yes"}, "programme.jump", "true or false"),
]


@pytest.mark.parametrize("programme, field, allowed", ERRORS, ids=[e[1].split(":")[-1].strip() + "-" + e[2]
                                                                   for e in ERRORS])
@pytest.mark.hostile
def test_bad_programmes_are_one_line(programme, field, allowed):
    with pytest.raises(SceneError) as err:
        strip(**programme)
    message = str(err.value)
    assert "\n" not in message and message.startswith(f"{field}:") and allowed in message, message


FILES = [
    ("count,speed\n3,1.0\n", "no column 'duration'"),
    ("count,duration,sped\n3,1.0,2\n", "unknown or repeated column 'sped'"),
    ("count,duration\n-3,1.0\n", "line 2: count: must be in [1, 1000000] (got -3)"),
    ("count,duration\n3,fast\n", "line 2: duration: must be a number or [start, end] (got 'fast')"),
    ("count,duration\n3\n", "line 2: has 1 cells, the header 2"),
    ("count,duration\n", "no blocks"),
]


@pytest.mark.parametrize("text, fragment", FILES, ids=[f[1].split()[-1] for f in FILES])
@pytest.mark.hostile
def test_bad_programme_files_are_one_line(tmp_path, text, fragment):
    (tmp_path / "p.csv").write_text(text)
    with pytest.raises(SceneError) as err:
        strip(file=str(tmp_path / "p.csv"))
    message = str(err.value)
    assert "\n" not in message and message.startswith("programme.file: ") and fragment in message, message


@pytest.mark.hostile
def test_a_missing_file_is_one_line(tmp_path):
    with pytest.raises(SceneError, match=r"^programme.file: cannot read .*none.csv"):
        strip(file=str(tmp_path / "none.csv"))


@pytest.mark.parametrize("path", ["/dev/zero", "/dev/urandom", "fifo"])
@pytest.mark.hostile
def test_a_programme_file_is_a_regular_file_or_refused_at_once(tmp_path, path):
    """A device is never read (it would read gigabytes before a MemoryError) and a FIFO never waited on."""
    if path == "fifo":
        path = tmp_path / "fifo"
        os.mkfifo(path)
    with pytest.raises(SceneError, match=rf"^programme.file: {re.escape(str(path))} is not a regular file \(a CSV "
                                         r"file of the blocks\)$"):
        strip(file=str(path))


@pytest.mark.hostile
def test_a_file_larger_than_the_bound_is_read_no_further(tmp_path, monkeypatch):
    from ngwear.model import programme_csv
    monkeypatch.setattr(programme_csv, "MAX_BYTES", 64)
    (tmp_path / "p.csv").write_text(CSV + "5,1.0,1.0,1.0,0.0\n" * 10)
    with pytest.raises(SceneError, match=r"^programme.file: p.csv is larger than 0 MB$"):
        strip(file=str(tmp_path / "p.csv"))


@pytest.mark.hostile
def test_a_spreadsheets_utf8_csv_with_its_byte_order_mark_is_read(scene, tmp_path):
    (tmp_path / "p.csv").write_bytes(b"\xef\xbb\xbf" + CSV.encode())
    assert strip(file=str(tmp_path / "p.csv"), steps_per_stop=4).programme.blocks == scene.programme.blocks


def test_the_start_times_are_the_exactly_rounded_sums_of_the_periods_before():
    """T_b = fsum of the earlier blocks' n (d + D), in one pass (the set-up is linear in the blocks)."""
    rng = np.random.default_rng(7)
    periods = list(rng.uniform(0.01, 100.0, 500) * 10.0 ** rng.integers(-8, 8, 500))
    assert np.array_equal(exact_prefix_sums(periods), [math.fsum(periods[:i]) for i in range(len(periods))])


def test_a_programme_file_is_read_once_per_scene(tmp_path, monkeypatch):
    from ngwear.model import programme
    (tmp_path / "p.csv").write_text(CSV)
    reads, read = [], programme.read_rows
    monkeypatch.setattr(programme, "read_rows", lambda path: reads.append(path) or read(path))
    loaded = strip(file=str(tmp_path / "p.csv"), steps_per_stop=4)
    Schedule.of(loaded.programme), loaded.programme.blocks, loaded.programme.count
    assert len(reads) <= 1          # none when the same unchanged file was read before


@pytest.mark.parametrize("loads, factor", [({"plate": {"boundary": "top", "force": [0.0, -1e300]}}, None),
                                           ({"traction": {"top": [0.0, -1e145]}}, 1e10)])
@pytest.mark.hostile
def test_loads_that_overflow_are_refused_before_the_run(loads, factor):
    data = ngwear.load_scene(PAPER).to_dict()
    data.pop("time")
    data["output"].pop("every")
    data["loads"] = loads
    if loads.get("plate"):
        data["geometry"]["dirichlet"] = []
    blocks = [{"count": 2, "duration": 1.0, "load": factor if factor else 1.0}]
    with pytest.raises(SceneError, match=r"^loads\.(plate\.force|traction\.top): its largest component( times the "
                                         r"largest load factor \(the programme, 1e\+10\))? is 1e\+\d+; must be <= "
                                         r"1e\+150"):
        ngwear.Scene.from_dict({**data, "programme": {"stops": blocks}})


@pytest.mark.parametrize("changes, field", [
    ({"time": {"T": 3.0}}, "time.T"),
    ({"time": {"steps": 30}}, "time.steps"),
    ({"time": {"adaptive": True}}, "time.adaptive"),
    ({"foundation": {"velocity": [1.0, 0.0], "speed_table": [[0.0, 1.0], [100.0, 1.0]]}}, "foundation.speed_table"),
    ({"loads": {"traction": {"top": [0.0, -0.1]}, "time_table": [[0.0, 1.0], [100.0, 1.0]]}}, "loads.time_table"),
    ({"geometry": {"kind": "strip", "dirichlet": []}, "loads": {"plate": {"boundary": "top", "force": [0.0, -0.1]}},
      "programme": {"stops": [{"duration": 1.0, "load": [1.0, -0.5]}]}}, "programme.stops: block 1: load"),
])
@pytest.mark.hostile
def test_what_a_programme_replaces_is_refused_with_it(changes, field):
    data = ngwear.load_scene(PAPER).to_dict()
    data.pop("time")
    data["output"].pop("every")
    data = {**data, "programme": {"stops": [{"duration": 1.0}]}, **changes}
    with pytest.raises(SceneError) as err:
        ngwear.Scene.from_dict(data)
    assert str(err.value).startswith(f"{field}:") and "\n" not in str(err.value), str(err.value)


@pytest.mark.parametrize("key, value, fragment", [("wear.geometry", "worn", "layer, surface"),
                                                  ("wear.update", 0.0, "(0, 0.5]"), ("wear.update", 0.6, "(0, 0.5]"),
                                                  ("wear.limit", -1.0, "> 0")])
@pytest.mark.hostile
def test_life_keys_are_validated(key, value, fragment):
    with pytest.raises(SceneError) as err:
        ngwear.load_scene(PAPER).replace(**{key: value})
    assert str(err.value).startswith(f"{key}:") and fragment in str(err.value), str(err.value)


def test_life_keys_default_to_the_paper_model():
    wear = ngwear.load_scene(PAPER).wear
    assert (wear.geometry, wear.update, wear.limit) == ("layer", 0.25, None)
