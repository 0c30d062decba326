"""The JSON Schema (draft 2020-12) of the model file, generated from the typed schema
(:mod:`rwadist.schema`): ``docs/model.schema.json`` is its output, pinned by tests/test_schema.py.

Run ``python -m rwadist.schema_json docs/model.schema.json`` after changing the typed schema.

A JSON Schema cannot say everything the typed parser checks: knots strictly increasing, as many
``psd_ref`` values as ``f_Hz`` knots, lo <= hi in ``excluded_rpm``, at most one effect of a kind a wheel has one of,
the physical bounds of the analytical parameters taken together (an overdamped mode), and integers
written as 3.0 (JSON Schema counts them as integers) are refused by :mod:`rwadist.schema` only.
"""
from __future__ import annotations

import json
import sys
from dataclasses import MISSING, fields

from . import schema


def _object(checks: dict, required: list, extra: bool = True) -> dict:
    return {"type": "object", "required": required,
            "properties": {k: fn.json for k, fn in checks.items()}, "additionalProperties": extra}


def effect_schema(cls: type[schema.Effect]) -> dict:
    """The JSON Schema of one effect kind (keys the class does not declare are allowed: carried through)."""
    checks, required = {}, ["kind"]
    for f in fields(cls):
        if "check" not in f.metadata:
            continue
        key = f.metadata.get("key") or f.name
        checks[key] = f.metadata["check"]
        if f.default is MISSING and f.default_factory is MISSING:
            required.append(key)
    out = _object(checks, required)
    out["properties"]["kind"] = {"const": cls.KIND}
    return out


def json_schema() -> dict:
    """The model file's JSON Schema (a dict)."""
    from .model import HARMONIC_CHECKS

    harmonic = _object(HARMONIC_CHECKS, ["h", "C"])
    harmonic["properties"]["excluded_rpm"] = {"type": "array", "items": {
        "type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}}
    params = {key: ({"type": "number", "exclusiveMinimum": 0} if name in schema.POSITIVE_PARAMS
                    else {"type": "number", "minimum": 0} if name in schema.NONNEGATIVE_PARAMS
                    else {"type": "number"}) for name, key in schema.PARAM_KEYS.items()}
    analytical = {"type": "object", "properties": {
        "kind": {"const": schema.ANALYTICAL_KIND}, **params, "modes_assumed": {"type": "boolean"},
        "unconstrained": {"type": "array", "items": {"enum": list(schema.UNCONSTRAINED_MODES + schema.UNCONSTRAINED_DAMPING)}}}}
    kinds = sorted(schema.EFFECT_KINDS)
    effect = {"type": "object", "required": ["kind"], "properties": {"kind": {"type": "string"}},
              "allOf": [{"if": {"properties": {"kind": {"const": k}}, "required": ["kind"]},
                         "then": {"$ref": f"#/$defs/effect_{k}"}} for k in kinds]}
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$id": "https://rwadist.invalid/model.schema.json",
        "title": "rwadist wheel model file (rwadist.model, version 1)",
        "description": "Generated from rwadist/schema.py by `python -m rwadist.schema_json`; SI units (C per "
                       "(rad/s)^2). The typed parser checks more (see rwadist/schema_json.py).",
        "type": "object",
        "required": ["schema", "schema_version"],
        "properties": {
            "schema": {"const": schema.SCHEMA},
            "schema_version": {"const": schema.SCHEMA_VERSION},
            "name": {"type": "string"},
            "units": {"type": "object"},
            "wheel": {"type": "object"},
            "empirical": {"type": "object", "additionalProperties": False,
                          "properties": {d: {"type": ["array", "null"], "items": {"$ref": "#/$defs/harmonic"}}
                                         for d in schema.DIRECTIONS}},
            "analytical": {"anyOf": [{"$ref": "#/$defs/analytical"}, {"type": "null"}]},
            "effects": {"type": ["array", "null"], "items": {"$ref": "#/$defs/effect"}},
            "provenance": {"type": ["object", "null"]},
        },
        "$defs": {"harmonic": harmonic, "analytical": analytical, "effect": effect,
                  **{f"effect_{k}": effect_schema(schema.EFFECT_KINDS[k]) for k in kinds}},
    }


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    text = json.dumps(json_schema(), indent=2) + "\n"
    if argv:
        with open(argv[0], "w") as fh:
            fh.write(text)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
