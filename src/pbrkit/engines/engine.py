"""The declaration of one engine of :data:`pbrkit.engines.ENGINES`: what pbrkit
knows about it, in one object (its module fills it in)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Optional

__all__ = ["Engine", "LOAD_BASE"]

#: What every target's load line is relative to (the manifest's ``load_base``).
LOAD_BASE = ("the bake folder (the one holding manifest.json): serve it and run the load line from a page, or "
             "an ES module, at its top level; every path in it is relative to that folder")


@dataclass(frozen=True)
class Engine:
    """One engine: a ``pbrkit bake --target`` and a ``pbrkit render --engine``.

    - ``name``: its name in :data:`pbrkit.choices.RENDER_ENGINES` and
      :data:`~pbrkit.choices.BAKE_TARGETS`; ``code``: its index in
      ``RENDER_ENGINES`` (what the real-time kernels switch on);
    - ``title``, ``npm``, ``version``: the engine and the npm package and version
      pbrkit's targets are written for and checked in (``tests/engines/package.json``);
    - ``curve``: the level curve of the chain it samples
      (:data:`pbrkit.ibl.prefilter.LEVEL_CURVES`; ``linear`` is the bake's own chain);
      ``lod(roughness, levels, size)``: the fractional level its shader samples for
      perceptual ``roughness`` in a chain of ``levels`` levels of base ``size``;
    - ``shading``: the compiled function of its IBL shading that the real-time
      kernel calls for it (by ``code``): one channel of the IBL of a
      metallic-roughness material, ``shading(base, metallic, r, n.v, A, B, radiance,
      E)``, for the Sample Viewer, three.js and Babylon.js; for Filament, whose
      ``evaluateIBL`` is pbrkit's split sum, the diffuse weight ``shading(E_spec)``;
      ``diffuse``: the irradiance it uses (``sh``, ``cube``, ``last-level``: pi x
      the chain's r = 1 level, or None: the caller's choice);
      ``energy_compensation``: whether its shader applies Filament's compensation
      (None: the caller's choice; False: it has its own multiple-scattering term);
      ``dominant_direction``: whether it looks the chain up in the specular
      dominant direction rather than the mirror direction;
    - ``writer(folder, bake)``: writes its files into ``folder`` (``OUT/<name>``)
      and returns its manifest entry; ``chain_file``: the file (relative to the
      bake folder) holding the chain it samples, None when that is the generic
      chain; ``mirror``: the coordinate its cube lookups mirror (None: none).
    """

    name: str
    code: int
    title: str
    npm: str
    version: str
    curve: str
    lod: Callable
    shading: Callable
    diffuse: Optional[str]
    energy_compensation: Optional[bool]
    dominant_direction: bool
    writer: Callable
    chain_file: Optional[str] = None
    mirror: Optional[str] = None

    @property
    def extra_chain(self):
        """The extra chain of the bake that it samples (:attr:`pbrkit.ibl.bake.Bake.chains`,
        its ``curve``), None when it samples the bake's own (linear) chain."""
        return None if self.curve == "linear" else self.curve
