"""The models' parameter declarations and what is generated from them: every
declared parameter is accepted by pbrkit.Material, by scene files and by the
explorer, every out-of-range value is refused with one line naming the key,
the packed layout holds every parameter once, and the documentation's table
is the declarations' (docs/materials.md)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import numpy as np
import pytest

from pbrkit import Material
from pbrkit.brdf.parameters import Choice, Parameter
from pbrkit.brdf.shading.registry import LAYOUT, PARAMETERS, REGISTERED, parameters_markdown
from pbrkit.explore import views
from pbrkit.rendering.scene import scene_from_dict

ROOT = Path(__file__).resolve().parents[2]


def _inside(p):
    """A value inside the declaration's range other than its default."""
    value = p.low + 0.37 * (p.high - p.low) if np.isfinite(p.high) else p.low + 0.5
    value = min(value, 0.9) if p.high <= 1.0 else value
    if np.isscalar(p.default) and value == p.default:  # (glTF's ior: 1.5 = 1 + 0.5)
        value = p.low + 0.25
    return (value, value * 0.9, value * 0.8) if p.channels == 3 else value


def _outside(p):
    value = p.high + 0.5
    return (0.1, value, 0.1) if p.channels == 3 else value


def _declared():
    return [(m.name, p) for m in REGISTERED for p in m.parameters]


def _scene(material):
    return {"materials": {"m": material}, "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1.0,
                                                       "material": "m"}]}


def _with_companions(p):
    """The keys a parameter needs beside it: eta and k go together."""
    if p.name in ("eta", "k"):
        other = "k" if p.name == "eta" else "eta"
        return {other: _inside(next(q for q in PARAMETERS if q.name == other))}
    return {}


@pytest.mark.parametrize("model, p", _declared(), ids=[f"{m}-{p.name}" for m, p in _declared()])
def test_every_declared_parameter_is_accepted_everywhere(model, p):
    if isinstance(p, Choice):
        for value in p.choices:
            extra = {"conductor": "gold"} if value == "exact-conductor" else {}
            scene = scene_from_dict(_scene({"model": model, p.name: value, **extra}))
            assert getattr(scene.materials["m"], p.name) == value
        assert views.model_brdf(model, **{p.name: p.choices[-1]}).spec.model == model
        return
    value = _inside(p)
    extra = _with_companions(p)
    material = Material(**{p.name: np.asarray(value)}, **{k: np.asarray(v) for k, v in extra.items()})
    np.testing.assert_allclose(getattr(material, p.name), value)
    as_list = list(value) if p.channels == 3 else value
    scene = scene_from_dict(_scene({"model": model, p.name: as_list,
                                    **{k: list(v) for k, v in extra.items()}}))
    np.testing.assert_allclose(getattr(scene.materials["m"], p.name), value)
    if p.name in ("base_color", "metallic", "roughness"):
        brdf = views.model_brdf(model, **{p.name: value})
    else:
        brdf = views.model_brdf(model, **{p.name: value}, **extra)
    np.testing.assert_allclose(getattr(brdf.material, p.name), value)


@pytest.mark.parametrize("model, p", [(m, p) for m, p in _declared() if isinstance(p, Parameter)],
                         ids=[f"{m}-{p.name}" for m, p in _declared() if isinstance(p, Parameter)])
def test_every_out_of_range_value_is_refused_with_one_line_naming_the_key(model, p):
    bad = _outside(p)
    extra = _with_companions(p)
    shared = next(q for q in PARAMETERS if q.name == p.name)  # Material knows no model: the widest range
    with pytest.raises(ValueError) as error:
        Material(**{p.name: np.asarray(_outside(shared))}, **{k: np.asarray(v) for k, v in extra.items()})
    assert f"Material.{p.name}" in str(error.value) and "\n" not in str(error.value)
    as_list = list(bad) if p.channels == 3 else bad
    with pytest.raises(ValueError) as error:
        scene_from_dict(_scene({"model": model, p.name: as_list, **{k: list(v) for k, v in extra.items()}}))
    assert p.name in str(error.value) and "\n" not in str(error.value)
    with pytest.raises(ValueError) as error:
        views.model_brdf(model, **{p.name: bad}, **extra)
    assert p.name in str(error.value) and "\n" not in str(error.value)


