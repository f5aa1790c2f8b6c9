"""Shared test helper: random inputs of the glTF model with KHR_materials_ior, _specular,
_clearcoat and _sheen, the Material they make, and the sheen table the independent
transcription (reference_brdf.gltf_khr_brdf) reads."""

from __future__ import annotations

import numpy as np
from model_values import N_DIR

from pbrkit import Material
from pbrkit.brdf.lobes.sheen import SHEEN_TABLE_FILE

#: Rows of a case.
N = 400
TABLE = np.load(SHEEN_TABLE_FILE)
KEYS = ("base", "metallic", "roughness", "sheen_color", "sheen_roughness", "clearcoat", "clearcoat_roughness",
        "specular", "specular_color", "ior")


def unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def khr_case(seed, n=N):
    """``n`` random inputs of the glTF model with KHR_materials_ior, _specular, _clearcoat and
    _sheen (values by KEYS, light and view directions; some at the edges: metallic 0,
    specular 1, ior 0, v = n, directions below the horizon) from ``seed``."""
    rng = np.random.default_rng(seed)
    u = rng.uniform
    values = dict(base=u(0.0, 1.0, (n, 3)), metallic=u(0.0, 1.0, n), roughness=u(0.05, 1.0, n),
                  sheen_color=u(0.0, 1.0, (n, 3)) * (rng.random((n, 1)) < 0.5), sheen_roughness=u(0.0, 1.0, n),
                  clearcoat=u(0.0, 1.0, n) * (rng.random(n) < 0.7), clearcoat_roughness=u(0.0, 1.0, n),
                  specular=u(0.0, 1.0, n), specular_color=u(0.0, 3.0, (n, 3)), ior=u(1.0, 3.0, n))
    values["metallic"][rng.random(n) < 0.2] = 0.0
    values["specular"][rng.random(n) < 0.1] = 1.0
    values["ior"][rng.random(n) < 0.05] = 0.0  # the specular-glossiness conversion's ior 0 (f0 = 1)
    v = unit(rng.normal(size=(n, 3)))
    v[:, 2] = np.abs(v[:, 2])
    v[rng.random(n) < 0.1] = N_DIR
    v[rng.random(n) < 0.05, 2] *= -1.0
    l = unit(rng.normal(size=(n, 3)))
    l[:, 2] = np.abs(l[:, 2])
    l[rng.random(n) < 0.05, 2] *= -1.0
    return values, l, v


def khr_material(values):
    """The pbrkit.Material of :func:`khr_case`'s values."""
    return Material(base_color=values["base"], metallic=values["metallic"], roughness=values["roughness"],
                    sheen_color=values["sheen_color"], sheen_roughness=values["sheen_roughness"],
                    clearcoat=values["clearcoat"], clearcoat_roughness=values["clearcoat_roughness"],
                    specular=values["specular"], specular_color=values["specular_color"], ior=values["ior"])
