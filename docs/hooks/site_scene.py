"""The scene-file reference page (``reference/scene.md``), generated from the scene
parser's own declarations so that it cannot go stale:

- the sections and each section's keys (per object and light type): the key sets
  :func:`pbrkit.rendering.scene.scene_from_dict` checks
  (:mod:`pbrkit.rendering.scene_checks`), and for ``[style]`` the fields of
  :class:`pbrkit.npr.style.Style`;
- what each value must be: the phrase of its check (the phrase the one-line
  errors print), the term and model names of their tables;
- defaults: the fields of the dataclasses the parser builds (``Camera``,
  ``EnvironmentSpec``, ``MaterialSpec``, ``Sphere``, ``Plane``, ``GltfObject``,
  ``Light``, ``AreaLight``, ``Style``);
- the material keys' meaning and models from the models' declarations
  (:mod:`pbrkit.brdf.parameters`); the other keys' meaning from the comments of
  the example in the module docstrings of :mod:`pbrkit.rendering.scene` and
  :mod:`pbrkit.npr.style`, which the page also shows."""

from __future__ import annotations

import dataclasses
import inspect
import re

_SECTION = re.compile(r"^\s*\[\[?(?P<name>[a-z_]+)(?:\.[^\]]*)?\]\]?\s*(?:#.*)?$")
_KEY_LINE = re.compile(r"^\s*#?\s*(?P<key>[a-z_]+)\s*=\s*(?P<value>.*?)\s*(?:#\s*(?P<comment>.*))?$")
_TYPE_LINE = re.compile(r'^\s*type\s*=\s*"(?P<type>[a-z_]+)"')


def _example(module):
    """The indented TOML example (after ``::``) of a module docstring, dedented."""
    doc = inspect.getdoc(module) or ""
    _, marker, rest = doc.partition("::\n")
    if not marker:
        return ""
    lines = []
    for line in rest.splitlines():
        if line.strip() and not line.startswith("    "):
            break
        lines.append(line[4:])
    return "\n".join(lines).strip("\n")


def _comments(example):
    """{(section, type or None, key): the comment on the key's line} of an example."""
    found = {}
    section, kind = "", None
    for line in example.splitlines():
        match = _SECTION.match(line)
        if match:
            section, kind = match.group("name"), None
            if "#" in line:  # the section's own comment
                found.setdefault((section, None, ""), line.split("#", 1)[1].strip())
            continue
        match = _TYPE_LINE.match(line)
        if match:
            kind = match.group("type")
        match = _KEY_LINE.match(line)
        if match and match.group("comment"):
            found.setdefault((section, kind, match.group("key")), match.group("comment").strip())
            found.setdefault((section, None, match.group("key")), match.group("comment").strip())
    return found


def _cell(text):
    text = str(text).replace("|", "\\|")
    return text.replace("<", "&lt;").replace(">", "&gt;")


def _value(value):
    """A default as a scene file writes it (TOML)."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "`true`" if value else "`false`"
    if isinstance(value, str):
        return f'`"{value}"`'
    if isinstance(value, (tuple, list)):
        return "`[" + ", ".join(f"{float(x):g}" for x in value) + "]`"
    if isinstance(value, float):
        return f"`{value:g}`"
    return f"`{value}`"


def _defaults(cls):
    """{field: its default (None where it has none)} of a dataclass."""
    out = {}
    for f in dataclasses.fields(cls):
        if f.default is not dataclasses.MISSING:
            out[f.name] = f.default
        elif f.default_factory is not dataclasses.MISSING:
            out[f.name] = f.default_factory()
        else:
            out[f.name] = dataclasses.MISSING
    return out


def _ordered(keys, cls):
    """``keys`` in the order of ``cls``'s fields (the others after them, sorted)."""
    order = [f.name for f in dataclasses.fields(cls)]
    return sorted(keys, key=lambda k: (order.index(k) if k in order else len(order), k))


