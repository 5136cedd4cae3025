"""The README's examples: the Python one prints the numbers shown beside it, the first CLI one is right as printed."""
import re
import shlex

import numpy as np
import pytest
from conftest import ROOT

from ngwear import cli, load_scene

README = (ROOT / "README.md").read_text()
NUMBER = r"-?\d+\.\d+"


def test_readme_example_prints_what_it_says(monkeypatch, capsys):
    """Each ``print`` line ends in a comment ``…: <what it prints>``; the run prints those numbers (to their digits)."""
    block = re.search(r"```python\n(.*?)```", README, re.S).group(1)
    shown = [re.findall(NUMBER, line.split("#", 1)[1].rsplit(":", 1)[1]) for line in block.splitlines()
             if line.startswith("print(")]
    monkeypatch.chdir(ROOT)
    exec(compile(block, "README.md", "exec"), {})
    printed = [re.findall(NUMBER, line) for line in capsys.readouterr().out.splitlines()]
    assert len(printed) == len(shown) == 2 and [len(p) for p in printed] == [len(s) for s in shown] == [2, 2]
    for got, said in zip(printed, shown):
        assert np.allclose(np.array(got, float), np.array(said, float), rtol=0, atol=1.01e-4), (got, said)


def first_cli_example() -> list[str]:
    """The arguments of the README's first ``ngwear run`` line (its comment cut off)."""
    line = next(line for line in README.splitlines() if line.startswith("ngwear run "))
    return shlex.split(line.split("#")[0])[1:]


def test_readme_first_cli_example_prints_nothing_to_interpret(tmp_path, monkeypatch, capsys):
    """No warning, the wear within the layer, (H_S) as information (pictures aside: the same run)."""
    args = first_cli_example()
    monkeypatch.chdir(ROOT)
    out = args.index("--out")
    assert cli.main([*args[:out + 1], str(tmp_path / "paper"), *args[out + 2:], "--no-pictures"]) == 0
    captured = capsys.readouterr()
    summary = dict(line.split(None, 1) for line in captured.out.splitlines())
    assert "warning" not in summary and "warning" not in captured.err, captured
    assert float(summary["max_wear"]) <= float(summary["gap"])
    assert summary["uniqueness"].startswith("(H_S)") and "does not cover this scene" in summary["uniqueness"]


@pytest.mark.parametrize("key", ["time.steps", "mesh.maxh"])
def test_readme_settings_differ_from_the_shipped_scene(key):
    """``--set mesh.maxh=0.05`` on the paper strip (its own value) changed nothing: the example's values do."""
    args = first_cli_example()
    settings = dict(item.split("=") for item in args[args.index("--set") + 1:])
    section, name = key.split(".")
    assert float(settings[key]) != getattr(getattr(load_scene(ROOT / args[1]), section), name)
