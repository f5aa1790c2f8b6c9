"""The published LTC tables (Heitz, Dupuy, Hill and Neubelt 2016, ``ltc_code``
``fit/results/ltc.js``) as three.js ships them, read from a file the caller
names: never bundled (the data is ltc_code's, MIT licensed, in three's
``RectAreaLightTexturesLib.js``) and never looked for by the library; the
command line (``pbrkit ltc --report --published FILE``), the benchmarks and
the tests decide where three's npm package is.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..core.inputs import check_regular, read_bytes, read_text

__all__ = ["LUT_SIZE", "THREE_FILES", "published_table", "published_table_path"]

#: Side of the published tables (texels per axis).
LUT_SIZE = 64
#: Largest JavaScript file searched for the published tables (three.js's are about 80 KiB).
_MAX_JS_BYTES = 16 << 20
#: The files of three's npm package that hold ``LTC_MAT_1`` / ``LTC_MAT_2``: three
#: r150+ keeps the arrays in ``RectAreaLightTexturesLib.js``, older releases in
#: ``RectAreaLightUniformsLib.js``.
THREE_FILES = ("examples/jsm/lights/RectAreaLightTexturesLib.js", "examples/jsm/lights/RectAreaLightUniformsLib.js")


def published_table_path(path):
    """The three.js file that holds ``LTC_MAT_1`` / ``LTC_MAT_2``, given ``path``:
    that file, the ``three`` package's folder or a ``node_modules`` folder holding
    it (:data:`THREE_FILES` inside the package).  Raises FileNotFoundError naming
    where it looked."""
    if path is None:
        raise TypeError("published_table_path needs the path of three.js's LTC data (no default)")
    p = Path(path)
    if p.exists() and not p.is_dir():
        check_regular(p, "three.js's LTC data (a JavaScript file, or the three package's folder)")
    looked = []
    for base in ([p] if p.is_file() else [p / "three", p]):
        for f in ([base] if base.is_file() else [base / name for name in THREE_FILES]):
            looked.append(str(f))
            if f.is_file() and "LTC_MAT_1" in read_bytes(f, _MAX_JS_BYTES, "a JavaScript file").decode(
                    "utf-8", errors="replace"):
                return f
    raise FileNotFoundError("the published LTC tables (three.js's LTC_MAT_1 / LTC_MAT_2) were not found; looked in: "
                            + ", ".join(looked))


def published_table(path):
    """The LTC tables of Heitz, Dupuy, Hill and Neubelt 2016 (``ltc_code``
    ``fit/results/ltc.js``) as three.js ships them: ``LTC_MAT_1`` and
    ``LTC_MAT_2`` read from ``path`` (:func:`published_table_path`: the file,
    three's package folder or a ``node_modules`` folder; MIT licensed, not
    bundled with pbrkit), as two float32 arrays (64, 64, 4) indexed [t, a, c],
    the order three uploads them in (a ``DataTexture`` 64 wide: row t, column
    a).  Values are rounded to float32 as three's ``Float32Array`` does."""
    f = published_table_path(path)
    text = read_text(f, _MAX_JS_BYTES, "three.js's LTC data (a JavaScript file with LTC_MAT_1 and LTC_MAT_2)")
    out = []
    for name in ("LTC_MAT_1", "LTC_MAT_2"):
        match = re.search(name + r"\s*=\s*\[([^\]]*)\]", text)
        if match is None:
            raise ValueError(f"{f}: no {name} array")
        try:
            values = np.array([float(x.replace(" ", "")) for x in match.group(1).split(",") if x.strip()],
                              dtype=np.float64)
        except ValueError:
            raise ValueError(f"{f}: {name} holds something other than numbers") from None
        if values.size != LUT_SIZE * LUT_SIZE * 4:
            raise ValueError(f"{f}: {name} has {values.size} values, expected {LUT_SIZE * LUT_SIZE * 4}")
        out.append(values.astype(np.float32).reshape(LUT_SIZE, LUT_SIZE, 4))
    return out[0], out[1]
