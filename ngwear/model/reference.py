"""The scene reference: one Markdown row per declared key (what ``docs/reference/scene.md`` shows), from the declarations."""
from __future__ import annotations

from typing import get_args

from pydantic import BaseModel
from pydantic.fields import FieldInfo

from .messages import allowed, base_type, plain
from .sections import declared_keys


def reference_table() -> str:
    """The scene reference: one Markdown row per key, from the declarations; a list of tables, then its entries' keys."""
    rows = ["| key | meaning | default | allowed |", "|---|---|---|---|"]
    for name, info in declared_keys():
        rows.append(_reference_row(name, info))
        entry = get_args(base_type(info.annotation))[:1]
        if entry and isinstance(entry[0], type) and issubclass(entry[0], BaseModel):
            rows += [_reference_row(f"{name}[].{key}", field) for key, field in entry[0].model_fields.items()]
    return "\n".join(rows)


def _reference_row(name: str, info: FieldInfo) -> str:
    extra = info.json_schema_extra or {}
    return markdown_row((f"`{name}`", info.description, extra.get("shown", plain(info.default)),
                         extra.get("allowed") or allowed(info)))


def markdown_row(cells) -> str:
    """A Markdown table row; a ``|`` in a cell (``|φ|``, ``|F_t|``) escaped, else the row splits there."""
    return "| " + " | ".join(str(cell).replace("|", "\\|") for cell in cells) + " |"