#: What a field of a given annotation takes, where no check declares a phrase (the
#: ``[style]`` keys, whose ranges :class:`pbrkit.npr.style.Style` checks inline).
_ANNOTATIONS = {"float": "a number", "int": "an integer", "bool": "true or false", "str": "a string",
                "tuple": "a list of numbers", "str | None": "a string", "tuple | None": "a list of numbers"}


def _table(keys, cls, phrases, notes, choices=None, extra=None):
    """A Markdown table of ``keys``: value (``choices[key]`` listed, else the check's
    phrase), default (``cls``'s field; "required" where it has none) and meaning."""
    defaults = _defaults(cls) if cls is not None else {}
    choices = choices or {}
    lines = ["| key | value | default | meaning |", "|---|---|---|---|"]
    for key in (_ordered(keys, cls) if cls is not None else sorted(keys)):
        if key in choices:
            value = "one of " + ", ".join(f"`{c}`" for c in choices[key])
        else:
            check = phrases.get(key)
            if check is None and cls is not None:
                check = _ANNOTATIONS.get(str({f.name: f.type for f in dataclasses.fields(cls)}.get(key)), "")
            value = _cell(check.phrase if hasattr(check, "phrase") else (check or ""))
        default = defaults.get(key)
        default = "required" if default is dataclasses.MISSING else _value(default)
        meaning = (extra or {}).get(key) or notes(key) or ""
        lines.append(f"| `{key}` | {value} | {default} | {_cell(meaning)} |")
    return lines + [""]


