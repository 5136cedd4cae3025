"""Shared fixtures: the paper's scene and a run of it (computed once per session)."""
from pathlib import Path

import pytest

import ngwear

ROOT = Path(__file__).resolve().parents[1]
PAPER = ROOT / "geometries" / "paper_strip.toml"


@pytest.fixture(scope="session")
def paper_scene():
    return ngwear.load_scene(PAPER)


@pytest.fixture(scope="session")
def paper_result(paper_scene):
    return ngwear.simulate(paper_scene, progress=False)
