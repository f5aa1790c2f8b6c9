"""``pbrkit demo``: the page is self-contained, every image loads in a real browser
(headless Chromium) without console errors, and the numbers are there."""

from __future__ import annotations

import html
import json
import re
import subprocess
from html.parser import HTMLParser

import numpy as np
import pytest
from skips import CHROMIUM, needs_chromium

CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                  "--disable-component-update", "--disable-sync", "--no-first-run"]


class _Links(HTMLParser):
    def __init__(self):
        super().__init__()
        self.images, self.links, self.scripts = [], [], 0

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "img":
            self.images.append(attrs.get("src"))
        elif tag == "a":
            self.links.append(attrs.get("href"))
        elif tag == "script":
            self.scripts += 1


@pytest.fixture(scope="module")
def demo_dir(tmp_path_factory):
    from typer.testing import CliRunner

    from pbrkit.cli import app

    out = tmp_path_factory.mktemp("demo") / "site"
    # the demo's CLI with small sizes (the defaults take ~20 s on 2 cores)
    result = CliRunner().invoke(app, ["demo", "-o", str(out), "--size", "56", "--spp", "8", "--bake-size", "32",
                                      "--quiet"])
    assert result.exit_code == 0, result.output
    return out


def test_page_is_self_contained_and_complete(demo_dir):
    page = (demo_dir / "index.html").read_text(encoding="utf-8")
    parser = _Links()
    parser.feed(page)
    assert parser.scripts == 0
    assert {"realtime.png", "reference.png", "error.png", "furnace/furnace_ggx.png", "furnace/furnace_models.png",
            "lut.png", "preview/irradiance.png"} <= set(parser.images)
    assert {"bake/preview.png", "furnace/furnace.png", "relative_error.exr"} <= set(parser.links)
    for ref in parser.images + parser.links:
        assert ref and not re.match(r"^[a-z]+:", ref) and not ref.startswith("/"), ref  # relative links only
        assert (demo_dir / ref).exists(), ref
    summary = json.loads((demo_dir / "summary.json").read_text())
    errors = summary["errors"]
    for key in ("mean_relative_error", "max_relative_error", "flip", "mean_relative_stderr"):
        assert np.isfinite(errors[key]) and f"{errors[key]:.4g}" in page
    assert summary["reference"]["spp"] == 8 and str(summary["reference"]["paths"]) in page
    manifest = json.loads((demo_dir / "bake" / "manifest.json").read_text())
    assert manifest["format"] in page and "sha256" in page
    assert len(summary["per_sphere_signed_relative_error"]) == 7
    assert (demo_dir / "LICENSE-environment.md").read_text().count("CC0") >= 1


def test_page_names_the_environment_and_its_licence(demo_dir):
    from pbrkit.data import ENVIRONMENT

    page = (demo_dir / "index.html").read_text(encoding="utf-8")
    for key in ("name", "source_file", "file", "licence"):
        assert html.escape(ENVIRONMENT[key]) in page, key
    assert 'href="LICENSE-environment.md"' in page


def test_error_map_has_a_colour_bar_on_a_scale_from_the_data(demo_dir):
    import imageio.v3 as iio

    summary = json.loads((demo_dir / "summary.json").read_text())
    emap = summary["error_map"]
    # the 99th percentile rounded up to 1, 2, 2.5 or 5 x 10^k, stated on the page with the maximum
    assert emap["percentile_99"] <= emap["scale_max"] <= 2.0 * emap["percentile_99"] + 1e-3
    mantissa = emap["scale_max"] / 10.0 ** np.floor(np.log10(emap["scale_max"]) + 1e-9)
    assert any(abs(mantissa - m) < 1e-9 for m in (1.0, 2.0, 2.5, 5.0))
    assert abs(emap["max"] - summary["errors"]["max_relative_error"]) < 1e-9
    page = (demo_dir / "index.html").read_text(encoding="utf-8")
    assert "relative luminance error" in page and f"{100.0 * emap['scale_max']:g}%" in page
    assert f"{100.0 * emap['max']:.1f}%" in page
    # the figure is taller than wide: the map with the colour bar and its label below
    height, width = iio.imread(demo_dir / "error.png").shape[:2]
    assert height > 1.15 * width


