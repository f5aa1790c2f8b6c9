"""glTF textures and the materials that use them.

Texture sampling follows the glTF sampler: bilinear (or nearest) filtering of
linear texel values at texel centres (sRGB texels are decoded before
filtering, as GPUs do), REPEAT / CLAMP_TO_EDGE / MIRRORED_REPEAT wrapping
(texel selection and weights of OpenGL 4.6 sec. 8.14.2,
:mod:`pbrkit.core.filtering`), UV (0, 0) at the first (top-left) texel.
Minification filters and mip maps are not used (supersample the camera
instead).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.filtering import (
    CLAMP_TO_EDGE,
    MIRRORED_REPEAT,
    REPEAT,
    floor_int,
    texel_pair,
    wrap_texel,
)
from .scene import MaterialSpec

__all__ = [
    "Texture",
    "TextureRef",
    "SurfaceMaterial",
    "tangent_space_normal",
]

# ================================================================ textures


#: glTF sampler wrap modes: the OpenGL enums of :mod:`pbrkit.core.filtering`.
_WRAP_REPEAT, _WRAP_CLAMP, _WRAP_MIRROR = REPEAT, CLAMP_TO_EDGE, MIRRORED_REPEAT
_FILTER_NEAREST = 9728


@dataclass
class Texture:
    """Texels (H, W, 4) float32, already linear (sRGB images decoded), with the
    glTF sampler's wrap modes and magnification filter."""

    texels: np.ndarray
    wrap_s: int = _WRAP_REPEAT
    wrap_t: int = _WRAP_REPEAT
    mag_filter: int | None = None

    def sample(self, uv):
        """Filtered texels at texture coordinates uv (N, 2) -> (N, 4).  Texel (row i,
        column j) has its centre at u = (j + 0.5) / W, v = (i + 0.5) / H (glTF: the
        first texel is the upper left corner of the image; texel selection and
        weights: :func:`pbrkit.core.filtering.texel_pair`, nearest:
        :func:`~pbrkit.core.filtering.wrap_texel`)."""
        h, w = self.texels.shape[:2]
        x = uv[:, 0] * w
        y = uv[:, 1] * h
        if self.mag_filter == _FILTER_NEAREST:
            j = wrap_texel(floor_int(x), w, self.wrap_s)
            i = wrap_texel(floor_int(y), h, self.wrap_t)
            return self.texels[i, j].astype(np.float64)
        j0, j1, fx = texel_pair(x - 0.5, w, self.wrap_s)
        i0, i1, fy = texel_pair(y - 0.5, h, self.wrap_t)
        fx = fx[:, None]
        fy = fy[:, None]
        t = self.texels
        return ((t[i0, j0] * (1 - fx) + t[i0, j1] * fx) * (1 - fy)
                + (t[i1, j0] * (1 - fx) + t[i1, j1] * fx) * fy).astype(np.float64)


@dataclass(frozen=True)
class TextureRef:
    """A material's use of a texture: which one, which TEXCOORD set, the scale
    (normal) or strength (occlusion), and its ``KHR_texture_transform``
    (:class:`pbrkit.io.gltf_extensions.TextureTransform`; None: the UVs as they are)."""

    texture: int
    texcoord: int = 0
    scale: float = 1.0
    transform: object | None = None

    def lookup_uv(self, uv):
        """The texture coordinates at which to sample this texture for the
        interpolated coordinates ``uv`` (N, 2) of its TEXCOORD set: ``uv`` itself
        (the same array) without a transform."""
        return uv if self.transform is None else self.transform.apply(uv)


@dataclass
class SurfaceMaterial:
    """A material as the renderer uses it: the :class:`pbrkit.rendering.scene.MaterialSpec`
    (factors, model and terms) and optional glTF textures."""

    spec: MaterialSpec
    base_color_texture: TextureRef | None = None
    metallic_roughness_texture: TextureRef | None = None
    normal_texture: TextureRef | None = None
    occlusion_texture: TextureRef | None = None
    emissive_texture: TextureRef | None = None
    textures: list | None = None  # the Texture objects the refs index
    #: glTF's alphaMode (OPAQUE, MASK, BLEND), alphaCutoff, baseColorFactor's alpha and the
    #: texture whose alpha channel multiplies it (the baseColorTexture; :mod:`pbrkit.rendering.alpha`)
    alpha_mode: str = "OPAQUE"
    alpha_cutoff: float = 0.5
    alpha: float = 1.0
    alpha_texture: TextureRef | None = None
    #: the KHR_materials extension textures: (use, TextureRef) with ``use`` a row of
    #: :data:`pbrkit.io.gltf_materials.TEXTURE_USES`
    extension_textures: tuple = ()
    #: KHR_materials_unlit: the base colour shows as emission (vertex colours multiply it there)
    unlit: bool = False

    @property
    def textured(self):
        return bool(self.extension_textures) or any(
            r is not None for r in (self.base_color_texture, self.metallic_roughness_texture, self.normal_texture,
                                    self.occlusion_texture, self.emissive_texture))




def tangent_space_normal(texel, scale, n, tangents, has_tangent):
    """The normals (N, 3) a normal texture gives: the texels' RGB (N, >= 3) as (2 RGB - 1)
    with x, y times ``scale`` in the tangent space (T, B, N) of unit normals ``n`` (N, 3)
    and tangents ``tangents`` (N, 4: T and the handedness w of B = w (N x T)), T made
    orthogonal to N, normalised (glTF 2.0 specification, "Materials", normalTexture and
    normalTextureInfo.scale; the same for KHR_materials_clearcoat's clearcoatNormalTexture).
    ``n`` itself where a hit has no tangent (``has_tangent`` False) or the texel maps to 0."""
    c = np.array(texel[:, :3], dtype=np.float64) * 2.0 - 1.0
    c[:, :2] *= scale
    tt = tangents[:, :3]
    tt = tt - np.sum(tt * n, axis=1, keepdims=True) * n
    tt = tt / np.maximum(np.linalg.norm(tt, axis=1, keepdims=True), 1e-300)
    bb = np.cross(n, tt) * np.where(tangents[:, 3:4] < 0.0, -1.0, 1.0)  # w's sign (glTF: +-1)
    mapped = c[:, 0:1] * tt + c[:, 1:2] * bb + c[:, 2:3] * n
    length = np.linalg.norm(mapped, axis=1, keepdims=True)
    ok = has_tangent[:, None] & (length > 1e-12)
    return np.where(ok, mapped / np.maximum(length, 1e-300), n)
