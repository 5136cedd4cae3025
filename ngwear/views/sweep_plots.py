"""Plots of a study's table (matplotlib, no display needed).

``against``: one panel per output over the values of one varied key; cases that share the values of
the other varied keys are joined by a line (up to :data:`MAX_LINES` lines, points only beyond).
``heat_map``: one panel per output, a coloured cell per point of a two-key grid.  Only completed cases
are drawn; values that are not numbers (strings, vectors) are placed as categories.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from .plots import _save as save

MAX_LINES = 8
ANNOTATE_CELLS = 36


def against(table: pd.DataFrame, key: str, others: list[str], outputs, path) -> Path:
    """Each output against ``key``, one line per combination of the ``others``' values; writes a PNG."""
    done = (table["status"] == "completed").to_numpy()
    x, ticks = _axis(table[key])
    labels = np.array([", ".join(f"{k} = {_text(v)}" for k, v in zip(others, values))
                       for values in zip(*(table[k] for k in others))] if others else [""] * len(table))[done]
    lines = list(dict.fromkeys(labels)) if len(set(labels)) <= MAX_LINES else [None]
    fig, axes = _panels(len(outputs))
    for ax, name in zip(axes, outputs):
        y = table[name].to_numpy(dtype=float)[done]
        for line in lines:
            on = np.ones(len(y), bool) if line is None else labels == line
            xs, ys = x[done][on], y[on]
            order = np.argsort(xs, kind="stable")
            style = "o" if line is None else "o-"
            ax.plot(xs[order], ys[order], style, ms=4, label=line or None)
        ax.set(xlabel=key, title=name)
        if ticks is not None:
            ax.set_xticks(range(len(ticks)), ticks, rotation=30, fontsize=7)
        ax.grid(True, alpha=0.3)
    if others and lines != [None]:
        axes[0].legend(fontsize=7)
    fig.suptitle(f"outputs against {key} ({done.sum()} of {len(table)} cases completed)", fontsize=9)
    return save(fig, path, dpi=110)


def heat_map(table: pd.DataFrame, keys, outputs, path) -> Path:
    """Each output over the grid of two ``keys`` (x: the first, y: the second); writes a PNG."""
    a, b = keys
    xa, ta = _axis(table[a])
    xb, tb = _axis(table[b])
    cols, rows = np.unique(xa), np.unique(xb)
    fig, axes = _panels(len(outputs))
    for ax, name in zip(axes, outputs):
        grid = np.full((len(rows), len(cols)), np.nan)
        ok = (table["status"] == "completed").to_numpy()
        values = table[name].to_numpy(dtype=float)
        grid[np.searchsorted(rows, xb[ok]), np.searchsorted(cols, xa[ok])] = values[ok]
        image = ax.imshow(grid, origin="lower", aspect="auto", cmap="viridis")
        fig.colorbar(image, ax=ax, shrink=0.8)
        ax.set_xticks(range(len(cols)), ta or [_text(v) for v in cols], rotation=30, fontsize=7)
        ax.set_yticks(range(len(rows)), tb or [_text(v) for v in rows], fontsize=7)
        ax.set(xlabel=a, ylabel=b, title=name)
        if grid.size <= ANNOTATE_CELLS:
            for (j, i), v in np.ndenumerate(grid):
                light = not np.isnan(v) and image.norm(v) > 0.6  # viridis turns yellow: dark text there
                ax.text(i, j, "–" if np.isnan(v) else f"{v:.3g}", ha="center", va="center", fontsize=6,
                        color="black" if light else "white")
    return save(fig, path, dpi=110)


def _axis(column: pd.Series) -> tuple[np.ndarray, list[str] | None]:
    """Positions of a column's values: the numbers themselves, or category indices and their labels."""
    if pd.api.types.is_numeric_dtype(column) and not pd.api.types.is_bool_dtype(column):
        return column.to_numpy(dtype=float), None
    labels = [_text(v) for v in column]
    categories = list(dict.fromkeys(labels))
    return np.array([categories.index(label) for label in labels], dtype=float), categories


def _text(value) -> str:
    return f"{value:.4g}" if isinstance(value, float) else str(value)


def _panels(count: int):
    cols = min(3, count)
    rows = -(-count // cols)
    height = 3.2 * rows + 0.5
    fig = Figure(figsize=(4.4 * cols, height))  # fixed margins: a layout engine triples the drawing time
    fig.subplots_adjust(left=0.08, right=0.97, bottom=1.1 / height, top=1 - 0.75 / height, wspace=0.35,
                        hspace=1.3 / 3.2)
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    for ax in axes[count:]:
        ax.set_visible(False)
    return fig, axes

