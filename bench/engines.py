"""Screenshots of each engine rendering its pbrkit bake, next to pbrkit's real-time
render of the same scene as that engine evaluates the IBL (issue 10).

    python bench/engines.py -o DIR [--engines filament,khronos,babylon,three]

For each engine this runs the render test's own steps (tests/engines/test_engine_render_<engine>.py:
``pbrkit bake --target <engine>`` of the bundled environment, the engine's page in
headless Chromium through tests/engines/harness.mjs, ``pbrkit render --engine
<engine>``) and writes ``DIR/<engine>_engine.png``, ``DIR/<engine>_pbrkit.png``,
``DIR/<engine>_difference.png`` (|difference| x 8 where both cover an object) and ``DIR/index.html``, a page
that opens without a server, with the mean absolute difference in 8-bit grey
levels over the pixels both images cover.  Needs node, Chromium and the pinned
engines (``npm ci --prefix tests/engines``).
"""

from __future__ import annotations

import argparse
import html
import importlib
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
ENGINES = ("filament", "khronos", "babylon", "three")
TITLES = {"filament": "Filament 1.53.4", "khronos": "Khronos glTF Sample Viewer 1.1.0",
          "babylon": "Babylon.js 9.35.0", "three": "three.js 0.187.0 (r187)"}


def covered(a, b):
    """Pixels both images cover (not the background), one pixel in from the edges."""
    both = (a.astype(int).sum(-1) > 0) & (b.astype(int).sum(-1) > 0)
    inner = both.copy()
    inner[1:] &= both[:-1]
    inner[:-1] &= both[1:]
    inner[:, 1:] &= both[:, :-1]
    inner[:, :-1] &= both[:, 1:]
    return inner


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--out", type=Path, required=True)
    parser.add_argument("--engines", default=",".join(ENGINES))
    args = parser.parse_args()
    sys.path[:0] = [str(ROOT / "tests" / "engines"), str(ROOT / "tests" / "support")]
    from engine_pages import engines_missing

    from pbrkit.io.png import write_png

    reason = engines_missing()
    if reason:
        sys.exit(f"bench/engines.py: {reason}")
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    for name in [e.strip() for e in args.engines.split(",") if e.strip()]:
        if name not in ENGINES:
            sys.exit(f"bench/engines.py: unknown engine {name!r}; choose from {', '.join(ENGINES)}")
        module = importlib.import_module(f"test_engine_render_{name}")
        t0 = time.perf_counter()
        with tempfile.TemporaryDirectory() as tmp:
            bake_dir = module.bake(Path(tmp) / "bake")
            scene_dir = Path(tmp) / "scene"
            scene_dir.mkdir()
            engine = module.engine_image(bake_dir, scene_dir)
            ours = module.pbrkit_image(bake_dir, scene_dir)
        mask = covered(engine, ours)
        grey = np.abs(engine.astype(float).mean(-1) - ours.astype(float).mean(-1))[mask]
        diff = np.clip(np.abs(engine.astype(int) - ours.astype(int)) * 8, 0, 255).astype(np.uint8)
        diff[~mask] = 0  # only where both show the objects (the engines' pages draw no background)
        for suffix, image in (("engine", engine), ("pbrkit", ours), ("difference", diff)):
            write_png(args.out / f"{name}_{suffix}.png", image / 255.0, srgb=False)
        rows.append((name, float(grey.mean()), float(np.percentile(grey, 95)), time.perf_counter() - t0))
        print(f"{name}: mean |grey| {rows[-1][1]:.2f} levels, p95 {rows[-1][2]:.1f} over {mask.sum()} pixels "
              f"({rows[-1][3]:.1f} s)")
    cells = "\n".join(
        f"<tr><th>{html.escape(TITLES[n])}</th><td><img src='{n}_engine.png'></td><td><img src='{n}_pbrkit.png'>"
        f"</td><td><img src='{n}_difference.png'></td><td>{m:.2f} (p95 {p:.1f})</td></tr>"
        for n, m, p, _ in rows)
    (args.out / "index.html").write_text(f"""<!doctype html><meta charset="utf-8"><title>pbrkit bakes in engines</title>
<style>body{{font-family:sans-serif}} img{{image-rendering:pixelated;width:512px}} td,th{{padding:4px}}</style>
<h1>pbrkit bakes inside real engines</h1>
<p>Each engine loads the files of <code>pbrkit bake --target ENGINE</code> through its own public loader and
renders a grid of spheres (top: dielectric, bottom: metal; roughness 0.25 to 1); next to it,
<code>pbrkit render --mode realtime --engine ENGINE</code> of the same scene. Differences are |engine - pbrkit|
x 8 in sRGB 8-bit levels; the last column is the mean absolute grey difference over the pixels both
cover.</p>
<table><tr><th>engine</th><th>engine</th><th>pbrkit</th><th>difference x 8</th><th>mean |grey|</th></tr>
{cells}
</table>
""", encoding="utf-8")
    print(f"wrote {args.out / 'index.html'}")


if __name__ == "__main__":
    main()
