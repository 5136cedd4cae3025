"""The temperatures a scene's materials stand: ``material.max_temperature`` (per region) and ``foundation.max_temperature``.

A run checks the body's nodal temperature in each limited region, and the counterface's, after every heat step (one
maximum over the region's nodes): the first step that passes a limit and the highest temperature there are kept, and
the run ends with one warning per limit passed, naming its key, the step and the temperature.  Nothing is computed
for a scene without limits.
"""
from __future__ import annotations

import ngsolve as ngs
import numpy as np

from ..model.thermal import limited
from ..results.units import suffix

KEY = "max_temperature"
CHECKPOINT = "heat_limits"
"""A checkpoint's key of :attr:`Limits.seen`."""


class Limits:
    """The limited regions' nodes and the counterface, and what each has seen.

    Attributes
    ----------
    entries : list of (key, limit, nodes, what)
        ``nodes`` the P1 nodes (vertices) of the limited regions, None for the counterface; ``what`` names them.
    seen : numpy.ndarray, shape (len(entries), 5)
        Per entry: passed (0 or 1), the first step that passed it, its time, the highest temperature, its step.
    """

    def __init__(self, entries):
        self.entries = entries
        self.seen = np.zeros((len(entries), 5))
        self.seen[:, 3] = -np.finfo(float).max

    @classmethod
    def of(cls, scene, mesh: ngs.Mesh) -> Limits | None:
        """The limits of ``scene`` on the body's ``mesh`` (None without any)."""
        if not limited(scene):
            return None
        entries, material = [], scene.material
        tables = material.by_region(scene.geometry.regions)
        groups: dict[tuple[str, float], list[str]] = {}
        for region, table in tables.items():
            if table.max_temperature is not None:
                own = region in material.regions and material.regions[region].max_temperature is not None
                name = f"material.regions.{region}.{KEY}" if own else f"material.{KEY}"
                groups.setdefault((name, table.max_temperature), []).append(region)
        if groups:
            regions, names = _region_of_vertices(mesh), list(mesh.GetMaterials())
            for (name, limit), members in groups.items():
                nodes = regions[[names.index(member) for member in members]].any(axis=0)
                entries.append((name, limit, np.flatnonzero(nodes), "region " + ", ".join(members)))
        if scene.foundation.max_temperature is not None:
            entries.append((f"foundation.{KEY}", scene.foundation.max_temperature, None, "the counterface"))
        return cls(entries)

    def check(self, step: int, t: float, temperature: np.ndarray, foundation: float) -> None:
        """After a heat step: each entry's highest temperature now, against its limit."""
        for i, (_, limit, nodes, _) in enumerate(self.entries):
            now = foundation if nodes is None else float(temperature[nodes].max())
            if now > self.seen[i, 3]:
                self.seen[i, 3:] = now, step
            if now > limit and not self.seen[i, 0]:
                self.seen[i, :3] = 1, step, t

    def warnings(self, scene, times: np.ndarray) -> list[str]:
        """One line per limit passed: its key and value, the first step past it, the highest temperature and when."""
        degrees, seconds = suffix(scene, "temperature"), suffix(scene, "time")
        out = []
        for (name, limit, _, what), (passed, first, when, peak, at) in zip(self.entries, self.seen):
            if passed:
                out.append(f"{name} = {limit:g}{degrees}: {what} passed it at step {int(first)} (t = {when:.4g}"
                           f"{seconds}), up to {peak:.4g}{degrees} at step {int(at)} (t = {times[int(at)]:.4g}"
                           f"{seconds})")
        return out


def _region_of_vertices(mesh: ngs.Mesh) -> np.ndarray:
    """(regions, vertices) booleans: whether a vertex is one of a region's elements' (a vertex of two regions: both)."""
    out = np.zeros((len(mesh.GetMaterials()), mesh.nv), dtype=bool)
    for element in mesh.Elements(ngs.VOL):
        out[element.index, [v.nr for v in element.vertices]] = True
    return out
