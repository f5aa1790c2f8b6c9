"""The ``KHR_materials_*`` extensions of a glTF 2.0 material as the ``gltf``
model's parameters (:mod:`pbrkit.brdf.shading.gltf`): one table row per factor,
read from the extensions' READMEs in the Khronos glTF repository
(``extensions/2.0/Khronos/KHR_materials_<name>/README.md``, "Properties"):

======================  ==========================  =================  ===========  =========
extension               property                    parameter          range        default
======================  ==========================  =================  ===========  =========
KHR_materials_sheen     sheenColorFactor            sheen_color        [0, 1]^3     0
KHR_materials_sheen     sheenRoughnessFactor        sheen_roughness    [0, 1]       0
KHR_materials_clearcoat clearcoatFactor             clearcoat          [0, 1]       0
KHR_materials_clearcoat clearcoatRoughnessFactor    clearcoat_roughness [0, 1]      0
KHR_materials_specular  specularFactor              specular           [0, 1]       1
KHR_materials_specular  specularColorFactor         specular_color     [0, inf)^3   1
KHR_materials_ior       ior                         ior                0 or >= 1    1.5
KHR_materials_iridescence iridescenceFactor         iridescence        [0, 1]       0
KHR_materials_iridescence iridescenceIor            iridescence_ior    >= 1         1.3
KHR_materials_iridescence iridescenceThicknessMinimum iridescence_thickness_minimum >= 0 100
KHR_materials_iridescence iridescenceThicknessMaximum iridescence_thickness_maximum >= 0 400
KHR_materials_transmission transmissionFactor       transmission       [0, 1]       0
KHR_materials_volume    thicknessFactor             thickness          [0, inf)     0
KHR_materials_volume    attenuationDistance         attenuation_distance (0, inf)   +inf (0)
KHR_materials_volume    attenuationColor            attenuation_color  [0, 1]^3     1
KHR_materials_anisotropy anisotropyStrength         anisotropy_strength [0, 1]      0
KHR_materials_anisotropy anisotropyRotation         anisotropy_rotation any (wrapped to [-pi, pi]) 0
KHR_materials_dispersion dispersion                 dispersion         [0, inf)     0
======================  ==========================  =================  ===========  =========

(:data:`FACTORS`), and each extension's textures (:data:`TEXTURES`), checked like
every textureInfo and applied per shading point as :data:`TEXTURE_USES` says (the
READMEs' channels: a factor times a channel, the thin film's thickness mixed
between its minimum and maximum, the anisotropy direction turned by the texture's
and its strength scaled, the clear coat's normal from its clearcoatNormalTexture).
attenuationDistance's default +Infinity
is the parameter's 0 (JSON has no infinity; glTF's range excludes 0).  ``KHR_materials_unlit`` (its README,
"Implementation") renders the base colour as emission and no reflection
(:func:`unlit_material`).
"""

from __future__ import annotations

import math

from .gltf_extensions import check_texture_info
from .gltf_fields import _number, _numbers, _object

__all__ = ["FACTORS", "TEXTURES", "TEXTURE_USES", "UNLIT", "MATERIAL_EXTENSIONS", "check_material_extensions",
           "material_extension_values", "unlit_material"]

