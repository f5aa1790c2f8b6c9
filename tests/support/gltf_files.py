"""Shared test helper: glTF files written byte by byte for the tests that build their own."""

import json
import struct


def glb_bytes(doc, blob):
    """A binary glTF container (glTF 2.0 sec. 4.4) of the document ``doc`` with ``blob``
    (or None) as its BIN chunk, each chunk padded to 4 bytes."""
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    chunks = struct.pack("<II", len(text), 0x4E4F534A) + text
    if blob is not None:
        blob = bytes(blob) + b"\0" * (-len(blob) % 4)
        chunks += struct.pack("<II", len(blob), 0x004E4942) + blob
    return b"glTF" + struct.pack("<II", 2, 12 + len(chunks)) + chunks
