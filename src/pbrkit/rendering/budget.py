"""Up-front memory check of a render, so that an impossible request (a
16384 x 16384 image with 16 x 16 supersampling asks for tens of TiB) is
refused at once with the figure, instead of being killed or swapping for
minutes.

The estimate is simple, conservative and linear in what a render allocates
per camera ray (``width x height x supersample^2`` rays; the NumPy arrays of
:mod:`pbrkit.rendering.primary`, :mod:`~pbrkit.rendering.realtime` and
:mod:`~pbrkit.rendering.reference` are all per ray or per pixel):

- :data:`BYTES_PER_RAY` per mode: ray directions and their temporaries, hit
  records, surface data (position, two normals, material index, base colour,
  metallic, roughness, occlusion, emission: about 150 bytes), shading buffers
  (view vectors, reflection directions, prefiltered and irradiance lookups),
  and for the ground truth its per-ray copies for the fused kernel or the
  wavefront's light and BSDF sample buffers, plus the per-pixel sums, image,
  standard error and output panels.  Measured peaks (Python 3.11, NumPy 2,
  spheres and planes or a glTF mesh, 512^2 to 2048^2 pixels): at most 510
  bytes per ray in real time, 880 for the ground truth, 900 for ``compare``
  with its per-approximation split; the constants add about 40% headroom.
- :data:`BAKE_BYTES_PER_TEXEL` per texel of the six ``bake_size^2`` faces of the
  real-time modes' bake (its prefiltered mip chain, irradiance cube and
  working copies; measured 60 to 80 for 256^2 to 2048^2 faces).
- :data:`FIXED_BYTES` for what does not scale with the image: the environment
  map, lookup tables and compiled kernels.

``spp`` and ``bounces`` do not change the peak: the ground truth loops over
samples and bounces, reusing per-ray buffers.  Not included: glTF meshes and
textures and large environment maps (known only once loaded; a glTF file's
own sizes are checked when it is read).

The memory available is :func:`pbrkit.core.inputs.available_memory`; where the
system does not say, the check is skipped.
"""

from __future__ import annotations

from ..core.errors import InputError
from ..core.inputs import available_memory, size_text

__all__ = [
    "BAKE_BYTES_PER_TEXEL",
    "BYTES_PER_RAY",
    "FIXED_BYTES",
    "available_memory",
    "check_render_memory",
    "estimate_render_memory",
]

#: Peak bytes per camera ray by render mode (module docstring).
BYTES_PER_RAY = {"realtime": 768, "reference": 1280, "compare": 1280}
#: Peak bytes of the bake per texel of its six level-0 faces (real-time modes).
BAKE_BYTES_PER_TEXEL = 128
#: Memory that does not scale with the image (environment, tables, kernels).
FIXED_BYTES = 256 << 20


def estimate_render_memory(scene, mode, bake_size=256):
    """``(total, parts)``: the estimated peak bytes of rendering ``scene`` in ``mode``
    (``realtime``, ``reference`` or ``compare``) and its parts ``rays``, ``bake``
    and ``fixed`` (module docstring)."""
    cam = scene.camera
    rays = int(cam.width) * int(cam.height) * int(cam.supersample) ** 2
    parts = {"rays": rays * BYTES_PER_RAY.get(mode, max(BYTES_PER_RAY.values())), "bake": 0, "fixed": FIXED_BYTES}
    if mode in ("realtime", "compare") and isinstance(bake_size, int) and not isinstance(bake_size, bool) \
            and bake_size > 0:
        parts["bake"] = 6 * bake_size * bake_size * BAKE_BYTES_PER_TEXEL
    return sum(parts.values()), parts


def _advice(scene, parts):
    """What to lower, in the terms of ``pbrkit render``'s options and the scene's keys."""
    remedies = ["lower --width/--height"]
    if scene.camera.supersample > 1:
        remedies.append("the camera's supersample")
    if parts["bake"] > parts["rays"] / 2:
        remedies.append("--bake-size")
    return remedies[0] if len(remedies) == 1 else ", ".join(remedies[:-1]) + " or " + remedies[-1]


def check_render_memory(scene, mode, spp, bounces=0, bake_size=256, available=None):
    """Refuse a render that cannot fit in memory: raise
    :class:`pbrkit.core.errors.InputError` (a ``ValueError`` naming the scene) with the
    estimate (:func:`estimate_render_memory`) and the memory available
    (``available`` bytes, default :func:`available_memory`; no check where that is
    unknown).  ``spp`` and ``bounces`` are accepted for the record: they do not change
    the peak (module docstring).  Returns the estimate in bytes."""
    need, parts = estimate_render_memory(scene, mode, bake_size)
    free = available_memory() if available is None else available
    if free is not None and need > free:
        cam = scene.camera
        size = f"{cam.width} x {cam.height}"
        if cam.supersample > 1:
            size += f" (supersample {cam.supersample})"
        raise InputError(f"a {size} {mode} render needs about {size_text(need)} of memory; this machine has "
                         f"{size_text(free)} available; {_advice(scene, parts)}", getattr(scene, "source", None))
    return need