#: (extension, property, parameter, components, low, high, default) of every factor.
FACTORS = (
    ("KHR_materials_sheen", "sheenColorFactor", "sheen_color", 3, 0.0, 1.0, (0.0, 0.0, 0.0)),
    ("KHR_materials_sheen", "sheenRoughnessFactor", "sheen_roughness", 1, 0.0, 1.0, 0.0),
    ("KHR_materials_clearcoat", "clearcoatFactor", "clearcoat", 1, 0.0, 1.0, 0.0),
    ("KHR_materials_clearcoat", "clearcoatRoughnessFactor", "clearcoat_roughness", 1, 0.0, 1.0, 0.0),
    ("KHR_materials_specular", "specularFactor", "specular", 1, 0.0, 1.0, 1.0),
    ("KHR_materials_specular", "specularColorFactor", "specular_color", 3, 0.0, None, (1.0, 1.0, 1.0)),
    ("KHR_materials_ior", "ior", "ior", 1, 0.0, None, 1.5),
    ("KHR_materials_iridescence", "iridescenceFactor", "iridescence", 1, 0.0, 1.0, 0.0),
    ("KHR_materials_iridescence", "iridescenceIor", "iridescence_ior", 1, 1.0, None, 1.3),
    ("KHR_materials_iridescence", "iridescenceThicknessMinimum", "iridescence_thickness_minimum", 1, 0.0, None,
     100.0),
    ("KHR_materials_iridescence", "iridescenceThicknessMaximum", "iridescence_thickness_maximum", 1, 0.0, None,
     400.0),
    ("KHR_materials_transmission", "transmissionFactor", "transmission", 1, 0.0, 1.0, 0.0),
    ("KHR_materials_volume", "thicknessFactor", "thickness", 1, 0.0, None, 0.0),
    ("KHR_materials_volume", "attenuationDistance", "attenuation_distance", 1, 0.0, None, 0.0),
    ("KHR_materials_volume", "attenuationColor", "attenuation_color", 3, 0.0, 1.0, (1.0, 1.0, 1.0)),
    ("KHR_materials_anisotropy", "anisotropyStrength", "anisotropy_strength", 1, 0.0, 1.0, 0.0),
    ("KHR_materials_anisotropy", "anisotropyRotation", "anisotropy_rotation", 1, None, None, 0.0),
    ("KHR_materials_dispersion", "dispersion", "dispersion", 1, 0.0, None, 0.0),
)
#: The textureInfos of each extension (checked, and applied as :data:`TEXTURE_USES` says).
TEXTURES = {
    "KHR_materials_sheen": ("sheenColorTexture", "sheenRoughnessTexture"),
    "KHR_materials_clearcoat": ("clearcoatTexture", "clearcoatRoughnessTexture", "clearcoatNormalTexture"),
    "KHR_materials_specular": ("specularTexture", "specularColorTexture"),
    "KHR_materials_ior": (),
    "KHR_materials_iridescence": ("iridescenceTexture", "iridescenceThicknessTexture"),
    "KHR_materials_transmission": ("transmissionTexture",),
    "KHR_materials_volume": ("thicknessTexture",),
    "KHR_materials_anisotropy": ("anisotropyTexture",),
    "KHR_materials_dispersion": (),
}
#: How each extension texture changes its parameter per shading point (the READMEs,
#: "Properties"): (extension, textureInfo key, sRGB, operation, parameter, channels), the
#: operations ``scale`` (the factor times the channels: RGB or one of R, G, B, A = 0..3),
#: ``thickness`` (KHR_materials_iridescence: thickness = mix(minimum, maximum, G)),
#: ``anisotropy`` (KHR_materials_anisotropy: strength times B, the direction (R, G) 2 - 1
#: turned by the rotation) and ``coat_normal`` (KHR_materials_clearcoat: the coat's own
#: normal, a normal texture with its ``scale`` in the mesh's tangent space,
#: :func:`pbrkit.rendering.textures.tangent_space_normal`).
TEXTURE_USES = (
    ("KHR_materials_sheen", "sheenColorTexture", True, "scale", "sheen_color", (0, 1, 2)),
    ("KHR_materials_sheen", "sheenRoughnessTexture", False, "scale", "sheen_roughness", (3,)),
    ("KHR_materials_clearcoat", "clearcoatTexture", False, "scale", "clearcoat", (0,)),
    ("KHR_materials_clearcoat", "clearcoatRoughnessTexture", False, "scale", "clearcoat_roughness", (1,)),
    ("KHR_materials_specular", "specularTexture", False, "scale", "specular", (3,)),
    ("KHR_materials_specular", "specularColorTexture", True, "scale", "specular_color", (0, 1, 2)),
    ("KHR_materials_iridescence", "iridescenceTexture", False, "scale", "iridescence", (0,)),
    ("KHR_materials_iridescence", "iridescenceThicknessTexture", False, "thickness", "iridescence_thickness_maximum",
     (1,)),
    ("KHR_materials_transmission", "transmissionTexture", False, "scale", "transmission", (0,)),
    ("KHR_materials_volume", "thicknessTexture", False, "scale", "thickness", (1,)),
    ("KHR_materials_anisotropy", "anisotropyTexture", False, "anisotropy", "anisotropy_strength", (0, 1, 2)),
    ("KHR_materials_clearcoat", "clearcoatNormalTexture", False, "coat_normal", "coat_normal", (0, 1, 2)),
)
UNLIT = "KHR_materials_unlit"
#: The material extensions pbrkit reads (an ``extensionsRequired`` entry it honours).
MATERIAL_EXTENSIONS = tuple(TEXTURES) + (UNLIT,)


