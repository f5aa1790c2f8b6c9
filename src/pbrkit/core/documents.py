"""Parsing the TOML and JSON documents pbrkit reads (scene and style files) with
errors that say *where* the text is wrong and what was expected, never what it
holds.

The parsers' own messages quote the file: :mod:`tomllib` names keys and
characters (``Cannot declare ('...',) twice``, ``Illegal character '...'``,
``Duplicate inline table key '...'``), at any length; so only the position
is kept: ``line L, column C`` (:class:`json.JSONDecodeError`'s ``lineno`` and
``colno``; the ``(at line L, column C)`` that ends every
:class:`tomllib.TOMLDecodeError` message of Python 3.11 to 3.13).  Nesting too
deep for the parser (:class:`RecursionError`) and an integer of more digits
than Python converts (:func:`sys.set_int_max_str_digits`) are named as such.
"""

from __future__ import annotations

import json
import re
import tomllib

from .errors import InputError

__all__ = ["FORMATS", "parse_document"]

#: The document formats, by file suffix.
FORMATS = {".toml": "toml", ".json": "json"}
_TOML_WHERE = re.compile(r"\(at line (\d+), column (\d+)\)\s*$")


def parse_document(text, fmt, path, expected):
    """The parsed ``text`` of ``path`` in ``fmt`` (``"toml"`` or ``"json"``), or
    :class:`InputError` ``"<path>: invalid TOML (line 3, column 7); expected
    <expected>"`` (module docstring: no quotation of the file)."""
    try:
        return tomllib.loads(text) if fmt == "toml" else json.loads(text)
    except json.JSONDecodeError as exc:
        where = f"line {exc.lineno}, column {exc.colno}"
    except tomllib.TOMLDecodeError as exc:
        lineno = getattr(exc, "lineno", None)  # Python 3.14 has the position as attributes
        match = _TOML_WHERE.search(str(exc))
        where = (f"line {lineno}, column {exc.colno}" if lineno is not None
                 else f"line {match[1]}, column {match[2]}" if match else "at the end of the text")
    except RecursionError:
        where = "nested too deeply"
    except ValueError:  # an integer of more digits than int() converts
        where = "a number with too many digits"
    raise InputError(f"invalid {fmt.upper()} ({where}); expected {expected}", path)
