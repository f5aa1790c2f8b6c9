"""The input rules: files read only where they belong, reads bounded by what the
format declares, memory estimated before it is allocated, and errors that never
echo a file's content.

pbrkit reads assets from elsewhere (downloaded glTF models, HDRIs, material and
scene files) and runs in batch on shared machines, so every input path goes
through this module:

- :func:`read_bytes` / :func:`read_text` / :func:`open_regular`: a *regular*
  file only (a device such as ``/dev/zero``, a pipe, a socket or a folder is
  refused, also behind a symbolic link), read to at most a stated limit: a file
  larger than what its kind may hold is refused with both figures before it is
  read;
- :class:`Confinement` / :func:`confined_path`: a path named *inside* an asset
  (a glTF buffer or image ``uri``, a texture of a scene) must resolve, after
  percent-decoding, ``..`` and symbolic links, to a file under the asset's own
  folder or under one of the roots the user allows (``--allow-root``, the scene
  key ``allow_roots``); absolute paths and ``file:`` URIs are refused unless
  they lie under an allowed root, other URI schemes always;
- :func:`check_allocation`: the bytes an input asks for (an accessor's count, an
  image's declared size) against the memory this process can still use
  (:func:`available_memory`), refused with both figures before allocating;
- :func:`describe`: a short, escaped rendering of a value taken from a file
  (an URI), for the few messages that must name one; a message never quotes a
  file's bytes or lines.

The limits (:data:`MAX_TEXT_BYTES`) are generous for real files: a scene, style,
list or manifest file is text of at most 64 MiB.
"""

from __future__ import annotations

import os
import re
import stat
from pathlib import Path
from urllib.parse import unquote

from .errors import InputError

__all__ = ["MAX_TEXT_BYTES", "Confinement", "available_memory", "check_allocation", "check_regular",
           "confined_path", "describe", "open_regular", "read_bytes", "read_text", "size_text"]

#: Largest text input (scene, style, ``--list``, manifest files), in bytes.
MAX_TEXT_BYTES = 64 << 20

_GIB = 1 << 30
_KIND = {stat.S_IFCHR: "a character device", stat.S_IFBLK: "a block device", stat.S_IFIFO: "a named pipe",
         stat.S_IFSOCK: "a socket", stat.S_IFDIR: "a folder"}


def size_text(n):
    """Bytes as a short figure: '512 GiB', '1.5 GiB', '300 MiB', '12 KiB', '80 bytes'."""
    n = int(n)
    if n >= 10 * _GIB:
        return f"{n / _GIB:.0f} GiB"
    if n >= _GIB:
        return f"{n / _GIB:.1f} GiB"
    if n >= 1 << 20:
        return f"{n >> 20} MiB"
    if n >= 1 << 10:
        return f"{n >> 10} KiB"
    return f"{n} bytes"


def describe(value, limit=60):
    """``value`` (a string taken from a file) as a short, escaped quotation: control
    and non-ASCII characters escaped (``ascii``), cut to ``limit`` characters."""
    text = ascii(str(value))
    return text if len(text) <= limit else text[:limit - 4] + "...'"


def _stat_or_fail(path, expected):
    try:
        return os.stat(path)  # follows symbolic links: the target is what would be read
    except FileNotFoundError:
        raise InputError(f"file not found; expected {expected}", path) from None
    except OSError as exc:
        raise InputError(f"cannot read file ({exc.strerror or exc}); expected {expected}", path) from None


def check_regular(path, expected="a file"):
    """The size of ``path`` if it is a regular file (after symbolic links); else
    :class:`InputError` saying what it is and what was ``expected``."""
    st = _stat_or_fail(path, expected)
    if not stat.S_ISREG(st.st_mode):
        kind = _KIND.get(stat.S_IFMT(st.st_mode), "not a regular file")
        raise InputError(f"is {kind}, not a regular file; expected {expected}", path)
    return st.st_size


def _check_size(path, size, limit, expected):
    if limit is not None and size > limit:
        raise InputError(f"{size_text(size)} is more than the {size_text(limit)} that {expected} may hold "
                         f"(not such a file, or corrupt)", path)


def open_regular(path, limit=None, expected="a file"):
    """``path`` opened for binary reading, if it is a regular file of at most ``limit``
    bytes (checked again on the open file, so a swap after the check is caught)."""
    _check_size(path, check_regular(path, expected), limit, expected)
    try:
        f = open(path, "rb")  # noqa: SIM115 - returned to the caller
    except OSError as exc:
        raise InputError(f"cannot read file ({exc.strerror or exc}); expected {expected}", path) from None
    st = os.fstat(f.fileno())
    if not stat.S_ISREG(st.st_mode) or (limit is not None and st.st_size > limit):
        f.close()
        check_regular(path, expected)
        _check_size(path, st.st_size, limit, expected)
        raise InputError(f"changed while it was opened; expected {expected}", path)
    return f


def read_bytes(path, limit, expected="a file"):
    """The bytes of the regular file ``path``, at most ``limit`` (:func:`open_regular`),
    with the memory to hold them checked before reading (:func:`check_allocation`); a
    file whose length changes while it is read is refused too."""
    with open_regular(path, limit, expected) as f:
        size = os.fstat(f.fileno()).st_size
        check_allocation(size, f"reading the file ({size_text(size)})", path)
        try:
            data = f.read(size + 1)
        except OSError as exc:
            raise InputError(f"cannot read file ({exc.strerror or exc}); expected {expected}", path) from None
    if len(data) != size:
        _check_size(path, len(data), limit, expected)
        raise InputError(f"changed while it was read ({len(data)} bytes read, {size} expected); expected {expected}",
                         path)
    return data