@pytest.mark.parametrize("m", REGISTERED, ids=[m.name for m in REGISTERED])
def test_a_parameter_the_model_lacks_or_its_narrower_range_is_refused(m):
    declared = {p.name for p in m.parameters}
    for p in PARAMETERS:
        if p.name in declared:
            continue
        value = p.choices[-1] if isinstance(p, Choice) else _inside(p)
        value = list(value) if isinstance(value, tuple) else value
        names = "|".join([p.name, *_with_companions(p)])  # (eta and k go together)
        with pytest.raises(ValueError, match=f"material 'm': ({names}) ") as error:
            scene_from_dict(_scene({"model": m.name, p.name: value, **{k: list(v) for k, v in
                                                                         _with_companions(p).items()}}))
        assert "\n" not in str(error.value)
    for p in m.numbers:  # the model's own range where it narrows the shared one
        shared = next(q for q in PARAMETERS if q.name == p.name)
        if shared.low < p.low:
            with pytest.raises(ValueError, match=f"{p.name} must be in .* for model '{m.name}'"):
                scene_from_dict(_scene({"model": m.name, p.name: 0.5 * (shared.low + p.low)}))


def test_unknown_choices_are_refused():
    with pytest.raises(ValueError, match="unknown diffuse 'oren-nayar'; choose one of lambert, burley, none, eon"):
        scene_from_dict(_scene({"model": "cook_torrance", "diffuse": "oren-nayar"}))
    with pytest.raises(ValueError, match="unknown model 'phong'"):
        scene_from_dict(_scene({"model": "phong"}))


def test_the_packed_layout_holds_every_parameter_once():
    columns = []
    for p in LAYOUT.parameters:
        start = getattr(LAYOUT.columns, p.name)
        columns += list(range(start, start + p.channels))
    assert sorted(columns) == list(range(LAYOUT.size))
    assert {p.name for p in PARAMETERS if isinstance(p, Parameter)} <= set(LAYOUT.by_name)
    row = LAYOUT.row({"sheen": 0.25, "specular_color": (0.1, 0.2, 0.3), "eta": None})[0]
    assert row[LAYOUT.columns.sheen] == 0.25
    assert list(row[LAYOUT.columns.specular_color:LAYOUT.columns.specular_color + 3]) == [0.1, 0.2, 0.3]
    assert row[LAYOUT.columns.roughness] == 0.5 and not row[LAYOUT.columns.eta:LAYOUT.columns.eta + 3].any()


def test_the_documentation_table_is_the_declarations():
    text = (ROOT / "docs" / "materials.md").read_text()
    generated = text.split("<!-- generated: begin -->\n", 1)[1].split("<!-- generated: end -->", 1)[0]
    assert generated == parameters_markdown(), "docs/materials.md is stale: regenerate it (its header says how)"
    for m in REGISTERED:
        section = generated.split(f"### `{m.name}`", 1)[1].split("### ", 1)[0]
        rows = re.findall(r"^\| `([a-z_0-9]+)` \|", section, flags=re.MULTILINE)
        assert rows == [p.name for p in m.parameters]


def test_the_explorer_controls_are_the_declarations():
    """Every scalar parameter of a model is a control of the explorer, but those that do not
    change its BRDF (the volume's, the thin film's minimum thickness: views.NOT_REFLECTION,
    each a declared parameter)."""
    assert set(views.NOT_REFLECTION) <= {p.name for p in PARAMETERS}
    for m in REGISTERED:
        scalars = [p.name for p in m.numbers if p.channels == 1 and p.name not in ("metallic", "roughness")
                   and p.name not in views.NOT_REFLECTION]
        assert list(views.MODEL_PARAMETERS[m.name]) == scalars
    for name, (low, high, default) in views.PARAMETER_RANGES.items():
        p = next(q for q in PARAMETERS if q.name == name)
        assert (low, high, default) == (p.low, p.high, p.default)


def test_no_model_branch_outside_the_generated_dispatch():
    """No source compares a model code (``b.model == ...``, ``MODEL_*`` constants) or a
    model's name in compiled code: the models are reached through the dispatch generated
    from the registry (pbrkit.brdf.dispatch)."""
    offenders = []
    for path in (ROOT / "src" / "pbrkit").rglob("*.py"):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.Name) and re.fullmatch(r"MODEL_[A-Z0-9_]+", node.id) and node.id not in (
                    "MODEL_TERMS", "MODEL_PARAMETERS"):
                offenders.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.id}")
            if isinstance(node, ast.Compare):
                for side in [node.left, *node.comparators]:
                    if isinstance(side, ast.Attribute) and side.attr == "model" and isinstance(side.value, ast.Name) \
                            and side.value.id == "b":
                        offenders.append(f"{path.relative_to(ROOT)}:{node.lineno} b.model comparison")
    assert offenders == []