def check_material_extensions(ext, where, index):
    """Check the ``KHR_materials_*`` objects of a material's ``extensions`` (``where``
    its JSON location): each an object, every factor a finite number (or array) in its
    range, KHR_materials_ior's ior 0 or at least 1, KHR_materials_volume's
    attenuationDistance above 0, every texture a textureInfo.
    ``ValueError`` of one line naming the field."""
    for name, textures in TEXTURES.items():
        if ext.get(name) is None:
            continue
        w = f"{where}.{name}"
        obj = _object(ext[name], w)
        for extension, key, _, n, lo, hi, _ in FACTORS:
            if extension != name or obj.get(key) is None:
                continue
            if n == 1:
                _number(obj[key], f"{w}.{key}", lo, hi)
            else:
                _numbers(obj[key], f"{w}.{key}", n, lo, hi)
        if name == "KHR_materials_ior" and obj.get("ior") is not None and 0.0 < obj["ior"] < 1.0:
            raise ValueError(f"{w}.ior must be 0 or at least 1; got {obj['ior']}")
        if name == "KHR_materials_volume" and obj.get("attenuationDistance") == 0:
            raise ValueError(f"{w}.attenuationDistance must be above 0; got 0")
        for key in textures:
            if obj.get(key) is not None:
                check_texture_info(obj[key], f"{w}.{key}", index)
        if name == "KHR_materials_clearcoat" and isinstance(obj.get("clearcoatNormalTexture"), dict) and \
                obj["clearcoatNormalTexture"].get("scale") is not None:  # a normalTextureInfo
            _number(obj["clearcoatNormalTexture"]["scale"], f"{w}.clearcoatNormalTexture.scale")
    if ext.get(UNLIT) is not None:
        _object(ext[UNLIT], f"{where}.{UNLIT}")


def material_extension_values(ext, notes, index):
    """The ``gltf`` model's parameters of a (checked) material's ``extensions``: each
    factor present, or its default where its extension is present (:data:`FACTORS`);
    a note in ``notes`` per texture not applied (none today: every one of
    :data:`TEXTURES` has its :data:`TEXTURE_USES` row)."""
    values = {}
    for extension, key, parameter, n, _, _, default in FACTORS:
        obj = ext.get(extension)
        if obj is None:
            continue
        value = obj.get(key)
        if value is None:
            values[parameter] = default
        else:
            values[parameter] = float(value) if n == 1 else tuple(float(x) for x in value)
        if parameter == "anisotropy_rotation":  # any angle: the same direction in [-pi, pi]
            values[parameter] = math.remainder(values[parameter], 2.0 * math.pi)
    applied = {(e, k) for e, k, *_ in TEXTURE_USES}
    for name, textures in TEXTURES.items():
        obj = ext.get(name) or {}
        for key in textures:
            if obj.get(key) is not None and (name, key) not in applied:
                notes.append(f"material {index}: {name} {key} is not supported yet")
    return values


def unlit_material(base_color):
    """``KHR_materials_unlit``: the material's colour is its base colour, unlit (the
    README, "Implementation": ``color = baseColor``): in the ``gltf`` model, emission of
    the base colour (factor, and texture in the emissive slot) over a surface that
    reflects nothing (base colour black, metallic 0, specular 0).  Returns the
    MaterialSpec keywords."""
    return {"emissive": tuple(float(x) for x in base_color[:3]), "base_color": (0.0, 0.0, 0.0), "metallic": 0.0,
            "specular": 0.0}

