"""The README's Python example runs verbatim and prints the numbers the README shows beside it."""
import re

import numpy as np
from conftest import ROOT

NUMBER = r"-?\d+\.\d+"


def test_readme_example_prints_what_it_says(monkeypatch, capsys):
    """Each ``print`` line ends in a comment ``…: <what it prints>``; the run prints those numbers (to their digits)."""
    text = (ROOT / "README.md").read_text()
    block = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    shown = [re.findall(NUMBER, line.split("#", 1)[1].rsplit(":", 1)[1]) for line in block.splitlines()
             if line.startswith("print(")]
    monkeypatch.chdir(ROOT)
    exec(compile(block, "README.md", "exec"), {})
    printed = [re.findall(NUMBER, line) for line in capsys.readouterr().out.splitlines()]
    assert len(printed) == len(shown) == 2 and [len(p) for p in printed] == [len(s) for s in shown] == [2, 2]
    for got, said in zip(printed, shown):
        assert np.allclose(np.array(got, float), np.array(said, float), rtol=0, atol=1.01e-4), (got, said)
