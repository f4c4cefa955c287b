"""Checks a YAML document against a typed schema before Drake's `yaml_load_typed` reads it.

`yaml_load_typed` is exact but terse: an unknown key deep in a scenario gives "The fields
['yaww'] were unknown to the schema", a wrong type "'float' object is not iterable", and a plain
string where a tagged alternative is expected (`perception: ground_truth` for
`perception: !GroundTruthPerception {}`) is read into the first alternative's first field.
`check_document` walks the raw document beside the schema (dataclasses, Drake's bound structs
with `__fields__`, lists, string-keyed maps, Optional and Union alternatives selected by their
`!Tag`) and raises `SchemaError` with the field path (`objects[0].yaw`), what was expected and,
for an unknown key, the allowed keys with the closest match.
"""

import dataclasses
import difflib
import types
import typing
from pathlib import Path

import numpy as np
import yaml

MAX_QUOTE = 80  # characters of a value quoted in a message
MAX_BYTES = 2_000_000  # a document larger than this is refused [bytes]
MAX_VALUES = 200_000  # ... and one whose aliases expand to more values than this


class SchemaError(ValueError):
    def __init__(self, message: str, path: str):
        super().__init__(message)
        self.message = message
        self.path = path


class Tagged(dict):
    """A YAML mapping written with a `!Tag`."""

    tag: str = ""


class _TaggedLoader(yaml.SafeLoader):
    """PyYAML's safe loader that keeps `!Tag` mappings as `Tagged` dicts."""


def _construct_tagged(loader, suffix, node):
    if isinstance(node, yaml.MappingNode):
        value = Tagged(loader.construct_mapping(node, deep=True))
    elif isinstance(node, yaml.ScalarNode) and loader.construct_scalar(node) in ("", None):
        value = Tagged()
    else:
        raise yaml.constructor.ConstructorError(
            None, None, f"the tag !{suffix} must be given to a mapping", node.start_mark)
    value.tag = suffix
    return value


_TaggedLoader.add_multi_constructor("!", _construct_tagged)


def load_raw(text: str):
    """The document with its tags kept (raises yaml.YAMLError when malformed, SchemaError when
    larger than MAX_BYTES)."""
    if len(text.encode("utf-8", "replace")) > MAX_BYTES:
        raise SchemaError(f"the document is larger than {MAX_BYTES:,} bytes", "")
    doc = yaml.load(text, Loader=_TaggedLoader)
    _count_values(doc, [0])
    return doc


def _count_values(value, seen: list) -> None:
    """Raises SchemaError when `value` holds more than MAX_VALUES values, counting each use of
    an alias again (as a loader copying the document would)."""
    seen[0] += 1
    if seen[0] > MAX_VALUES:
        raise SchemaError(f"the document expands to more than {MAX_VALUES:,} values (through "
                          "aliases?)", "")
    if isinstance(value, dict):
        for item in value.values():
            _count_values(item, seen)
    elif isinstance(value, list):
        for item in value:
            _count_values(item, seen)


def _quote(value) -> str:
    text = repr(value)
    return text if len(text) <= MAX_QUOTE else text[:MAX_QUOTE] + "…"


def _fields(schema) -> dict | None:
    if dataclasses.is_dataclass(schema):
        hints = typing.get_type_hints(schema)
        return {f.name: hints.get(f.name, f.type) for f in dataclasses.fields(schema)}
    fields = getattr(schema, "__fields__", None)
    if fields is not None:
        return {f.name: f.type for f in fields}
    return None


def _union_members(schema) -> tuple | None:
    if typing.get_origin(schema) in (typing.Union, types.UnionType):
        return typing.get_args(schema)
    return None


def _type_name(schema) -> str:
    return getattr(schema, "__name__", str(schema))


def _is_number(value) -> bool:
    if isinstance(value, bool):
        return False
    if isinstance(value, (int, float)):
        return True
    if isinstance(value, str):  # YAML 1.1 reads 1e-3 as a string; Drake reads it as a number
        try:
            float(value)
        except ValueError:
            return False
        return True
    return False


def check_document(value, schema, path: str = "") -> None:
    """Raises SchemaError at the first place where `value` does not fit `schema` (a document
    from `load_raw`, whose size is bounded)."""
    where = path or "the document"
    members = _union_members(schema)
    if members is not None:
        non_null = [m for m in members if m is not type(None)]
        if value is None and len(non_null) < len(members):
            return
        if len(non_null) == 1:
            return check_document(value, non_null[0], path)
        structs = [m for m in non_null if _fields(m) is not None]
        if structs and len(structs) == len(non_null):
            names = [_type_name(m) for m in structs]
            expected = " or ".join(f"!{n} {{...}}" for n in names)
            if not isinstance(value, dict):
                raise SchemaError(f"expected one of {expected}, got {_quote(value)}", where)
            tag = getattr(value, "tag", "")
            if not tag:
                return check_document(value, structs[0], path)  # untagged: the first one
            if tag not in names:
                close = difflib.get_close_matches(tag, names, n=1)
                hint = f" (did you mean !{close[0]}?)" if close else ""
                raise SchemaError(f"unknown alternative !{tag}{hint}; allowed: "
                                  + ", ".join(f"!{n}" for n in names), where)
            return check_document(value, structs[names.index(tag)], path)
        if isinstance(value, (dict, list)) and all(m in (int, float, str, bool)
                                                   for m in non_null):
            raise SchemaError("expected a single value (" + " or ".join(
                _type_name(m) for m in non_null) + f"), got {_quote(value)}", where)
        return  # unions of scalars: the rest is left to the loader
    origin = typing.get_origin(schema)
    args = typing.get_args(schema)
    if origin is list:
        if not isinstance(value, list):
            raise SchemaError(f"expected a list, got {_quote(value)}", where)
        for i, item in enumerate(value):
            check_document(item, args[0], f"{path}[{i}]")
        return
    if origin is dict:
        if not isinstance(value, dict):
            raise SchemaError(f"expected a mapping of names to values, got {_quote(value)}",
                              where)
        for key, item in value.items():
            check_document(item, args[1], f"{path}.{key}" if path else str(key))
        return
    if schema is float:
        if not _is_number(value):
            raise SchemaError(f"expected a number, got {_quote(value)}", where)
        return
    if schema is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise SchemaError(f"expected a whole number, got {_quote(value)}", where)
        return
    if schema is bool:
        if not isinstance(value, bool):
            raise SchemaError(f"expected true or false, got {_quote(value)}", where)
        return
    if schema in (str, Path):
        if isinstance(value, (dict, list)) or value is None:
            raise SchemaError(f"expected a string, got {_quote(value)}", where)
        return
    if schema is np.ndarray:
        if not isinstance(value, list) or not all(_is_number(v) for v in value):
            raise SchemaError(f"expected a list of numbers, got {_quote(value)}", where)
        return
    fields = _fields(schema) if isinstance(schema, type) else None
    if fields is None:
        return  # a type the loader checks itself
    if not isinstance(value, dict):
        raise SchemaError(f"expected a mapping with keys among {', '.join(fields)}, got "
                          f"{_quote(value)}", where)
    for key, item in value.items():
        if key not in fields:
            close = difflib.get_close_matches(str(key), list(fields), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise SchemaError(f"unknown field {str(key)!r}{hint}; allowed: "
                              + ", ".join(fields), f"{path}.{key}" if path else str(key))
        check_document(item, fields[key], f"{path}.{key}" if path else str(key))

