"""The train file's JSON Schema (draft 2020-12), generated from the declarative schema.

:func:`train_schema` walks :data:`gearcheck.train.schema.TRAIN` (its :class:`~gearcheck.train.schema.Table`,
``TableList``, ``ListOf``, ``Number``, ``Integer``, ``Flag``, ``Text``) into JSON Schema, so an editor or a CI
step can check a train file (parsed from TOML) before gearcheck reads it.  Keys keep the file's names and units
(``module_mm``), units are stated in the descriptions, bounds and defaults are the file's, a closed table has
``additionalProperties: false``.  Tables the module names (``SUPPORT``, ``MESH``, ...) are shared
``$defs``.  The two open tables are written as their plug-ins check them: a mesh ``stiffness`` table against
the parameter table of its model (:data:`gearcheck.train.mesh_stiffness.MODELS`), ``[tolerances]`` as
:func:`gearcheck.train.spec.flat_tolerances` reads it.

What the schema cannot say, the loader still checks: the geometry, the assembly and power flow, member
references, a list that must increase, NaN; and JSON Schema counts 3.0 as an integer where TOML does not.
``python -m gearcheck.compare.presentation.schemas DIR`` writes this schema with the report's.
"""

from __future__ import annotations

import json

from gearcheck.train import schema
from gearcheck.train.mesh_stiffness import MODELS
from gearcheck.train.spec import MAX_TOLERANCE

DRAFT = "https://json-schema.org/draft/2020-12/schema"


def schema_text(document: dict) -> str:
    """A schema as the shipped files hold it: indented JSON, UTF-8 characters as they are, a final newline."""
    return json.dumps(document, indent=2, ensure_ascii=False) + "\n"


def _description(spec) -> str:
    doc = spec.doc or ""
    unit = spec.unit if spec.unit not in ("", "-") else ""
    if isinstance(spec, schema.ListOf) and spec.increasing:
        doc += "; strictly increasing"
    return f"{doc} [{unit}]" if unit else doc


def _default(spec):
    """The JSON default of a field, or None when it has none (required, optional without default, a table)."""
    if spec.default is schema.REQUIRED or spec.default is None or isinstance(spec, schema.Table):
        return None
    return list(spec.default) if isinstance(spec.default, tuple) else spec.default


class _Walker:
    """Turns declarative fields into JSON Schema, the module's named tables into ``$defs``."""

    def __init__(self):
        self.names = {id(value): name.lower() for name, value in vars(schema).items()
                      if isinstance(value, schema.Table) and value is not schema.TRAIN}
        self.open = {id(schema.STIFFNESS): self._stiffness, id(schema.TRAIN.fields["tolerances"]): self._tolerances}
        self.defs: dict[str, dict] = {}

    def field(self, spec) -> dict:
        if isinstance(spec, schema.Table):
            return self.table(spec)
        if isinstance(spec, schema.TableList):
            out = {"type": "array", "description": _description(spec), "items": self.table(spec.table)}
            return out | ({"minItems": spec.min_length} if spec.min_length else {})
        out = {"description": _description(spec)} if spec.doc else {}
        if isinstance(spec, schema.Number):
            out["type"] = "number"
            if spec.minimum is not None:
                out["exclusiveMinimum" if spec.strict else "minimum"] = spec.minimum
            if spec.maximum is not None:
                out["maximum"] = spec.maximum
        elif isinstance(spec, schema.Integer):
            out["type"] = "integer"
            out |= {k: v for k, v in (("minimum", spec.minimum), ("maximum", spec.maximum)) if v is not None}
        elif isinstance(spec, schema.Text):
            out["type"] = "string"
            if spec.choices is not None:
                out["enum"] = list(spec.choices)
            if spec.pattern is not None:
                out["pattern"] = f"^(?:{spec.pattern})$"  # the loader matches the whole string
        elif isinstance(spec, schema.Flag):
            out["type"] = "boolean"
        elif isinstance(spec, schema.ListOf):
            out |= {"type": "array", "items": self.field(spec.item)}
            out |= {k: v for k, v in (("minItems", spec.min_length or None), ("maxItems", spec.max_length))
                    if v is not None}
        else:  # pragma: no cover - a new kind of field needs its translation here
            raise TypeError(f"no JSON Schema for {type(spec).__name__}")
        default = _default(spec)
        return out | ({"default": default} if default is not None else {})

    def table(self, table: schema.Table) -> dict:
        """A table inline, or a reference to its ``$defs`` entry when the module names it."""
        name = self.names.get(id(table))
        if name is None:
            return self._table(table)
        if name not in self.defs:
            self.defs[name] = {}  # reserved first: a table may be reached again while it is being written
            self.defs[name] = self._table(table)
        return {"$ref": f"#/$defs/{name}"}

    def _table(self, table: schema.Table) -> dict:
        if id(table) in self.open:
            return self.open[id(table)](table)
        out = {"type": "object"} | ({"description": table.doc} if table.doc else {})
        out |= self._properties(table.fields)
        if table.patterns:
            out["patternProperties"] = {f"^(?:{regex})$": self.field(spec) for regex, spec in table.patterns}
        if not table.open:
            out["additionalProperties"] = False
        return out

    def _properties(self, fields: dict) -> dict:
        required = [key for key, spec in fields.items() if spec.default is schema.REQUIRED]
        return {"properties": {key: self.field(spec) for key, spec in fields.items()}} | (
            {"required": required} if required else {})

    def _stiffness(self, table: schema.Table) -> dict:
        """A mesh stiffness table: ``model`` and the parameters of that model (absent: the default model)."""
        model = table.fields["model"]
        out = {"type": "object", "description": table.doc,
               "properties": {"model": self.field(model) | {"enum": list(MODELS)}}, "allOf": []}
        for name, cls in MODELS.items():
            condition = {"properties": {"model": {"const": name}}} | (
                {} if name == model.default else {"required": ["model"]})
            then = self._properties({"model": model, **cls.parameters.fields})
            then["properties"]["model"] = {}
            out["allOf"].append({"if": condition, "then": then | {"additionalProperties": False}})
        return out

    def _tolerances(self, table: schema.Table) -> dict:
        """``KIND.METRIC = value`` or ``"QUANTITY.METRIC" = value``; TOML's dotted keys arrive as nested tables."""
        value = {"type": "number", "exclusiveMinimum": 0, "maximum": MAX_TOLERANCE}
        self.defs["tolerance_table"] = {"type": "object",
                                        "additionalProperties": {"anyOf": [value, {"$ref": "#/$defs/tolerance_table"}]}}
        return {"type": "object", "description": table.doc,
                "patternProperties": {r"\.": {"anyOf": [value, {"$ref": "#/$defs/tolerance_table"}]}},
                "additionalProperties": {"$ref": "#/$defs/tolerance_table"}}


def train_schema() -> dict:
    """The JSON Schema (draft 2020-12) of a train file, as parsed from TOML."""
    walker = _Walker()
    body = walker._table(schema.TRAIN)
    body["description"] = (f"{schema.TRAIN.doc} (TOML, parsed); units in the keys' suffixes and the descriptions. "
                           "The loader also checks what a schema cannot: geometry, assembly, power flow, references.")
    return {"$schema": DRAFT, "title": "gearcheck train file"} | body | {"$defs": dict(sorted(walker.defs.items()))}
