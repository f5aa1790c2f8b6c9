"""The gallery (``gallery.md`` and its images), rendered when the site is built:
small real-time and ground-truth renders of the built-in scenes and the style
presets through :func:`pbrkit.render`, encoded as PNG by
:meth:`pbrkit.rendering.result.Rendering._repr_png_` (no date or version in the
file).  Fixed sizes, seed and sample counts: the same sources give the same bytes.
The sizes are small so that the strict build stays quick (about 5 s once Numba's
cache is warm); ``pbrkit demo`` renders the full-size page."""

from __future__ import annotations

import dataclasses

#: (file stem, caption, scene, render keywords): what the gallery shows.
SHOTS = (
    ("spheres", "The `spheres` scene in real time: roughness 0 to 1 left to right, metallic 0 to 1 "
     "top to bottom (`pbrkit render spheres`)", "spheres", {"mode": "realtime", "width": 256}),
    ("sphere-compare", "One material ball: real time, Monte Carlo ground truth and the relative luminance "
     "error (`pbrkit render sphere --mode compare`)", "sphere",
     {"mode": "compare", "width": 128, "height": 128, "spp": 256}),
    ("area", "Gold spheres, roughness 0.1 to 0.9, under a rect light: linearly transformed cosines "
     "in real time (`pbrkit render area`)", "area", {"mode": "realtime", "width": 256}),
    ("area-reference", "The same scene as Monte Carlo ground truth (`--mode reference`)", "area",
     {"mode": "reference", "width": 256, "spp": 64}),
)

#: The styles shown on the material ball, with a key light (``pbrkit render --style``).
STYLES = ("toon", "mtoon", "hatching", "outline")
#: The styles' key light (a scene file's ``[[lights]]`` table).
KEY_LIGHT = {"type": "directional", "direction": (-0.45, -0.5, -0.74), "intensity": 3.0}
#: Small bakes: the specular cube's size.
BAKE_SIZE = 32


def _styled_scene():
    from pbrkit.rendering.lights import Light
    from pbrkit.rendering.scene import builtin_scene

    scene = builtin_scene("sphere", width=160, height=160)
    return dataclasses.replace(scene, lights=(Light(**KEY_LIGHT),))


def images():
    """{file name: PNG bytes} and the page's Markdown, as (images, markdown)."""
    import pbrkit
    from pbrkit.npr.style import STYLE_PRESETS

    files = {}
    lines = ["# Gallery", "",
             "Rendered by pbrkit when this site is built (`docs/hooks/site_gallery.py`), small and with few "
             "samples to keep the build quick; `pbrkit demo -o demo` renders the full-size page with every "
             "error figure.", ""]
    for stem, caption, scene, options in SHOTS:
        result = pbrkit.render(scene, bake_size=BAKE_SIZE, seed=0, **options)
        files[f"gallery/{stem}.png"] = result._repr_png_()
        lines += [f"![{stem}](gallery/{stem}.png)", "", f"*{caption}.*", ""]
    lines += ["## Styles", "",
              "The material ball with a key light in each style preset (`pbrkit render sphere --style NAME`):", "",
              '<div class="grid" markdown>', ""]
    scene = _styled_scene()
    for name in STYLES:
        result = pbrkit.render(scene, mode="realtime", bake_size=BAKE_SIZE, style=STYLE_PRESETS[name])
        files[f"gallery/style-{name}.png"] = result._repr_png_()
        lines += [f"![{name}](gallery/style-{name}.png){{ width=160 }} `{name}`", ""]
    lines += ["</div>", ""]
    return files, "\n".join(lines) + "\n"