def test_bake_has_roughness_steps_of_at_most_0_2_and_labelled_crosses(demo_dir):
    summary = json.loads((demo_dir / "summary.json").read_text())
    bake = summary["bake"]
    assert bake["levels"] >= 6 and np.all(np.diff(bake["roughness"]) <= 0.2 + 1e-12)
    page = (demo_dir / "index.html").read_text(encoding="utf-8")
    assert "Prefiltered specular chain" in page and "irradiance E(n)" in page
    for m, r in enumerate(bake["roughness"]):
        assert f"level {m}: r = {r:.2f}" in page
        assert (demo_dir / "preview" / f"specular_m{m}.png").is_file()


def test_page_shows_timings_with_units_and_the_furnace_check(demo_dir):
    summary = json.loads((demo_dir / "summary.json").read_text())
    page = (demo_dir / "index.html").read_text(encoding="utf-8")
    for value in summary["timings_s"].values():
        assert f"{value:.3f} s" in page
    for lobe, entry in summary["furnace"].items():
        assert f"{100.0 * entry['fraction_within_3_stderr']:.1f}%" in page
        assert f"{entry['max_abs_mc_minus_quadrature']:.2e}" in page
    assert "within 3" in page


def test_page_says_what_the_ground_truth_includes(demo_dir):
    summary = json.loads((demo_dir / "summary.json").read_text())
    assert summary["reference"]["includes"] == {"occlusion": False, "bounces": 0}
    page = (demo_dir / "index.html").read_text(encoding="utf-8")
    assert "What the ground truth includes" in page and "inter-object occlusion: <b>no</b>" in page
    assert "bounces: <b>0</b>" in page
    for name in summary["realtime"]["approximations"]:
        assert f"<code>{html.escape(name)}</code>" in page


def test_split_table_only_with_a_split():
    """The table of the error's split by approximation appears when the summary has
    errors["split"] (either value key), and not otherwise."""
    from pbrkit.app.demo import _split_table

    assert _split_table({"mean_relative_error": 0.1}) == ""
    split = {"sh": {"mean_relative_error": 0.0123, "description": "SH irradiance"},
             "split_sum": {"mean_relative_error": 0.0456, "description": "the split sum"}}
    table = _split_table({"split": split})
    assert "Error split by approximation" in table and "0.0123" in table and "the split sum" in table
    split = {"fstar": {"rms_relative_error": 0.0789, "description": "F* weight"}}
    assert "0.0789" in _split_table({"split": split})


def test_images_have_the_requested_sizes(demo_dir):
    import imageio.v3 as iio

    for name in ("realtime.png", "reference.png"):
        assert iio.imread(demo_dir / name).shape == (56, 56, 3)


@needs_chromium()
def test_page_loads_in_headless_chromium(demo_dir, tmp_path):
    # A copy of the page with a checker appended (the product page has no script): after
    # the load event it lists the images that failed to decode into the document title.
    page = (demo_dir / "index.html").read_text(encoding="utf-8")
    checker = """<script>
window.addEventListener("load", function () {
  var bad = [], imgs = document.images;
  for (var i = 0; i < imgs.length; i++) {
    if (!imgs[i].complete || imgs[i].naturalWidth === 0) bad.push(imgs[i].getAttribute("src"));
  }
  document.body.setAttribute("data-images", imgs.length);
  document.body.setAttribute("data-broken", bad.join(","));
  document.body.setAttribute("data-checked", "yes");
});
</script></body>"""
    check = demo_dir / "check.html"
    check.write_text(page.replace("</body>", checker), encoding="utf-8")
    try:
        profile = tmp_path / "profile"
        dom = subprocess.run([CHROMIUM, *CHROMIUM_FLAGS, f"--user-data-dir={profile}", "--enable-logging=stderr",
                              "--v=0", "--virtual-time-budget=10000", "--dump-dom", check.as_uri()],
                             capture_output=True, text=True, timeout=120)
    finally:
        check.unlink()
    assert 'data-checked="yes"' in dom.stdout, dom.stderr[-2000:]
    images = int(re.search(r'data-images="(\d+)"', dom.stdout).group(1))
    broken = re.search(r'data-broken="([^"]*)"', dom.stdout).group(1)
    assert images >= 6 and broken == ""
    console = [line for line in dom.stderr.splitlines()
               if "CONSOLE" in line or "Failed to load resource" in line or "Uncaught" in line
               or "ERR_FILE_NOT_FOUND" in line]
    assert console == []
    # a screenshot of the real page, kept beside the demo output
    shot = demo_dir.parent / "screenshot.png"
    run = subprocess.run([CHROMIUM, *CHROMIUM_FLAGS, f"--user-data-dir={tmp_path / 'profile2'}",
                          "--enable-logging=stderr", "--v=0", "--window-size=1280,1800", "--hide-scrollbars",
                          f"--screenshot={shot}", (demo_dir / "index.html").as_uri()],
                         capture_output=True, text=True, timeout=120)
    assert shot.exists(), run.stderr[-2000:]
    import imageio.v3 as iio

    pixels = iio.imread(shot)
    assert pixels.shape[:2] == (1800, 1280) and pixels.std() > 10  # not a blank page
    assert not [line for line in run.stderr.splitlines() if "CONSOLE" in line or "Failed to load" in line]


