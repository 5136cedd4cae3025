"""The registry of part kinds: what ``geometry.kind`` may be, each declared once.

A :class:`Kind` holds everything that depends on the kind: its dimension, default size and named
boundaries, the default clamping, the rules of its size and of the keys only it takes, its largest
dimension (the bound of ``mesh.maxh``) and how its shape is built.  The built-in kinds register in
:mod:`ngwear.model.shapes`, the part-file kinds in :mod:`ngwear.model.user_parts`; a new kind is one
:func:`register` call there.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from .keys import SceneError

KINDS: dict[str, Kind] = {}

FEATURE = 1e-3
"""The smallest feature of a built-in part relative to its largest dimension (thinner parts are refused:
OpenCASCADE and Netgen cannot build or mesh them)."""


@dataclass(frozen=True)
class Kind:
    """One geometry kind.

    ``dim``, ``size``, ``boundaries`` are None for the part-file kinds, whose file gives them.  ``check``
    takes the validated ``[geometry]`` table and raises a SceneError for a bad size or option; ``defaults``
    fills the kind's defaults into a raw ``[geometry]`` dict; ``extent`` is the part's largest dimension
    from its size; ``build`` makes the netgen.occ shape from ``(geometry, mesh)`` (None: a mesh file).
    ``options`` are the keys (dotted) that only this kind takes; ``files`` the suffixes of its part files;
    ``thickness`` the index in ``size`` of the height above Γ_C (where a ``geometry.backing`` is stacked); ``zone``
    the default ``mesh.contact_zone`` from the size (None: ``mesh.contact_maxh`` refines all of Γ_C).
    """

    name: str
    doc: str
    dim: int | None
    size: tuple[float, ...] | None = None
    size_doc: str = ""
    boundaries: tuple[str, ...] | None = None
    dirichlet: tuple[str, ...] = ()
    check: Callable | None = None
    defaults: Callable | None = None
    extent: Callable = max
    build: Callable | None = None
    options: tuple[str, ...] = ()
    files: tuple[str, ...] = ()
    thickness: int | None = None
    zone: Callable | None = None

    @property
    def from_file(self) -> bool:
        return bool(self.files)


def check_features(name: str, size, features: dict[str, float], extent: float) -> None:
    """Refuse a part whose thinnest feature is below FEATURE × its largest dimension (``name``: the key to blame)."""
    what, thinnest = min(features.items(), key=lambda item: item[1])
    if thinnest < FEATURE * extent:
        raise SceneError(f"{name}: the part's {what} ({thinnest:.3g}) must be at least {FEATURE:g} × its largest "
                         f"dimension {extent:.3g} (got {list(size) if isinstance(size, (list, tuple)) else size})")


def register(kind: Kind) -> Kind:
    """Add a kind to :data:`KINDS` (in the order of registration: the order of the documentation)."""
    KINDS[kind.name] = kind
    return kind


def ordered() -> list[Kind]:
    """The kinds as the documentation lists them: the built-in ones first, then the part files."""
    return sorted(KINDS.values(), key=lambda kind: kind.from_file)


def owners(option: str) -> tuple[str, ...]:
    """The kinds that take the dotted key ``option`` (empty: every kind takes it)."""
    return tuple(name for name, kind in KINDS.items() if option in kind.options)