def read_text(path, limit=MAX_TEXT_BYTES, expected="a UTF-8 text file"):
    """The UTF-8 text of the regular file ``path`` (:func:`read_bytes`); a file that
    is not UTF-8 is refused with the offset of its first bad byte, not its content."""
    data = read_bytes(path, limit, expected)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"is not UTF-8 text (byte {exc.start} is not valid UTF-8); expected {expected}",
                         path) from None


_SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*:")
_WINDOWS_DRIVE = re.compile(r"^[A-Za-z]:[\\/]")


class Confinement:
    """Where the files an asset names may lie: under ``folder`` (the asset's own) or
    under one of ``allowed`` (the roots the user allows, :func:`confined_path`)."""

    def __init__(self, folder, allowed=()):
        self.folder = Path(folder).resolve()
        self.allowed = tuple(Path(r).expanduser().resolve() for r in allowed)

    @property
    def roots(self):
        return (self.folder,) + self.allowed

    def resolve(self, reference, where, asset=None):
        """The file that ``reference`` (a relative URI or path named inside ``asset``,
        at ``where``) stands for, or :class:`InputError` naming ``asset`` and ``where``."""
        return confined_path(reference, self, where, asset)


def confined_path(reference, confinement, where, asset=None):
    """The resolved file that ``reference`` names, relative to ``confinement.folder``,
    if it lies under one of the confinement's roots (module docstring).  The reference
    is percent-decoded as a URI (``%2e%2e/`` is ``../``); ``file:`` URIs and absolute
    paths are resolved as they are and must lie under an allowed root; other URI
    schemes (``http:``, ...) are refused."""
    text = str(reference)
    if "\x00" in text:
        raise InputError(f"{where}: a path with a NUL character; expected a relative path", asset)
    absolute = False
    if text.lower().startswith("file:"):
        text, absolute = unquote(re.sub(r"^file:(//[^/]*)?", "", text, flags=re.IGNORECASE)), True
    elif _SCHEME.match(text) and not _WINDOWS_DRIVE.match(text):
        raise InputError(f"{where} {describe(text)}: only relative file paths and data: URIs are read", asset)
    else:
        text = unquote(text)
        absolute = os.path.isabs(text) or bool(_WINDOWS_DRIVE.match(text)) or text.startswith("\\")
    if "\x00" in text:
        raise InputError(f"{where}: a path with a NUL character; expected a relative path", asset)
    target = Path(text) if absolute else confinement.folder / text
    resolved = Path(os.path.realpath(target))
    if absolute and not confinement.allowed:
        raise InputError(f"{where}: an absolute path or file: URI, read only under a folder allowed with "
                         "--allow-root (scene key allow_roots); expected a path relative to the asset", asset)
    for root in confinement.roots:
        if resolved == root or resolved.is_relative_to(root):
            return resolved
    allowed = "its own folder" + (" or an allowed root" if confinement.allowed else "")
    raise InputError(f"{where} {describe(reference)} lies outside {allowed}; allow another folder with "
                     "--allow-root (scene key allow_roots)", asset)


# ------------------------------------------------------------------ memory


def _read_int(path):
    """The integer in a one-number file (cgroup limits), None if absent or not a number."""
    try:
        return int(Path(path).read_text().split()[0])
    except (OSError, ValueError, IndexError):
        return None


def _meminfo_available():
    """``MemAvailable`` of ``/proc/meminfo`` in bytes, None where unknown."""
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


def _sysconf_available():
    """Free physical memory from ``os.sysconf``, None where unsupported."""
    try:
        pages, size = os.sysconf("SC_AVPHYS_PAGES"), os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):
        return None
    return pages * size if pages > 0 and size > 0 else None


def _cgroup_headroom():
    """Bytes left under a cgroup memory limit (v2, else v1), None without a limit."""
    for limit_file, usage_file in (("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
                                   ("/sys/fs/cgroup/memory/memory.limit_in_bytes",
                                    "/sys/fs/cgroup/memory/memory.usage_in_bytes")):
        limit, usage = _read_int(limit_file), _read_int(usage_file)
        if limit is not None and usage is not None and limit < 1 << 60:  # "max" / huge: no limit
            return max(limit - usage, 0)
    return None


def available_memory():
    """Bytes this process can still allocate without swapping: ``MemAvailable`` of
    ``/proc/meminfo`` (else the free pages of ``os.sysconf``), lowered to the headroom
    of a cgroup memory limit if one is set; None where the system does not say."""
    free = _meminfo_available()
    if free is None:
        free = _sysconf_available()
    headroom = _cgroup_headroom()
    if headroom is not None:
        free = headroom if free is None else min(free, headroom)
    return free


def check_allocation(nbytes, what, path=None, advice=None, available=None):
    """Refuse, before allocating, ``nbytes`` for ``what`` (e.g. ``"accessors[3] (count
    10,000,000)"``) when more than the memory available (``available``, default
    :func:`available_memory`; no check where that is unknown): :class:`InputError`
    naming ``path`` with both figures and ``advice``.  Returns ``nbytes``."""
    free = available_memory() if available is None else available
    if free is not None and nbytes > free:
        tail = f"; {advice}" if advice else ""
        raise InputError(f"{what} would need about {size_text(nbytes)} of memory; this machine has "
                         f"{size_text(free)} available{tail}", path)
    return nbytes
