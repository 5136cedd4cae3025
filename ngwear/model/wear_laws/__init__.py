"""Wear laws w' = α g(p), each declared once: the rate, its derivative in p and the stability slope.

A wear law writes the rate of wear at a contact point as a coefficient of the motion times a function of the pressure,

    w' = α g(p),      α = α(κ, μ, ‖v*‖) ≥ 0,      g(0) = 0,  g non-decreasing and convex on [0, ∞),

so that every wear integrator (:mod:`ngwear.numerics.wear`) writes its step as the nodal relation
w_j = a_j + c_j g(p(z_j − w_j)) and the solver sees p_j(z) = p(z − W(z)), dp_j/dz = p'/(1 + c g'(p) p').  The
update's stiffness, ∂w'/∂r = α g'(p) p'(r) ≤ α g'(p(g)) L_p on [0, g] (L_p the compliance's largest slope), is the
*stability slope* k α g'(p(g)) L_p that bounds the explicit scheme (:meth:`~.law.WearLaw.slope`).

A law is a :class:`~.law.WearLaw` in a module of this package, registered with :func:`~.law.register` (every
module here is imported, by name, after :class:`~.law.Archard`, the default): it declares its ``contact.wear_law``
name, its line of documentation, its keys of ``[contact]`` besides κ (:class:`~ngwear.model.keys.Constant`: the
scene's table, its schema and reference, and the rule that other laws' keys keep their defaults follow from them),
the unit of κ in an SI scene, and ``of``.  Laws: :class:`~.law.Archard` (the paper's, the default), :mod:`.power` and
:mod:`.energy`.
"""
from __future__ import annotations

import importlib
import pkgutil

from .law import WEAR_LAWS, Archard, WearLaw, constants, register, wear_law

for _module in sorted(m.name for m in pkgutil.iter_modules(__path__) if m.name != "law"):    # each law's module
    importlib.import_module(f"{__name__}.{_module}")

__all__ = ["WEAR_LAWS", "Archard", "WearLaw", "constants", "register", "wear_law"]
