"""``pbrkit explore``: an interactive BRDF explorer (after Disney's BRDF Explorer,
Burley 2012) built on pbrkit's own models.

- :mod:`~pbrkit.explore.views`: the data of every view, as NumPy arrays computed
  by pbrkit's models (no plotting library);
- :mod:`~pbrkit.explore.app`: the Panel / Bokeh application (served by
  ``pbrkit explore``, or displayed in Jupyter: ``explorer()``);
- :mod:`~pbrkit.explore.server`: its local server, which answers only requests
  that name it by a loopback name and port (no DNS rebinding);
- :mod:`~pbrkit.explore.static`: the same views as PNG and SVG (Matplotlib),
  ``pbrkit explore --static -o DIR``.
"""