def page():
    """The Markdown of ``reference/scene.md``."""
    from pbrkit.brdf.fresnel import CONDUCTORS
    from pbrkit.brdf.shading.registry import MODELS, REGISTERED
    from pbrkit.npr import style as style_module
    from pbrkit.rendering import scene as scene_module
    from pbrkit.rendering import scene_checks as sc
    from pbrkit.rendering.area_lights import AREA_LIGHT_TYPES, AREA_UNITS, AreaLight
    from pbrkit.rendering.lights import FALLOFFS, LIGHT_TYPES, Light
    from pbrkit.rendering.material_spec import CHOICES, NUMBERS, MaterialSpec, models_with

    example = _example(scene_module)
    notes = _comments(example)
    style_example = _example(style_module)
    style_notes = _comments(style_example)

    def note(section, kind=None):
        """A key's comment in the example: of its section, or for a type of object or
        light of that type, or of another type's line where the comment names this one
        ("centre (rect, disk, sphere)")."""
        if kind is None:
            return lambda key: notes.get((section, None, key))

        def lookup(key):
            own = notes.get((section, kind, key))
            if own:
                return own
            return next((text for (s, k, name), text in notes.items() if s == section and k not in (None, kind)
                         and name == key and re.search(rf"\b{kind}\b", text)), None)

        return lookup

    lines = ["# Scene files", "",
             "Generated from the scene parser when the site is built (`docs/hooks/site_scene.py`): "
             "the sections and keys `pbrkit.rendering.scene.scene_from_dict` accepts, what each value "
             "must be (the phrase its one-line error prints), the defaults of the objects it builds, and "
             "the material keys of every shading model's declaration.  A scene file is TOML or JSON "
             "(the same structure); relative paths are relative to its folder; a key not listed here "
             "is refused with one line naming it.", "",
             "Sections: " + ", ".join(f"`{s}`" for s in sorted(sc._SECTIONS)) + ".", "",
             "## Example", "",
             "From the docstring of `pbrkit.rendering.scene`:", "", "```toml", example, "```", ""]

    lines += ["## `allow_roots`", "",
              "A list of folder paths, each " + sc._STRING.phrase + ": folders besides a glTF model's own "
              "that its buffer and image URIs may name (`pbrkit render --allow-root`).", ""]

    lines += ["## `[camera]`", ""]
    lines += _table(sc._CAMERA_KEYS, scene_module.Camera, sc._CAMERA_VALUES, note("camera"))

    lines += ["## `[environment]`", "", _cell(notes.get(("environment", None, ""), "")), ""]
    lines += _table(sc._ENV_KEYS, scene_module.EnvironmentSpec, sc._ENV_VALUES, note("environment"))

    lines += ["## `[materials.<name>]`", "",
              "One table per material, named by the objects' `material` key (`default` is always there: "
              "the `gltf` model's defaults).  The numeric keys and term choices are the shading models' "
              "declared parameters (their ranges per model: [Materials](../materials.md)); a key the "
              "material's model does not declare must keep its default.", ""]
    model_notes = {p.name: f"{p.doc} (models {models_with(p.name)})" for p in NUMBERS + CHOICES}
    model_notes["model"] = "the shading model (below)"
    material_choices = {"model": MODELS, "conductor": tuple(sorted(CONDUCTORS)),
                        **{c.name: c.choices for c in CHOICES}}
    lines += _table(sc._MATERIAL_KEYS, MaterialSpec, sc._MATERIAL_VALUES, note("materials"),
                    choices=material_choices, extra=model_notes)
    lines += ["The models (`pbrkit.brdf.shading.registry`):", ""]
    lines += [f"- `{m.name}`: {_cell(m.doc)}" for m in REGISTERED] + [""]

    lines += ["## `[[objects]]`", "",
              "An array of tables, each with a `type`: " + ", ".join(f"`{t}`" for t in sc._OBJECT_KEYS) + ".", ""]
    for kind, keys in sc._OBJECT_KEYS.items():
        cls = scene_module._OBJECT_TYPES[kind]
        lines += [f"### `type = \"{kind}\"`", ""]
        doc = inspect.getdoc(cls)
        if doc and not doc.startswith(cls.__name__ + "("):
            lines += [_cell(" ".join(doc.split())), ""]
        lines += _table(keys - {"type"}, cls, sc._OBJECT_VALUES, note("objects", kind))

    lines += ["## `[[lights]]`", "",
              "An array of tables, each with a `type`: the punctual lights of `KHR_lights_punctual` ("
              + ", ".join(f"`{t}`" for t in LIGHT_TYPES) + ") and the area lights ("
              + ", ".join(f"`{t}`" for t in AREA_LIGHT_TYPES) + ").", ""]
    for kind, keys in sc._LIGHT_KEYS.items():
        lines += [f"### `type = \"{kind}\"`", ""]
        lines += _table(keys - {"type"}, Light, sc._LIGHT_VALUES, note("lights", kind),
                        choices={"falloff": FALLOFFS})
    for kind, keys in sc._AREA_LIGHT_KEYS.items():
        lines += [f"### `type = \"{kind}\"`", ""]
        lines += _table(keys - {"type"}, AreaLight, sc._AREA_LIGHT_VALUES, note("lights", kind),
                        choices={"unit": AREA_UNITS})

    style_choices = {"shading": style_module.SHADINGS, "lighting": style_module.LIGHTINGS,
                     "outline": style_module.OUTLINES, "hatching_space": style_module.HATCHING_SPACES,
                     "outline_width_mode": style_module.OUTLINE_WIDTH_MODES}
    alternatives = "; ".join(f"`{a}` or `{b}`" for a, b in style_module.EXCLUSIVE)
    lines += ["## `[style]`", "",
              "A non-photorealistic style for the real-time image (`pbrkit.npr.style`; a style file "
              "holds the same table, `pbrkit render --style FILE`; presets: "
              + ", ".join(f"`{name}`" for name in style_module.STYLE_PRESETS) + ").  Alternatives, "
              f"refused together: {alternatives}.", ""]
    lines += _table(style_module._KEYS, style_module.Style, {}, lambda key: style_notes.get(("style", None, key)),
                    choices=style_choices)
    lines += ["From the docstring of `pbrkit.npr.style`:", "", "```toml", style_example, "```", ""]
    return "\n".join(lines) + "\n"
