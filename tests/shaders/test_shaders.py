"""Shader code that matches the bake (issue 10): ``pbrkit shaders --target glsl``.

The files are written (atomically, deterministically, refusals as one line), every
function carries its citation and roughness remap, and -- in WebGL2, headless
Chromium through SwiftShader (``tests/engines/pages/shaders.js``) -- every
exported GLSL function is evaluated over a grid of inputs and compared with
pbrkit's own Python function at the same (float32) inputs.
"""

from __future__ import annotations

import importlib
import json
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from engine_pages import needs_engines, run_page
from shader_cases import (CUBE_LEVELS, CUBE_SIZE, WIDTH, N, Case, assert_cases_match, f32, random_alphas,
                          random_cosines, random_directions, random_units, vec4s)

from pbrkit import shaders
from pbrkit.brdf import diffuse, distributions, fresnel, masking, models
from pbrkit.brdf.bxdf import isotropic_cosines
from pbrkit.brdf.material import Material

ROOT = Path(__file__).resolve().parents[2]


# ------------------------------------------------------------------ files


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "pbrkit", "shaders", *args], capture_output=True, text=True,
                          timeout=120)


def test_write_shaders_files_and_manifest(tmp_path):
    out = tmp_path / "glsl"
    names = shaders.write_shaders(out)
    assert sorted(p.name for p in out.iterdir()) == sorted(names)
    assert set(names) == set(shaders.GLSL_FILES) | {"manifest.json"}
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["target"] == "glsl" and manifest["files"] == list(shaders.GLSL_FILES)
    listed = {f["name"] for f in manifest["functions"]}
    # every function defined in the files is listed, and nothing else
    defined = set()
    for name in shaders.GLSL_FILES:
        text = (out / name).read_text()
        assert not re.search(r"^\s*#version", text, re.M)  # the user adds the version line
        defined |= set(re.findall(r"^(?:float|vec[234]|mat[234]|pbrkit_Cosines)\s+(\w+)\s*\(", text, re.M))
    assert listed == defined
    for entry in manifest["functions"]:
        assert entry["source"] and entry["roughness"] and entry["summary"], entry["name"]
        assert entry["file"] in shaders.GLSL_FILES