def test_demo_replaces_a_previous_demo_as_a_whole(demo_dir):
    """Run again into a previous demo's folder: allowed, and the new folder replaces it
    as a whole (a stale file of the old one is gone; nothing is left beside it)."""
    from typer.testing import CliRunner

    from pbrkit.cli import app

    stale = demo_dir / "preview" / "specular_m9.png"
    stale.write_bytes(b"stale")
    siblings = sorted(p.name for p in demo_dir.parent.iterdir())
    result = CliRunner().invoke(app, ["demo", "-o", str(demo_dir), "--size", "56", "--spp", "8", "--bake-size",
                                      "32", "--quiet"])
    assert result.exit_code == 0, result.output
    assert not stale.exists() and (demo_dir / "index.html").is_file()
    assert sorted(p.name for p in demo_dir.parent.iterdir()) == siblings


def test_npr_section_shows_the_grid_and_a_gltf_model_in_each_style(demo_dir):
    import imageio.v3 as iio
    import pygltflib

    page = (demo_dir / "index.html").read_text(encoding="utf-8")
    parser = _Links()
    parser.feed(page)
    summary = json.loads((demo_dir / "summary.json").read_text())["npr"]
    model = summary["model"]["styles"]
    assert set(model) == {"pbr", "toon", "mtoon", "hatching", "outline"}
    assert model["hatching"]["outline"] == "geometry" and model["mtoon"]["outline"] == "hull"
    images = {}
    for name, entry in list(summary["styles"].items()) + [("model " + k, v) for k, v in model.items()]:
        assert entry["file"] in parser.images
        images[name] = iio.imread(demo_dir / entry["file"]).astype(float)
        assert images[name].shape[:2] == (summary["size"], summary["size"])
    # each style changes the model's image (the outline style draws on top of the PBR one)
    for name in ("toon", "mtoon", "hatching", "outline"):
        assert np.abs(images["model " + name] - images["model pbr"]).mean() > 1.0, name
    # the model is a glTF 2.0 file an independent reader loads: the knot with its UVs and the box
    assert "model.glb" in parser.links
    gltf = pygltflib.GLTF2().load(str(demo_dir / "model.glb"))
    assert [m.name for m in gltf.materials] == ["knot", "pedestal"]
    assert gltf.meshes[0].primitives[0].attributes.TEXCOORD_0 is not None


