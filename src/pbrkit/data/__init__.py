"""Data shipped with pbrkit: a small CC0 environment map for examples, the demo
and scenes without an ``[environment]``.

:func:`environment_path` is the path of ``environment.hdr`` (512 x 256,
Radiance RGBE, equirectangular, linear scene-referred RGB): Poly Haven's
"Kloofendal Overcast" (``kloofendal_overcast_1k.hdr``, CC0) downsampled by
pbrkit with exact solid-angle weights.  :data:`ENVIRONMENT` describes it
(name, source, licence), as ``LICENSE-environment.md`` beside it does at
length (:func:`environment_licence_path`).

>>> from pbrkit.data import environment_path
>>> from pbrkit.ibl import bake
>>> b = bake(environment_path(), size=64)        # doctest: +SKIP
"""

from __future__ import annotations

import atexit
from contextlib import ExitStack
from importlib.resources import as_file, files
from pathlib import Path

__all__ = ["ENVIRONMENT", "environment_path", "environment_licence_path"]

#: What the bundled environment is and where it comes from (LICENSE-environment.md).
ENVIRONMENT = {
    "file": "environment.hdr",
    "name": "Kloofendal Overcast",
    "source_file": "kloofendal_overcast_1k.hdr",
    "author": "Poly Haven",
    "url": "https://polyhaven.com",
    "licence": "CC0 1.0 Universal",
    "licence_url": "https://creativecommons.org/publicdomain/zero/1.0/",
    "resolution": [512, 256],
    "description": "overcast hillside; soft, low dynamic range (peak ~5.9), downsampled 2 x 2 by pbrkit "
                   "with exact solid-angle weights",
    "licence_file": "LICENSE-environment.md",
}


_extracted = ExitStack()
atexit.register(_extracted.close)


def _resource(name):
    resource = files(__name__) / name
    # An installed package (wheel, editable or source tree) is a directory on disk; from a
    # zip the file is extracted to a temporary file that lives as long as the process.
    if isinstance(resource, Path):
        return resource
    return Path(_extracted.enter_context(as_file(resource)))


def environment_path():
    """Path of the bundled CC0 environment map ``environment.hdr`` (:data:`ENVIRONMENT`),
    usable wherever pbrkit takes an environment file (``bake``, scene files,
    ``pbrkit bake``)."""
    return _resource(ENVIRONMENT["file"])


def environment_licence_path():
    """Path of ``LICENSE-environment.md``: the bundled environment's source and licence."""
    return _resource(ENVIRONMENT["licence_file"])