def test_write_shaders_is_deterministic_and_refuses(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    shaders.write_shaders(a)
    shaders.write_shaders(b)
    for name in shaders.GLSL_FILES + ("manifest.json",):
        assert (a / name).read_bytes() == (b / name).read_bytes()
    with pytest.raises(ValueError, match="not empty"):
        shaders.write_shaders(a)
    (a / "keep.txt").write_text("x")
    shaders.write_shaders(a, force=True)  # replaces the folder
    assert not (a / "keep.txt").exists() and (a / "manifest.json").exists()
    with pytest.raises(ValueError, match="unknown shader target 'hlsl'"):
        shaders.write_shaders(tmp_path / "c", target="hlsl")
    assert not (tmp_path / "c").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a", "b"]  # no temporaries left


def test_cli_shaders(tmp_path):
    out = tmp_path / "out"
    done = _cli("--target", "glsl", "-o", str(out))
    assert done.returncode == 0, done.stderr
    assert (out / "pbrkit_brdf.glsl").read_bytes() == shaders.glsl_sources()["pbrkit_brdf.glsl"].encode()
    again = _cli("-o", str(out))
    assert again.returncode == 1 and again.stdout == ""
    assert again.stderr.strip().splitlines() == [f"pbrkit: error: {out}: directory exists and is not empty "
                                                 f"(use --force to replace it)"]
    blocker = tmp_path / "file"
    blocker.write_text("x")
    bad = _cli("-o", str(blocker / "sub"), "--force")
    assert bad.returncode == 1 and len(bad.stderr.strip().splitlines()) == 1
    assert bad.stderr.startswith(f"pbrkit: error: --out: {blocker / 'sub'}: its parent")
    target = _cli("--target", "hlsl", "-o", str(tmp_path / "x"))
    assert target.returncode == 1 and "choose one of glsl" in target.stderr
    assert not (tmp_path / "x").exists()
    helped = _cli("--help")
    assert helped.returncode == 0 and "[glsl]" in helped.stdout


def test_cli_choices_and_lazy_help():
    from pbrkit.cli import shaders as cli

    assert cli.SHADER_TARGETS == shaders.TARGETS
    code = ("import sys\nfrom pbrkit.cli import app\ntry:\n    app(['shaders', '--help'], prog_name='pbrkit')\n"
            "except SystemExit as exc:\n    assert exc.code in (0, None)\n"
            "print([m for m in ('numpy', 'numba', 'pbrkit.shaders') if m in sys.modules], file=sys.stderr)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and done.stderr.strip().splitlines()[-1] == "[]", done.stderr


def test_glsl_files_are_package_data():
    """Wheels carry the .glsl files only if pyproject lists them as package data."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    data = config["tool"]["setuptools"]["package-data"]
    patterns = data.get("pbrkit", []) + [f"shaders/{p}" for p in data.get("pbrkit.shaders", [])]
    assert any(Path("shaders/glsl/pbrkit_brdf.glsl").match(p) for p in patterns), patterns


def _docs(dotted):
    module_name, _, attribute = dotted.rpartition(".")
    module = importlib.import_module(module_name)
    obj = getattr(module, attribute)  # every named counterpart exists
    return (obj.__doc__ or "") + (module.__doc__ or "")


def test_comments_cite_what_the_python_docstrings_cite():
    """Each function's citation names authors the pbrkit counterpart's docstring (or its
    module's) also cites, and the roughness line states a remap or says there is none."""
    for entry in shaders.functions():
        docs = " ".join(_docs(d) for d in entry["pbrkit"])
        # the first name of each citation: "Walter et al. 2007, eq. 33; Karis 2013" -> Walter, Karis
        cited = [m.group(1) for m in (re.match(r"\s*([A-Z][\w\u00fc-]+|glTF)", piece)
                                      for piece in entry["source"].split(";")) if m]
        assert cited, (entry["name"], entry["source"])
        known = [name for name in cited if name in docs]
        assert known, (entry["name"], cited)
        assert re.search(r"alpha|roughness|\bk\b|exponent|none|r\b", entry["roughness"]), entry


# ------------------------------------------------------------------ numbers in WebGL2


def _scalar_cases(rng):
    cases = []
    add = cases.append
    r = f32(rng.uniform(0.0, 1.0, N))
    r[:3] = (0.0, 1.0, 0.01)
    add(Case("alpha", ("pbrkit_alphaFromRoughness",), "pbrkit_alphaFromRoughness(a.x)", [vec4s(r)],
             distributions.alpha_from_roughness(r)[:, None]))

    noh, alpha = random_cosines(rng, -0.2), random_alphas(rng)
    add(Case("D_GGX", ("D_GGX",), "D_GGX(a.x, a.y)", [vec4s(noh, alpha)], distributions.d_ggx(noh, alpha)[:, None]))
    noh, alpha = random_cosines(rng), random_alphas(rng, 0.05)
    add(Case("D_Beckmann", ("D_Beckmann",), "D_Beckmann(a.x, a.y)", [vec4s(noh, alpha)],
             distributions.d_beckmann(noh, alpha)[:, None], atol=1e-30))
    noh = random_cosines(rng)
    alpha = np.concatenate([np.exp(rng.uniform(np.log(1e-3), np.log(0.1), N // 2)), rng.uniform(0.5, 1.0, N // 2)])
    alpha[-4:] = (1.0, 0.999, 0.96, 0.94)
    alpha = f32(alpha)
    add(Case("D_GTR1", ("D_GTR1",), "D_GTR1(a.x, a.y)", [vec4s(noh, alpha)], distributions.d_gtr1(noh, alpha)[:, None]))
    noh, alpha = random_cosines(rng), f32(rng.uniform(0.1, 1.0, N))
    exponent = f32(distributions.phong_exponent_from_beckmann_alpha(alpha))
    add(Case("phong_exponent", ("pbrkit_phongExponentFromBeckmannAlpha",), "pbrkit_phongExponentFromBeckmannAlpha(a.x)",
             [vec4s(alpha)], distributions.phong_exponent_from_beckmann_alpha(alpha)[:, None], atol=1e-5))
    scale = distributions.d_blinn_phong(1.0, exponent)
    add(Case("D_BlinnPhong", ("D_BlinnPhong",), "D_BlinnPhong(a.x, a.y)", [vec4s(noh, exponent)],
             distributions.d_blinn_phong(noh, exponent)[:, None], atol=1e-6 * float(scale.max())))

    nox, alpha = random_cosines(rng), random_alphas(rng)
    add(Case("Lambda_GGX", ("Lambda_GGX",), "Lambda_GGX(a.x, a.y)", [vec4s(nox, alpha)],
             masking.lambda_ggx(nox, alpha)[:, None]))
    lam = f32(np.exp(rng.uniform(np.log(1e-6), np.log(50.0), (N, 2))))
    add(Case("G2", ("G2_Separable", "G2_HeightCorrelated"), "vec2(G2_Separable(a.x, a.y), G2_HeightCorrelated(a.x, a.y))",
             [vec4s(lam)], np.stack([masking.g2_separable(lam[:, 0], lam[:, 1]),
                                      masking.g2_height_correlated(lam[:, 0], lam[:, 1])], axis=1)))
    g2, nol, nov = f32(rng.uniform(0, 1, N)), random_cosines(rng, -0.2), random_cosines(rng, -0.2)[::-1]
    add(Case("visibility", ("pbrkit_visibility",), "pbrkit_visibility(a.x, a.y, a.z)", [vec4s(g2, nol, nov)],
             masking.visibility(g2, nol, nov)[:, None]))

    nol, nov, alpha = random_cosines(rng), random_cosines(rng)[rng.permutation(N)], random_alphas(rng)
    separable = masking.visibility(masking.g2_separable(masking.lambda_ggx(nol, alpha), masking.lambda_ggx(nov, alpha)),
                                   nol, nov)
    add(Case("V_Smith", ("V_SmithGGXCorrelated", "V_SmithGGX"),
             "vec2(V_SmithGGXCorrelated(a.x, a.y, a.z), V_SmithGGX(a.x, a.y, a.z))", [vec4s(nol, nov, alpha)],
             np.stack([masking.v_smith_ggx_height_correlated(nol, nov, alpha), separable], axis=1)))
    k = f32(rng.uniform(0.0, 0.5, N))
    k[:2] = (0.0, 0.5)
    add(Case("SchlickGGX", ("G1_SchlickGGX", "V_SchlickGGX"),
             "vec2(G1_SchlickGGX(a.x, a.z), V_SchlickGGX(a.x, a.y, a.z))", [vec4s(nol, nov, k)],
             np.stack([masking.g1_schlick_ggx(nol, k),
                       masking.visibility(masking.g2_schlick_ggx(nol, nov, k), nol, nov)], axis=1)))
    add(Case("k", ("pbrkit_kUE4Direct", "pbrkit_kUE4IBL"), "vec2(pbrkit_kUE4Direct(a.x), pbrkit_kUE4IBL(a.x))",
             [vec4s(r)], np.stack([masking.k_ue4_direct(r), masking.k_ue4_ibl(r)], axis=1), atol=1e-7))
    voh = random_cosines(rng, -0.2)
    add(Case("V_Kelemen_Neubelt", ("V_Kelemen", "V_Neubelt"), "vec2(V_Kelemen(a.x), V_Neubelt(a.y, a.z))",
             [vec4s(voh, nol, nov)], np.stack([masking.v_kelemen(voh), masking.v_neubelt(nol, nov)], axis=1)))

    cos = f32(rng.uniform(-0.1, 1.1, N))
    f0, f90 = f32(rng.uniform(0, 1, (N, 3))), f32(rng.uniform(0, 1, N))
    add(Case("F_Schlick", ("F_Schlick",), "vec4(F_Schlick(a.x, b.xyz, a.y), F_Schlick(a.x, b.w, a.y))",
             [vec4s(cos, f90), vec4s(f0, f0[:, 0])],
             np.concatenate([fresnel.f_schlick(cos[:, None], f0, f90[:, None]),
                             fresnel.f_schlick(cos, f0[:, 0], f90)[:, None]], axis=1), atol=1e-7))
    add(Case("F_SphericalGaussian", ("F_SphericalGaussian",),
             "vec4(F_SphericalGaussian(a.x, b.xyz), F_SphericalGaussian(a.x, b.w))", [vec4s(cos), vec4s(f0, f0[:, 0])],
             np.concatenate([fresnel.f_schlick_ue4_sg(cos[:, None], f0),
                             fresnel.f_schlick_ue4_sg(cos, f0[:, 0])[:, None]], axis=1), atol=1e-7))
    add(Case("F_SchlickRoughness", ("F_SchlickRoughness",), "vec4(F_SchlickRoughness(a.x, b.xyz, a.y), 0.0)",
             [vec4s(cos, r), vec4s(f0)], fresnel.f_schlick_roughness(cos[:, None], f0, r[:, None]), atol=1e-7))
    eta = f32(rng.uniform(0.5, 3.0, N))
    eta[:8] = (1.0, 1.5, 1.5, 0.66, 0.66, 1.33, 2.5, 0.9)
    cos = f32(rng.uniform(0.0, 1.0, N))
    cos[:8] = (1.0, 1.0, 0.0, 1.0, 0.2, 0.5, 0.0, 0.1)
    # keep away from the critical angle, where F is not a well-conditioned function of float32 inputs
    sin2t = (1.0 - cos * cos) / (eta * eta)
    cos = np.where(np.abs(sin2t - 1.0) < 1e-2, 1.0, cos)
    add(Case("F_Dielectric", ("F_Dielectric",), "F_Dielectric(a.x, a.y)", [vec4s(cos, eta)],
             np.asarray(fresnel.f_dielectric(cos, eta), dtype=float)[:, None], atol=1e-7))
    ior, refl, metal = f32(rng.uniform(1.0, 3.0, N)), f32(rng.uniform(0, 1, N)), f32(rng.uniform(0, 1, N))
    base, dielectric_f0 = f32(rng.uniform(0, 1, (N, 3))), f32(rng.uniform(0, 0.1, N))
    add(Case("f0", ("pbrkit_f0FromIOR", "pbrkit_f0FromReflectance", "pbrkit_f90Filament"),
             "vec3(pbrkit_f0FromIOR(a.x), pbrkit_f0FromReflectance(a.y), pbrkit_f90Filament(b.xyz))",
             [vec4s(ior, refl), vec4s(f0 * 0.05)],
             np.stack([fresnel.f0_from_ior(ior), fresnel.f0_from_reflectance(refl),
                       fresnel.f90_filament((f0 * 0.05).sum(axis=1))], axis=1), atol=1e-7))
    add(Case("f0_metallic", ("pbrkit_f0Metallic",), "vec4(pbrkit_f0Metallic(b.xyz, a.x, a.y), 0.0)",
             [vec4s(metal, dielectric_f0), vec4s(base)],
             fresnel.f0_metallic(base, metal[:, None], dielectric_f0[:, None]), atol=1e-7))

    nol, nov, loh = random_cosines(rng, -0.2), random_cosines(rng)[rng.permutation(N)], f32(rng.uniform(0, 1, N))
    add(Case("diffuse", ("Fd_Lambert", "Fd_Burley"), "vec2(Fd_Lambert(a.x), Fd_Burley(a.x, a.y, a.z, a.w))",
             [vec4s(nol, nov, loh, r)], np.stack([diffuse.lambert(nol), diffuse.burley(nol, nov, loh, r)], axis=1)))
    return cases


def _model_cases(rng):
    l, v, n = random_directions(rng)
    base = f32(rng.uniform(0, 1, (N, 3)))
    metal = f32(np.where(rng.uniform(size=N) < 0.3, rng.integers(0, 2, N), rng.uniform(0, 1, N)))
    # near-mirror rows keep r >= 0.3: at smaller r the peak of D changes by more than 1e-4 across the
    # float32 rounding of h = normalize(l + v) (D'/D ~ 4 / alpha^2 at the peak)
    rough = f32(np.where(np.arange(N) < N // 2, rng.uniform(0.03, 1.0, N), rng.uniform(0.3, 1.0, N)))
    refl = f32(rng.uniform(0, 1, N))
    material = Material(base_color=base, metallic=metal, roughness=rough, reflectance=refl)
    gltf_material = Material(base_color=base, metallic=metal, roughness=rough)
    inputs = [vec4s(l, metal), vec4s(v, rough), vec4s(n, refl), vec4s(base)]
    cases = []
    cos = np.array([isotropic_cosines(*n[i], *v[i], *l[i])[:4] for i in range(N)])
    cases.append(Case("cosines", ("pbrkit_cosines",),
                      "vec4(pbrkit_cosines(a.xyz, b.xyz, c.xyz).NoL, pbrkit_cosines(a.xyz, b.xyz, c.xyz).NoV, "
                      "pbrkit_cosines(a.xyz, b.xyz, c.xyz).NoH, pbrkit_cosines(a.xyz, b.xyz, c.xyz).VoH)",
                      inputs, cos, rtol=0.0, atol=1e-6))
    for name, expr, value in (
        ("BRDF_UE4", "BRDF_UE4(a.xyz, b.xyz, c.xyz, d.xyz, a.w, b.w, c.w)", models.ue4(l, v, n, material)),
        ("BRDF_Filament", "BRDF_Filament(a.xyz, b.xyz, c.xyz, d.xyz, a.w, b.w, c.w, false)",
         models.filament(l, v, n, material)),
        ("BRDF_Filament_burley", "BRDF_Filament(a.xyz, b.xyz, c.xyz, d.xyz, a.w, b.w, c.w, true)",
         models.filament(l, v, n, material, diffuse="burley")),
        ("BRDF_glTF", "BRDF_glTF(a.xyz, b.xyz, c.xyz, d.xyz, a.w, b.w)", models.gltf(l, v, n, gltf_material)),
    ):
        cases.append(Case(name, (name.split("_burley")[0],), f"vec4({expr}, 0.0)", inputs, value,
                          rtol=1e-4, atol=1e-6))
    return cases


def _ibl_cases(rng, dfg, splitsum):
    from pbrkit.albedo.tables import env_brdf_approx, sample_table
    from pbrkit.ibl.cubemap import cube_texel_directions, direction_to_cube, sample_cube
    from pbrkit.ibl.prefilter import level_of_roughness, roughness_of_level
    from pbrkit.ibl.sh import irradiance_from_sh

    cases = []
    add = cases.append
    levels = rng.integers(2, 11, N).astype(float)
    r = f32(rng.uniform(-0.2, 1.2, N))
    lod = f32(rng.uniform(0, 1, N) * (levels - 1))
    add(Case("lod", ("pbrkit_lodFromRoughness", "pbrkit_roughnessFromLod"),
             "vec2(pbrkit_lodFromRoughness(a.x, a.z), pbrkit_roughnessFromLod(a.y, a.z))", [vec4s(r, lod, levels)],
             np.stack([[level_of_roughness(r[i], int(levels[i])) for i in range(N)],
                       [roughness_of_level(lod[i], int(levels[i])) for i in range(N)]], axis=1), atol=1e-6))

    nov, rough = f32(rng.uniform(-0.1, 1.1, N)), f32(rng.uniform(-0.1, 1.1, N))
    table = dfg.astype(np.float64)
    looked_up = sample_table(table, nov, rough)
    add(Case("fetchDFG", ("pbrkit_fetchDFG",), "vec4(pbrkit_fetchDFG(u_lut, a.x, a.y), 0.0, 0.0)",
             [vec4s(nov, rough)], looked_up, rtol=1e-5, atol=1e-6))
    # the GPU's own bilinear filter: weights of limited precision (8 fractional bits is common),
    # so up to 1/256 of the largest difference between neighbouring texels
    step = max(np.abs(np.diff(table, axis=0)).max(), np.abs(np.diff(table, axis=1)).max())
    add(Case("sampleDFG", ("pbrkit_sampleDFG",), "vec4(pbrkit_sampleDFG(u_lut, a.x, a.y), 0.0, 0.0)",
             [vec4s(nov, rough)], looked_up, rtol=0.0, atol=step / 256.0))

    # The albedo formulas, checked against the other table kind: DFG1 + F0 (DFG2 - DFG1) of the
    # dfg table must equal F0 A + B of the splitsum table with the same visibility (texel values).
    j, i = rng.integers(0, dfg.shape[0], N), rng.integers(0, dfg.shape[1], N)
    f0 = f32(rng.uniform(0, 1, (N, 3)))
    d12, ab = f32(dfg[j, i]), f32(splitsum[j, i])
    add(Case("albedoDFG", ("pbrkit_specularAlbedoDFG",), "vec4(pbrkit_specularAlbedoDFG(a.xy, b.xyz), 0.0)",
             [vec4s(d12), vec4s(f0)], f0 * ab[:, :1] + ab[:, 1:], rtol=1e-4, atol=2e-6))
    add(Case("albedoSplitSum", ("pbrkit_specularAlbedoSplitSum",),
             "vec4(pbrkit_specularAlbedoSplitSum(a.xy, b.xyz), 0.0)", [vec4s(ab), vec4s(f0)],
             d12[:, :1] + f0 * (d12[:, 1:] - d12[:, :1]), rtol=1e-4, atol=2e-6))
    prefiltered = f32(rng.uniform(0, 4, (N, 3)))
    add(Case("specularIBL", ("pbrkit_specularIBL",), "vec4(pbrkit_specularIBL(c.xyz, a.xy, b.xyz), 0.0)",
             [vec4s(d12), vec4s(f0), vec4s(prefiltered)], prefiltered * (f0 * ab[:, :1] + ab[:, 1:]),
             rtol=1e-4, atol=1e-5))
    nov, rough = f32(rng.uniform(0, 1, N)), f32(rng.uniform(0, 1, N))
    add(Case("EnvBRDFApprox", ("EnvBRDFApprox",), "vec4(EnvBRDFApprox(a.x, a.y), 0.0, 0.0)", [vec4s(nov, rough)],
             np.stack(env_brdf_approx(nov, rough), axis=1), atol=1e-6))

    # Prefiltered specular: a small cube with every level random, sampled at the texel centres of
    # level 0 (r = 0) and in the faces' interiors (|sc|, |tc| <= 0.5: clear of the seams at every
    # level) at random roughness, against pbrkit's trilinear cube sampler.
    pyramid = [f32(rng.uniform(0, 1, (6, CUBE_SIZE >> m, CUBE_SIZE >> m, 4))) for m in range(CUBE_LEVELS)]
    centres = cube_texel_directions(CUBE_SIZE).reshape(-1, 3)
    take = rng.choice(centres.shape[0], N // 2, replace=False)
    face = rng.integers(0, 6, N // 2)
    from pbrkit.ibl.cubemap import face_direction

    sc, tc = rng.uniform(-0.5, 0.5, N // 2), rng.uniform(-0.5, 0.5, N // 2)
    inner = np.array([face_direction(f, s, t) for f, s, t in zip(face, sc, tc)], dtype=float)
    dirs = f32(np.concatenate([centres[take], inner / np.linalg.norm(inner, axis=1, keepdims=True)]))
    rough = f32(np.concatenate([np.zeros(N // 2), rng.uniform(0, 1, N // 2)]))
    lods = level_of_roughness(rough, CUBE_LEVELS)
    expected = sample_cube([p.astype(np.float64) for p in pyramid], dirs, lods)[:, :3]
    assert np.array_equal(direction_to_cube(dirs[: N // 2])[0], take // (CUBE_SIZE * CUBE_SIZE))
    level_step = max(np.abs(pyramid[m] - pyramid[m].mean()).max() for m in range(CUBE_LEVELS)) * 2.0
    add(Case("sampleSpecular", ("pbrkit_sampleSpecular",),
             f"vec4(pbrkit_sampleSpecular(u_cube, a.xyz, a.w, {CUBE_LEVELS}.0), 0.0)", [vec4s(dirs, rough)],
             expected, rtol=0.0, atol=level_step / 256.0,
             extra={"cube": {"size": CUBE_SIZE, "levels": [[face.reshape(-1).tolist() for face in level]
                                                          for level in pyramid]}}))

    sh = f32(rng.normal(size=(9, 3)))
    sh[0] += 2.0
    normals = random_units(rng)
    normals[:6] = np.concatenate([np.eye(3), -np.eye(3)])
    irradiance = irradiance_from_sh(sh, normals)
    base = f32(rng.uniform(0, 1, (N, 3)))
    add(Case("irradianceSH", ("pbrkit_irradianceSH", "pbrkit_diffuseIBL"),
             "vec4(pbrkit_irradianceSH(u_sh, a.xyz), pbrkit_diffuseIBL(b.xyz, pbrkit_irradianceSH(u_sh, a.xyz)).g)",
             [vec4s(normals), vec4s(base)],
             np.concatenate([irradiance, (base[:, 1] * irradiance[:, 1] / np.pi)[:, None]], axis=1),
             rtol=1e-4, atol=1e-5 * np.abs(irradiance).max(), extra={"sh": sh.reshape(-1).tolist()}))
    return cases


def _ltc_cases(rng):
    """pbrkit's own LTC evaluation (exact horizon clipping) of rectangles, some
    crossing the horizon, some seen from behind, against :func:`pbrkit.ltc.shader.
    ltc_exact_rect` with a constant table (its lookup then returns the texel)."""
    from pbrkit.ltc.lights import random_rect_lights
    from pbrkit.ltc.shader import ltc_exact_rect

    lights = random_rect_lights(N, 77)
    corners = f32(lights.corners)
    texel = f32(np.stack([rng.uniform(0.2, 1.2, N), rng.uniform(-0.3, 0.1, N), rng.uniform(0.0, 0.8, N),
                           rng.uniform(0.05, 1.2, N)], axis=1))
    corners[: N // 8] = corners[: N // 8, ::-1]  # reversed winding: seen from behind, 0
    expected = np.array([ltc_exact_rect(np.tile(texel[i], (2, 2, 1)), np.tile([1.0, 1.0, 0.0, 0.0], (2, 2, 1)),
                                        0.5, 0.5, corners[i]) for i in range(N)])[:, None]
    cases = [Case("ltcRect", ("pbrkit_ltcEdgeIntegral", "pbrkit_ltcHorizonCrossing", "pbrkit_ltcFormFactorQuad",
                              "pbrkit_ltcRect"),
                  "vec4(pbrkit_ltcRect(vec4(a.w, b.w, c.w, d.w), a.xyz, b.xyz, c.xyz, d.xyz), 0.0, 0.0, 0.0)",
                  [vec4s(corners[:, k], texel[:, k]) for k in range(4)], expected, rtol=2e-4, atol=2e-6)]
    from pbrkit.ltc.shader import ltc_fresnel_rect

    tfc, split, f0 = np.array([0.9, -0.1, 0.2, 0.7]), np.array([0.8, 0.3]), 0.04
    table2 = np.tile([split[0], split[1], 0.0, 0.0], (2, 2, 1))
    expected = np.array([ltc_fresnel_rect(np.tile(texel[i], (2, 2, 1)), table2, np.tile(tfc, (2, 2, 1)), 0.5, 0.5,
                                          corners[i], f0) for i in range(N)])[:, None]
    cases.append(Case("ltcRectFresnel", ("pbrkit_ltcRectFresnel",),
                      "vec4(pbrkit_ltcRectFresnel(vec4(a.w, b.w, c.w, d.w), vec4(0.9, -0.1, 0.2, 0.7), "
                      "vec2(0.8, 0.3), 0.04, a.xyz, b.xyz, c.xyz, d.xyz), 0.0, 0.0, 0.0)",
                      [vec4s(corners[:, k], texel[:, k]) for k in range(4)], expected, rtol=2e-4, atol=2e-6))
    nov, rough = f32(rng.uniform(-0.1, 1.1, N)), f32(rng.uniform(-0.1, 1.1, N))
    size = f32(rng.choice([8.0, 32.0, 64.0], N))
    uv = np.stack([np.clip(rough, 0, 1), np.sqrt(1 - np.clip(nov, 0, 1))], axis=1)  # CONVENTIONS, Area lights
    cases.append(Case("ltcUv", ("pbrkit_ltcUv",), "vec4(pbrkit_ltcUv(a.x, a.y, a.z), 0.0, 0.0)",
                      [vec4s(nov, rough, size)], uv * (size[:, None] - 1) / size[:, None] + 0.5 / size[:, None],
                      rtol=1e-6, atol=1e-7))
    return cases


RAMP_ROW = 8  # pbrkit reads a ramp image's middle row: row H // 2 of the 16-row table the page uploads as u_lut
TAM_SIZE = 32
TAM_LEVELS = 3


def _npr_cases(rng, dfg):
    """The toon, MToon and hatching terms (:mod:`pbrkit.npr.toon`, :func:`pbrkit.npr.hatching.hatch`).
    Small absolute tolerances where a float32 difference of nearly equal inputs makes the value
    small (a smoothstep or linearstep just past its lower end, a rim with n.v near 1 + lift)."""
    from types import SimpleNamespace

    from pbrkit.npr import hatching, toon
    from pbrkit.npr.render import _shade

    cases = []
    add = cases.append
    def soft_or_hard():  # 30% hard steps (softness 0)
        return f32(np.where(rng.uniform(size=N) < 0.3, 0.0, rng.uniform(0.0, 0.3, N)))

    x, edge, soft = f32(rng.uniform(-0.2, 1.2, N)), f32(rng.uniform(0.0, 1.0, N)), soft_or_hard()
    x[: N // 8] = edge[: N // 8]  # on the edge: the hard step gives 1
    x[N // 8: N // 4] = f32(edge[N // 8: N // 4] + rng.uniform(-1.0, 1.0, N // 8) * soft[N // 8: N // 4])
    add(Case("smoothStepBand", ("pbrkit_smoothStepBand",), "pbrkit_smoothStepBand(a.x, a.y, a.z)",
             [vec4s(x, edge, soft)],
             np.array([toon.smooth_step_band(x[i], edge[i], soft[i]) for i in range(N)])[:, None], atol=1e-6))

    count = rng.integers(0, 9, N)
    count[:9] = np.arange(9)
    thresholds = f32(rng.uniform(0.0, 1.0, (N, 8)))  # entries past the count are ignored
    for i in range(N):
        thresholds[i, : count[i]] = np.sort(thresholds[i, : count[i]])
    thresholds[9:40, :3], count[9:40] = toon.default_thresholds(4), 3  # pbrkit's default bands
    x, soft = f32(rng.uniform(-0.2, 1.2, N)), soft_or_hard()
    x[40:72] = thresholds[40:72, 0] * (count[40:72] > 0)
    add(Case("toonTone", ("pbrkit_toonTone",),
             "pbrkit_toonTone(a.x, float[8](b.x, b.y, b.z, b.w, c.x, c.y, c.z, c.w), int(a.y), a.z)",
             [vec4s(x, count, soft), vec4s(thresholds[:, :4]), vec4s(thresholds[:, 4:])],
             np.array([toon.toon_tone(x[i], thresholds[i, : count[i]], soft[i]) for i in range(N)])[:, None],
             atol=1e-6))

    shadow, tone = f32(rng.uniform(0.0, 1.0, (N, 3))), f32(rng.uniform(0.0, 1.0, N))
    add(Case("toonShade", ("pbrkit_toonShade",), "pbrkit_toonShade(b.xyz, a.x)", [vec4s(tone), vec4s(shadow)],
             _shade(SimpleNamespace(ramp_colors=None, shadow_color=shadow), tone), atol=1e-7))

    # the ramp: the middle row of the (DFG1, DFG2) table the page uploads as u_lut (RG32F: blue reads 0)
    ramp = np.concatenate([dfg[RAMP_ROW].astype(np.float64), np.zeros((dfg.shape[1], 1))], axis=1)
    tone = f32(rng.uniform(-0.1, 1.1, N))
    tone[:dfg.shape[1]] = (np.arange(dfg.shape[1]) + 0.5) / dfg.shape[1]  # texel centres
    tone[dfg.shape[1]: dfg.shape[1] + 4] = (0.0, 1.0, 0.5 / dfg.shape[1], 1.0 - 0.5 / dfg.shape[1])
    tone = f32(tone)
    looked_up = _shade(SimpleNamespace(ramp_colors=ramp), tone)
    assert np.array_equal(looked_up, toon.ramp_lookup(ramp, tone))
    add(Case("fetchRamp", ("pbrkit_fetchRamp",), "pbrkit_fetchRamp(u_lut, a.x)", [vec4s(tone)], looked_up,
             rtol=1e-5, atol=1e-6))
    step = np.abs(np.diff(ramp, axis=0)).max()  # the GPU's filter weights: see sampleDFG
    add(Case("sampleRamp", ("pbrkit_sampleRamp",), "pbrkit_sampleRamp(u_lut, a.x)", [vec4s(tone)], looked_up,
             rtol=0.0, atol=step / 256.0))

    alpha, noh = random_alphas(rng, 0.02), random_cosines(rng)
    d, d_peak = f32(distributions.d_ggx(noh, alpha)), f32(distributions.d_ggx(1.0, alpha))
    d_peak[:8] = 0.0  # no peak: no highlight
    threshold, soft = f32(rng.uniform(0.1, 0.9, N)), soft_or_hard()
    add(Case("highlightTone", ("pbrkit_highlightTone",), "pbrkit_highlightTone(a.x, a.y, a.z, a.w)",
             [vec4s(d, d_peak, threshold, soft)],
             np.array([toon.highlight_tone(d[i], d_peak[i], threshold[i], soft[i]) for i in range(N)])[:, None],
             atol=1e-6))

    lo, width, x = f32(rng.uniform(-1.0, 1.0, N)), rng.uniform(0.05, 1.0, N), f32(rng.uniform(-1.5, 1.5, N))
    hi = f32(lo + np.where(rng.uniform(size=N) < 0.5, width, -width))  # b < a too
    nol, shift, toony = f32(rng.uniform(-1.0, 1.0, N)), f32(rng.uniform(-0.5, 0.5, N)), f32(rng.uniform(0, 0.9, N))
    add(Case("mtoon", ("pbrkit_linearstep", "pbrkit_mtoonShading"),
             "vec2(pbrkit_linearstep(a.x, a.y, a.z), pbrkit_mtoonShading(b.x, b.y, b.z))",
             [vec4s(lo, hi, x), vec4s(nol, shift, toony)],
             np.stack([toon.linearstep(lo, hi, x), toon.mtoon_shading(nol, shift, toony)], axis=1), atol=1e-6))
    nov, power, lift = random_cosines(rng), f32(rng.uniform(1.0, 8.0, N)), f32(rng.uniform(-0.3, 0.5, N))
    power[:16] = (0.0, 1e-6, 0.5, 5.0) * 4  # the epsilon, and MToon's default 5
    lift[:4] = 0.0
    add(Case("parametricRim", ("pbrkit_parametricRim",), "pbrkit_parametricRim(a.x, a.y, a.z)",
             [vec4s(nov, power, lift)], toon.parametric_rim(nov, power, lift)[:, None], atol=2e-6))
    gi, up, down = (f32(rng.uniform(0.0, 4.0, (N, 3))) for _ in range(3))
    factor = f32(rng.uniform(0.0, 1.0, N))
    factor[:2] = (0.0, 1.0)
    add(Case("giEqualized", ("pbrkit_giEqualized",), "pbrkit_giEqualized(a.xyz, b.xyz, c.xyz, a.w)",
             [vec4s(gi, factor), vec4s(up), vec4s(down)], toon.gi_equalized(gi, up, down, factor[:, None]),
             atol=1e-6))

    # Hatching: small TAMs of 2, 3, 6 and 8 tones.  Tone k is sampled at the pixel as hatch() samples it
    # (bilinear, REPEAT, trilinear at the level): hatch at the tone (k + 1) / T, which selects it alone;
    # the shader blends those samples for the pixel's tone and must give hatch at that tone.
    tone, tones, level = np.zeros(N), np.zeros(N), np.zeros(N)
    samples, expected = f32(rng.uniform(0.0, 1.0, (N, 8))), np.zeros(N)  # entries past T are ignored
    groups = np.array_split(np.arange(N), 4)
    for rows, count in zip(groups, (2, 3, 6, 8)):
        tam = hatching.tonal_art_map(tones=count, size=TAM_SIZE, levels=TAM_LEVELS, seed=count)
        t = f32(rng.uniform(-0.1, 1.1, rows.size))
        t[: count + 1] = f32(np.arange(count + 1) / count)  # the images themselves
        uv = f32(rng.uniform(-1.0, 2.0, (rows.size, 2)))
        lam = f32(rng.uniform(-0.5, TAM_LEVELS - 0.5, rows.size))
        for k in range(count):
            samples[rows, k] = hatching.hatch((k + 1) / count, uv, tam, level=lam)
        tone[rows], tones[rows], level[rows] = t, count, lam
        expected[rows] = hatching.hatch(t, uv, tam, level=lam)
        # the level pbrkit_hatchLevel gives is the one hatch() takes from a footprint
        footprint = 2.0 ** rng.uniform(-3.0, 4.0, rows.size)
        assert np.array_equal(hatching.hatch(t, uv, tam, footprint=footprint),
                              hatching.hatch(t, uv, tam, level=np.clip(np.log2(footprint), 0.0, TAM_LEVELS - 1)))
    add(Case("hatchBlend", ("pbrkit_hatchBlend",), "pbrkit_hatchBlend(a.x, int(a.y), b, c)",
             [vec4s(tone, tones), vec4s(samples[:, :4]), vec4s(samples[:, 4:])], expected[:, None], atol=1e-6))
    footprint = f32(2.0 ** rng.uniform(-3.0, 8.0, N))
    footprint[:3] = (1.0, 2.0, 0.5)
    levels = f32(rng.integers(1, 10, N))
    add(Case("hatchLevel", ("pbrkit_hatchLevel",), "pbrkit_hatchLevel(a.x, a.y)", [vec4s(footprint, levels)],
             np.clip(np.log2(footprint), 0.0, levels - 1.0)[:, None], atol=1e-6))
    return cases


@pytest.fixture(scope="module")
def webgl_results(tmp_path_factory):
    from pbrkit.albedo.lut import lookup_table

    root = tmp_path_factory.mktemp("shaders")
    shaders.write_shaders(root / "shaders")
    rng = np.random.default_rng(20240510)
    dfg, _ = lookup_table("dfg", 16)
    splitsum, _ = lookup_table("splitsum", 16, "height-correlated")
    cases = (_scalar_cases(rng) + _model_cases(rng) + _ibl_cases(rng, dfg, splitsum) + _ltc_cases(rng)
             + _npr_cases(rng, dfg))
    spec = {"files": [f"shaders/{name}" for name in shaders.GLSL_FILES], "width": WIDTH,
            "lut": {"width": dfg.shape[1], "height": dfg.shape[0], "data": dfg.reshape(-1).tolist()},
            "cases": [{"name": c.name, "expr": c.expr, "count": N,
                       "inputs": [x.reshape(-1).tolist() for x in c.inputs]} for c in cases]}
    for c in cases:
        spec.update(c.extra)
    (root / "cases.json").write_text(json.dumps(spec))
    report = run_page("shaders.html", data=root, timeout=120)
    return cases, report["result"]


@needs_engines()
def test_every_function_is_tested_in_webgl2(webgl_results):
    cases, result = webgl_results
    covered = {name for c in cases for name in c.covers}
    # pbrkit_khr.glsl's and pbrkit_khr_material.glsl's functions are tested in tests/shaders/test_shaders_khr.py and
    # tests/shaders/test_shaders_khr_material.py (with the E_sheen table as u_lut)
    assert covered == {f["name"] for f in shaders.functions()
                       if f["file"] not in ("pbrkit_khr.glsl", "pbrkit_khr_material.glsl")}
    assert set(result["results"]) == {c.name for c in cases}


@needs_engines()
def test_glsl_matches_pbrkit_in_webgl2(webgl_results):
    cases, result = webgl_results
    assert_cases_match(cases, result)