def test_gltf_extensions_scene_has_one_sphere_per_extension():
    """The section's materials: the core first (no extension: the core model's code), then
    each KHR_materials extension alone (its keys away from their defaults, the others at
    theirs: the extended model's code), then the first four together; the materials of the
    brief (velvet sheen 0.5, car-paint coat 1 / 0.05 over roughness 0.5, specular 0.3
    coloured, ior 2.4), a thin film, a thin transmissive wall and a brushed metal."""
    from pbrkit.app.demo import GLTF_EXTENSION_MATERIALS, gltf_extensions_scene
    from pbrkit.brdf.shading.registry import BY_NAME, EXTENDED_CODES, MODELS, model_codes
    from pbrkit.rendering.scene import EnvironmentSpec

    keys = {"sheen": {"sheen_color", "sheen_roughness"}, "clearcoat": {"clearcoat", "clearcoat_roughness"},
            "specular": {"specular", "specular_color"}, "ior": {"ior"},
            "iridescence": {"iridescence"},  # (its IOR 1.3 and 400 nm are the defaults)
            "transmission": {"transmission"},
            "anisotropy": {"anisotropy_strength"}}
    declared = BY_NAME["gltf"]
    scene = gltf_extensions_scene(50, EnvironmentSpec(color=(1.0, 1.0, 1.0)))
    assert (scene.camera.width, scene.camera.height) == (50, 20) and len(scene.objects) == 9
    names = [name for name, _, _ in GLTF_EXTENSION_MATERIALS]
    assert names == ["core", "sheen", "clearcoat", "specular", "ior", "iridescence", "transmission", "anisotropy",
                     "combined"]
    combined = set().union(*(keys[k] for k in ("sheen", "clearcoat", "specular", "ior")))
    for obj, (name, shows, _) in zip(scene.objects, GLTF_EXTENSION_MATERIALS):
        spec = scene.materials[obj.material]
        assert spec.model == "gltf" and shows
        changed = {p.name for p in declared.parameters if p.name in set().union(*keys.values())
                   and np.any(np.asarray(getattr(spec, p.name)) != p.default)}
        expected = combined if name == "combined" else keys.get(name, set())
        assert changed == expected, name
        values = {p.name: getattr(spec, p.name) for p in declared.parameters}
        code = model_codes("gltf", values=values)[0]
        assert code == (MODELS.index("gltf") if name == "core" else EXTENDED_CODES["gltf"]), name
    m = {name: scene.materials[name] for name in names}
    assert m["sheen"].sheen_roughness == 0.5 and tuple(m["sheen"].sheen_color) == (1.0, 1.0, 1.0)
    assert max(m["sheen"].base_color) < 0.2
    assert (m["clearcoat"].clearcoat, m["clearcoat"].clearcoat_roughness, m["clearcoat"].roughness) == (1.0, 0.05, 0.5)
    assert m["specular"].specular == 0.3 and len(set(m["specular"].specular_color)) == 3
    assert m["ior"].ior == 2.4


def test_gltf_extensions_section_shows_both_modes_and_their_errors(demo_dir):
    """The page's glTF extensions section: the whole images and error map, each material's
    sphere cut out of both modes side by side with its errors and a line saying what it
    shows; the errors finite, within the bound of this run's noise (8 spp: the ground
    truth's own relative noise is about 25% per pixel here) and the section's numbers
    the ones on the page."""
    import imageio.v3 as iio

    page = (demo_dir / "index.html").read_text(encoding="utf-8")
    parser = _Links()
    parser.feed(page)
    g = json.loads((demo_dir / "summary.json").read_text())["gltf_extensions"]
    assert "<h2>glTF material extensions</h2>" in page
    assert {"gltf_realtime.png", "gltf_reference.png", "gltf_error.png"} <= set(parser.images)
    assert iio.imread(demo_dir / "gltf_realtime.png").shape[:2] == (g["image"]["height"], g["image"]["width"])
    assert g["spp"] == 8 and g["model"] == "gltf"
    e = g["errors"]
    for key in ("mean_relative_error", "rms_relative_error_noise_removed", "mean_relative_stderr", "flip"):
        assert np.isfinite(e[key]), key
    assert e["mean_relative_error"] < 0.4 and e["flip"] < 0.3
    assert f"{100.0 * e['mean_relative_error']:.1f}%" in page and f"{e['flip']:.4f}" in page
    assert [m["name"] for m in g["materials"]] == ["core", "sheen", "clearcoat", "specular", "ior", "iridescence",
                                                  "transmission", "anisotropy", "combined"]
    for m in g["materials"]:
        for mode in ("realtime", "reference"):
            assert m["files"][mode] in parser.images and (demo_dir / m["files"][mode]).is_file()
        errors = m["errors"]
        assert errors["pixels"] > 0 and all(np.isfinite(v) for v in errors.values()), m["name"]
        assert errors["mean_relative_error"] < 0.7, (m["name"], errors)
        assert html.escape(m["shows"]) in page
        assert f"{100.0 * errors['signed_relative_error']:+.1f}%" in page
    # the real-time and ground-truth cut-outs of one sphere are side by side in one table row
    row = page.split("<tr><th>clearcoat</th>", 1)[1].split("</tr>", 1)[0]
    assert "gltf_extensions/clearcoat_realtime.png" in row and "gltf_extensions/clearcoat_reference.png" in row
    assert "<code>clearcoat_roughness</code> = 0.05" in row
