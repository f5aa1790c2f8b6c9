"""The checks every part of a glTF 2.0 document's validation shares (Khronos glTF 2.0
specification, 2021): the accessor component types (sec. 3.6.2.2), JSON values of
each kind (objects, arrays, integers, finite numbers in a range, enumerations,
booleans, strings) and indices into the document's arrays, each raising a
ValueError that names the value's JSON location; and how a value of the file is
shown in a message (:func:`_shown`: never a line of the file).
:mod:`pbrkit.io.gltf_document`, :mod:`pbrkit.io.gltf_extensions` and
:mod:`pbrkit.io.gltf_materials` build on them.
"""

from __future__ import annotations

import json
import re

import numpy as np

from ..core.checks import is_finite_number

__all__ = ["COMPONENT_TYPES", "COMPONENT_NAMES", "COMPONENT_COUNTS"]

#: Accessor component types (glTF 2.0 sec. 3.6.2.2) and their NumPy types, names and counts per type.
_BYTE, _UBYTE, _SHORT, _USHORT, _UINT, _FLOAT = 5120, 5121, 5122, 5123, 5125, 5126
_COMPONENT = {_BYTE: np.int8, _UBYTE: np.uint8, _SHORT: np.int16, _USHORT: np.uint16, _UINT: np.uint32,
              _FLOAT: np.float32}
_COMPONENT_NAMES = {_BYTE: "BYTE", _UBYTE: "UNSIGNED_BYTE", _SHORT: "SHORT", _USHORT: "UNSIGNED_SHORT",
                    _UINT: "UNSIGNED_INT", _FLOAT: "FLOAT"}
_NCOMP = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
COMPONENT_TYPES = _COMPONENT
COMPONENT_NAMES = _COMPONENT_NAMES
COMPONENT_COUNTS = _NCOMP


def _shown(value, limit=60):
    """A JSON value of the file for a message: a short plain string (a word or a number
    written as text, at most 16 characters) or a non-string value quoted, escaped and
    cut to ``limit`` characters; any other string described by its length only, so a
    message never carries a line of the file."""
    if isinstance(value, str):
        if len(value) <= 16 and re.fullmatch(r"[A-Za-z0-9 ._+-]*", value):
            return repr(value)
        return f"a string of {len(value)} characters"
    text = ascii(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _json_kind(value):
    """'an array', 'a string', ... for messages about JSON values."""
    if isinstance(value, bool) or value is None:
        return json.dumps(value)
    return {dict: "an object", list: "an array", str: "a string", int: "a number", float: "a number"}.get(
        type(value), type(value).__name__)


def _is_int(value):
    return isinstance(value, int) and not isinstance(value, bool)


def _object(value, where):
    if not isinstance(value, dict):
        raise ValueError(f"{where} must be a JSON object; got {_json_kind(value)}")
    return value


def _array(value, where, of_objects=False):
    if not isinstance(value, list):
        raise ValueError(f"{where} must be a JSON array; got {_json_kind(value)}")
    if of_objects:
        for i, item in enumerate(value):
            _object(item, f"{where}[{i}]")
    return value


def _integer(value, where, lo=0, hi=None):
    if not _is_int(value) or value < lo or (hi is not None and value > hi):
        bound = f"from {lo} to {hi}" if hi is not None else f">= {lo}"
        raise ValueError(f"{where} must be an integer {bound}; got {_shown(value)}")
    return value


def _number(value, where, lo=None, hi=None):
    if not is_finite_number(value) or (lo is not None and value < lo) or (hi is not None and value > hi):
        bound = f" in [{lo}, {hi}]" if lo is not None and hi is not None else (
            f" >= {lo}" if lo is not None else "")
        raise ValueError(f"{where} must be a finite number{bound}; got {_shown(value)}")
    return value


def _numbers(value, where, n, lo=None, hi=None):
    if not isinstance(value, list) or len(value) != n or not all(is_finite_number(x) for x in value) or (
            lo is not None and min(value) < lo) or (hi is not None and max(value) > hi):
        bound = f" in [{lo}, {hi}]" if lo is not None and hi is not None else (
            f" >= {lo}" if lo is not None else "")
        raise ValueError(f"{where} must be an array of {n} finite numbers{bound}; got {_shown(value)}")
    return value


def _choice(value, where, choices):
    if isinstance(value, bool) or value not in choices:
        raise ValueError(f"{where} must be one of {', '.join(map(str, choices))}; got {_shown(value)}")
    return value


def _boolean(value, where):
    if not isinstance(value, bool):
        raise ValueError(f"{where} must be true or false; got {_shown(value)}")
    return value


def _string(value, where):
    if not isinstance(value, str):
        raise ValueError(f"{where} must be a string; got {_shown(value)}")
    return value


class _Indices:
    """Checks references into the document's arrays (sizes known up front)."""

    def __init__(self, counts):
        self.counts = counts

    def __call__(self, value, where, array):
        """``value`` as a valid index into ``array`` (a key of ``counts``)."""
        n = self.counts[array]
        if not _is_int(value):
            raise ValueError(f"{where} must be an integer index into {array}; got {_shown(value)}")
        if not 0 <= value < n:
            have = f"the file has {n} {array} (indices 0 to {n - 1})" if n else f"the file has no {array}"
            raise ValueError(f"{where} is {value}, but {have}")
        return value

    def optional(self, obj, key, where, array):
        if obj.get(key) is not None:
            self(obj[key], f"{where}.{key}", array)

    def required(self, obj, key, where, array):
        if obj.get(key) is None:
            raise ValueError(f"{where} has no {key} (an index into {array})")
        self(obj[key], f"{where}.{key}", array)

    def many(self, obj, key, where, array, unique=True):
        """A list of indices (``unique``: no duplicates); [] when absent."""
        values = obj.get(key)
        if values is None:
            return []
        _array(values, f"{where}.{key}")
        for i, value in enumerate(values):
            self(value, f"{where}.{key}[{i}]", array)
        if unique and len(set(values)) != len(values):
            twice = next(v for v in values if values.count(v) > 1)
            raise ValueError(f"{where}.{key} lists {twice} more than once")
        return values
