"""The ``pbrkit explore`` application: Panel widgets and Bokeh plots fed by
:mod:`pbrkit.explore.views` (every number comes from pbrkit's models in Python;
the browser only draws: the plots are ``ColumnDataSource`` updates, no formula
runs in JavaScript).

:func:`explorer` returns a Panel layout that a Panel server serves (``pbrkit
explore``, :func:`serve`) and that Jupyter displays (after
``panel.extension()``)::

    import panel as pn
    from pbrkit.explore.app import explorer
    pn.extension()
    explorer(model="disney", roughness=0.3)

The model's material and terms are chosen in the side bar; a second BRDF (another
model with the same material, a measured MERL file, or a model fitted to it) is
drawn beside the first in every view and compared in the "Compare" tab.

Each plot's data source is named (``incidence_a``, ``lobe_a``, ``theta_h_a``,
``theta_d_a``, ``image_a``, ``albedo_a``, ``sphere_point_a``, ``sphere_env_a``,
``terms_d_a``, ``terms_g_a``, ``terms_f_a``, their ``_b`` twins and
``difference``, ``difference_image``, ``sphere_difference``) so that a page
(tests/support/explore_browser.mjs) can read what is drawn.
"""

from __future__ import annotations

import functools
import math
import time

import numpy as np

from . import views as V

__all__ = ["Explorer", "explorer", "serve", "lobe_projection", "SECOND_CHOICES"]

#: What the second BRDF can be besides a model: nothing, the loaded MERL file, or the fit to it.
SECOND_CHOICES = ("none", "measured", "fit")
_DEG30, _DEG45, _DEG90, _DEG135 = (math.radians(x) for x in (30.0, 45.0, 90.0, 135.0))
_COLOURS = {"a": "#1f77b4", "b": "#d62728"}
_RGB = ("#d62728", "#2ca02c", "#1f77b4")


_LOBE_AZIMUTH, _LOBE_ELEVATION = math.radians(-60.0), math.radians(25.0)  # Matplotlib's 3D default view


def lobe_projection(points, azimuth=_LOBE_AZIMUTH, elevation=_LOBE_ELEVATION):
    """Screen coordinates (X, Y) of local points (..., 3) (normal +z) seen
    orthographically from the direction (cos e cos a, cos e sin a, sin e): X
    along (-sin a, cos a, 0), Y along (-sin e cos a, -sin e sin a, cos e)."""
    p = np.asarray(points, dtype=np.float64)
    ca, sa, ce, se = math.cos(azimuth), math.sin(azimuth), math.cos(elevation), math.sin(elevation)
    x = -sa * p[..., 0] + ca * p[..., 1]
    y = -se * ca * p[..., 0] - se * sa * p[..., 1] + ce * p[..., 2]
    return x, y


def _deg(x):
    return np.degrees(np.asarray(x, dtype=np.float64))


def _rgba_image(radiance, exposure):
    """Bokeh's image_rgba array (H, W) uint32, row 0 at the bottom."""
    rgba = V.display_rgba(radiance, exposure)
    return np.ascontiguousarray(np.flipud(rgba)).view(np.uint32).reshape(rgba.shape[:2])


def _wireframe(lobe):
    """Lines of the 3D lobe (rings of constant theta, meridians of constant phi) projected for drawing."""
    x, y = lobe_projection(lobe["points"])
    xs = [list(r) for r in x] + [list(c) for c in x.T[:-1:2]]
    ys = [list(r) for r in y] + [list(c) for c in y.T[:-1:2]]
    return {"xs": xs, "ys": ys}


class Explorer:
    """The explorer's state: widgets, data sources and figures.

    ``brdf_kwargs`` are :func:`pbrkit.explore.views.model_brdf`'s arguments for the
    first BRDF; ``second`` a model name or one of :data:`SECOND_CHOICES`; ``merl``
    a MERL file to load (:func:`pbrkit.measured.merl.read_merl`); ``threads`` the
    compiled kernels' threads while views update (:func:`pbrkit.explore.views.view_threads`).  :attr:`layout`
    is the Panel object to show; :attr:`timings` holds the last update time of
    each group of views (seconds)."""

    def __init__(self, model="gltf", base_color=(0.8, 0.8, 0.8), metallic=0.0, roughness=0.5, second="none",
                 merl=None, theta_v=_DEG45, light_theta=_DEG45, light_phi=_DEG135, theta_h=0.0, theta_d=_DEG30,
                 phi_d=_DEG90, exposure=0.0, compensation="filament", distribution="ggx",
                 masking="height-correlated", fresnel="schlick", diffuse="lambert", conductor=None, threads=1,
                 **parameters):
        import panel as pn

        self.pn = pn
        self.timings = {}
        self.threads = threads
        self.measured = None
        self.fitted = None
        self._building = True
        params = {k: v[2] for k, v in {**V.PARAMETER_RANGES, **V.COLOUR_RANGES}.items()}
        params.update(metallic=metallic, roughness=roughness, **parameters)
        angles = {"theta_v": theta_v, "light_theta": light_theta, "light_phi": light_phi, "theta_h": theta_h,
                  "theta_d": theta_d, "phi_d": phi_d}
        self._make_widgets(model, base_color, params, second, angles, exposure, compensation, distribution, masking,
                           fresnel, diffuse, conductor)
        self._make_plots()
        self.status = pn.pane.Markdown("", name="status", sizing_mode="stretch_width")
        if merl is not None:
            self.merl_path.value = str(merl)
            self._load_merl()
        self._building = False
        self._sync_widgets()
        self.update_all()
        self.layout = self._make_layout()

    # ------------------------------------------------------------ widgets

    def _make_widgets(self, model, base_color, params, second, angles, exposure, compensation, distribution,
                      masking, fresnel, diffuse, conductor):
        from ..brdf.models import DIFFUSES, DISTRIBUTIONS, FRESNELS, MASKINGS, MODELS
        from ..brdf.fresnel import CONDUCTORS

        pn = self.pn
        w = pn.widgets
        self.model = w.Select(label="model", options=list(MODELS), value=model)
        self.distribution = w.Select(label="distribution (D)", options=list(DISTRIBUTIONS), value=distribution)
        self.masking = w.Select(label="masking (G)", options=list(MASKINGS), value=masking)
        self.fresnel = w.Select(label="Fresnel (F)", options=list(FRESNELS), value=fresnel)
        self.diffuse = w.Select(label="diffuse", options=list(DIFFUSES), value=diffuse)
        self.conductor = w.Select(label="conductor (metal's IOR; exact-conductor)",
                                  options=["none", *sorted(CONDUCTORS)],
                                  value=conductor or "none")
        rgb = np.asarray(base_color, dtype=float)
        self.base = [w.FloatSlider(label=f"base colour {c} (linear)", start=0.0, end=1.0, step=0.01, value=float(x))
                     for c, x in zip("RGB", rgb)]
        self.params = {}
        for name in V.PARAMETER_RANGES:  # each slider over its declared range, finite (views.SLIDER_RANGES)
            lo, hi = V.SLIDER_RANGES[name]
            self.params[name] = w.FloatSlider(label=name, start=lo, end=hi, step=0.01,
                                              value=min(max(float(params[name]), lo), hi))
        self.colours = {}  # the colour parameters (views.COLOUR_PARAMETERS): one slider per channel
        for name in V.COLOUR_RANGES:
            lo, hi = V.SLIDER_RANGES[name]
            rgb = np.broadcast_to(np.asarray(params[name], dtype=float), (3,))
            self.colours[name] = [w.FloatSlider(label=f"{name} {c} (linear)", start=lo, end=hi, step=0.01,
                                                value=min(max(float(x), lo), hi)) for c, x in zip("RGB", rgb)]
        deg = {k: round(math.degrees(v), 1) for k, v in angles.items()}
        self.theta_v = w.FloatSlider(label="theta_v (view, degrees)", start=0.0, end=89.0, step=0.5,
                                     value=deg["theta_v"])
        self.phi_v = w.FloatSlider(label="phi_v (view azimuth, 3D lobe, degrees)", start=0.0, end=360.0, step=1.0,
                                   value=0.0)
        self.light_theta = w.FloatSlider(label="theta_l (point light, degrees)", start=0.0, end=90.0, step=0.5,
                                         value=deg["light_theta"])
        self.light_phi = w.FloatSlider(label="phi_l (point light azimuth, degrees)", start=0.0, end=360.0,
                                       step=1.0, value=deg["light_phi"])
        self.theta_h = w.FloatSlider(label="theta_h (theta_d slice, degrees)", start=0.0, end=90.0, step=0.5,
                                     value=deg["theta_h"])
        self.theta_d = w.FloatSlider(label="theta_d (theta_h slice, degrees)", start=0.0, end=90.0, step=0.5,
                                     value=deg["theta_d"])
        self.phi_d = w.FloatSlider(label="phi_d (slices and image, degrees)", start=0.0, end=180.0, step=1.0,
                                   value=deg["phi_d"])
        self.exposure = w.FloatSlider(label="exposure (EV, spheres)", start=-6.0, end=6.0, step=0.25,
                                      value=float(exposure))
        self.compensation = w.Select(label="compensation (albedo view)", options=list(V.COMPENSATIONS),
                                     value=compensation)
        self.second = w.Select(label="second BRDF", options=list(SECOND_CHOICES[:1]) + list(MODELS)
                               + list(SECOND_CHOICES[1:]), value=second)
        self.merl_path = w.TextInput(label="MERL file (.binary)", placeholder="path/to/material.binary")
        self.merl_load = w.Button(label="load MERL", color="primary")
        self.fit_model = w.Select(label="fit model", options=["ggx", "disney"], value="ggx")
        self.fit_fresnel = w.Checkbox(label="fit with Fresnel", value=True)
        self.fit_weighting = w.Select(label="fit weighting", options=["log", "cosine"], value="log")
        self.fit_button = w.Button(label="fit to the measured BRDF", color="primary", disabled=True)

        groups = {
            "all": [self.model, self.distribution, self.masking, self.fresnel, self.diffuse, self.conductor,
                    *self.base, *self.params.values(), *self._colour_widgets(), self.second],
            "plane": [self.theta_v],
            "lobe": [self.phi_v],
            "slices": [self.theta_h, self.theta_d, self.phi_d],
            "spheres": [self.light_theta, self.light_phi, self.exposure],
            "albedo": [self.compensation],
        }
        for group, widgets in groups.items():
            for widget in widgets:
                widget.param.watch(lambda event, g=group: self._changed(g), "value")
        self.merl_load.on_click(lambda event: self._load_merl(show=True))
        self.fit_button.on_click(lambda event: self._fit())

    def _colour_widgets(self):
        return [widget for widgets in self.colours.values() for widget in widgets]

    def _sync_widgets(self):
        """Enable the widgets of the chosen model: terms for cook_torrance (filament:
        diffuse), parameters by :data:`pbrkit.explore.views.MODEL_PARAMETERS` and
        :data:`pbrkit.explore.views.COLOUR_PARAMETERS`."""
        model = self.model.value
        ct = model == "cook_torrance"
        for widget in (self.distribution, self.masking, self.fresnel):
            widget.disabled = not ct
        self.diffuse.disabled = model not in ("cook_torrance", "filament")
        for name, widget in self.params.items():
            widget.disabled = name not in V.MODEL_PARAMETERS[model] or (
                name == "anisotropy" and ct and self.distribution.value == "blinn-phong")
        for name, widgets in self.colours.items():
            for widget in widgets:
                widget.disabled = name not in V.COLOUR_PARAMETERS[model]

    # ------------------------------------------------------------ BRDFs

    def brdf_a(self, model=None):
        """The first BRDF (a :class:`~pbrkit.explore.views.ModelBRDF`) from the widgets
        (``model`` replaces the chosen model, for the second BRDF)."""
        model = model or self.model.value
        params = V.applicable_parameters(model, {**{k: w.value for k, w in self.params.items()},
                                                 **{k: tuple(w.value for w in ws) for k, ws in self.colours.items()}})
        terms = {}
        if model == "cook_torrance":
            terms = {"distribution": self.distribution.value, "masking": self.masking.value,
                     "fresnel": self.fresnel.value, "diffuse": self.diffuse.value}
            if terms["distribution"] == "blinn-phong":
                params.pop("anisotropy", None)  # an isotropic lobe
        elif model == "filament":
            own = V.model_choices("filament")["diffuse"]
            terms = {"diffuse": self.diffuse.value if self.diffuse.value in own and self.diffuse.value != "none"
                     else "lambert"}
        if self.conductor.value != "none":
            terms["conductor"] = self.conductor.value
        base = tuple(w.value for w in self.base)
        return V.model_brdf(model, base, self.params["metallic"].value, self.params["roughness"].value,
                            **terms, **{k: v for k, v in params.items() if k not in ("metallic", "roughness")})

    def brdf_b(self):
        """The second BRDF, or None."""
        choice = self.second.value
        if choice == "none":
            return None
        if choice == "measured":
            return self.measured
        if choice == "fit":
            return self.fitted
        return self.brdf_a(choice)

    # ------------------------------------------------------------ plots

    def _figure(self, title, x_label, y_label, **kwargs):
        from bokeh.plotting import figure

        kwargs.setdefault("tools", "pan,wheel_zoom,box_zoom,reset,save,hover")
        fig = figure(title=title, width=kwargs.pop("width", 420), height=kwargs.pop("height", 320),
                     toolbar_location="above", **kwargs)
        fig.xaxis.axis_label = x_label
        fig.yaxis.axis_label = y_label
        return fig

    def _source(self, name, **columns):
        from bokeh.models import ColumnDataSource

        src = ColumnDataSource(data=columns, name=name)
        self.sources[name] = src
        return src

    def _make_plots(self):
        from bokeh.models import ColorBar, LinearColorMapper
        from bokeh.palettes import RdBu11, Viridis256

        self.sources = {}
        f = {}
        empty = {"x": [], "y": []}
        # polar plot of f cos in the plane of incidence
        f["polar"] = self._figure("f cos θl in the plane of incidence (polar)", "x", "z (normal)",
                                  match_aspect=True)
        for k in "ab":
            f["polar"].line("x", "y", source=self._source(f"incidence_{k}", **empty), color=_COLOURS[k],
                            line_width=2, legend_label=k.upper())
        f["polar"].line("x", "y", source=self._source("view_ray", **empty), color="black", line_dash="dashed")
        # 3D lobe, projected
        f["lobe"] = self._figure("3D lobe: f cos θl over the hemisphere", "", "", match_aspect=True)
        for k in "ab":
            f["lobe"].multi_line("xs", "ys", source=self._source(f"lobe_{k}", xs=[], ys=[]), color=_COLOURS[k],
                                 line_alpha=0.6)
        f["lobe"].multi_line("xs", "ys", source=self._source("lobe_axes", xs=[], ys=[]), color="black",
                             line_dash="dashed")
        # slices
        f["theta_h"] = self._figure("θh slice (fixed θd, φd)", "θh (degrees)", "f (luminance, 1/sr)",
                                    y_axis_type="log", x_range=(0, 90))
        f["theta_d"] = self._figure("θd slice (fixed θh, φd)", "θd (degrees)", "f (luminance, 1/sr)",
                                    y_axis_type="log", x_range=(0, 90))
        for k in "ab":
            f["theta_h"].line("x", "y", source=self._source(f"theta_h_{k}", **empty), color=_COLOURS[k],
                              line_width=2, legend_label=k.upper())
            f["theta_d"].line("x", "y", source=self._source(f"theta_d_{k}", **empty), color=_COLOURS[k],
                              line_width=2, legend_label=k.upper())
        # half/difference images
        self.log_mapper = LinearColorMapper(palette=Viridis256, low=-3.0, high=2.0)
        for k in "ab":
            fig = self._figure(f"{k.upper()}: log10 f over (θh, θd)", "θh (degrees)", "θd (degrees)",
                               width=360, height=330, x_range=(0, 90), y_range=(0, 90))
            fig.image("image", x=0, y=0, dw=90, dh=90, source=self._source(f"image_{k}", image=[]),
                      color_mapper=self.log_mapper)
            f[f"image_{k}"] = fig
        f["image_a"].add_layout(ColorBar(color_mapper=self.log_mapper, width=8), "right")
        # albedo
        f["albedo"] = self._figure("directional albedo E(θv)", "θv (degrees)", "E", x_range=(0, 90),
                                   y_range=(0.0, 1.2))
        src = self._source("albedo_a", x=[], y=[], white=[], compensated=[], furnace=[])
        f["albedo"].line("x", "y", source=src, color=_COLOURS["a"], line_width=2, legend_label="A (luminance)")
        f["albedo"].line("x", "white", source=src, color="gray", line_width=2, legend_label="A, F = 1")
        f["albedo"].line("x", "compensated", source=src, color="green", line_dash="dashed", line_width=2,
                         legend_label="GGX F = 1, compensated")
        f["albedo"].line("x", "furnace", source=src, color="black", line_dash="dotted", legend_label="1")
        f["albedo"].line("x", "y", source=self._source("albedo_b", **empty), color=_COLOURS["b"], line_width=2,
                         legend_label="B (luminance)")
        f["albedo"].legend.location = "bottom_left"
        # spheres
        for kind, title in (("point", "point light"), ("env", "environment (bake)")):
            for k in "ab":
                fig = self._figure(f"{k.upper()}: {title}", "", "", width=300, height=300, x_range=(0, 1),
                                   y_range=(0, 1), tools="save")
                fig.image_rgba("image", x=0, y=0, dw=1, dh=1, source=self._source(f"sphere_{kind}_{k}", image=[]))
                fig.axis.visible = False
                f[f"sphere_{kind}_{k}"] = fig
        # compare
        f["difference"] = self._figure("B − A: f cos θl in the plane of incidence", "θl (degrees)",
                                       "Δ f cos (luminance)", x_range=(-90, 90))
        f["difference"].line("x", "y", source=self._source("difference", **empty), color="purple", line_width=2)
        self.ratio_mapper = LinearColorMapper(palette=RdBu11, low=-1.0, high=1.0, nan_color="white")
        fig = self._figure("log10 (B / A) over (θh, θd)", "θh (degrees)", "θd (degrees)", width=380, height=330,
                           x_range=(0, 90), y_range=(0, 90))
        fig.image("image", x=0, y=0, dw=90, dh=90, source=self._source("difference_image", image=[]),
                  color_mapper=self.ratio_mapper)
        fig.add_layout(ColorBar(color_mapper=self.ratio_mapper, width=8), "right")
        f["difference_image"] = fig
        self.diff_mapper = LinearColorMapper(palette=RdBu11, low=-0.5, high=0.5)
        fig = self._figure("B − A: point-lit sphere (luminance)", "", "", width=330, height=300, x_range=(0, 1),
                           y_range=(0, 1), tools="save,hover")
        fig.image("image", x=0, y=0, dw=1, dh=1, source=self._source("sphere_difference", image=[]),
                  color_mapper=self.diff_mapper)
        fig.add_layout(ColorBar(color_mapper=self.diff_mapper, width=8), "right")
        fig.axis.visible = False
        f["sphere_difference"] = fig
        # terms
        f["D"] = self._figure("D(θh)", "θh (degrees)", "D (1/sr)", y_axis_type="log", x_range=(0, 90))
        f["G"] = self._figure("G2(θl) in the plane of incidence", "θl (degrees)", "G2", x_range=(-90, 90),
                              y_range=(0.0, 1.05))
        f["F"] = self._figure("F(θd)", "θd (degrees)", "F", x_range=(0, 90), y_range=(0.0, 1.05))
        for k in "ab":
            dash = "solid" if k == "a" else "dashed"
            f["D"].line("x", "y", source=self._source(f"terms_d_{k}", **empty), color=_COLOURS[k], line_width=2,
                        line_dash=dash, legend_label=k.upper())
            f["G"].line("x", "y", source=self._source(f"terms_g_{k}", **empty), color=_COLOURS[k], line_width=2,
                        line_dash=dash, legend_label=k.upper())
            src = self._source(f"terms_f_{k}", x=[], r=[], g=[], b=[])
            for channel, colour in zip("rgb", _RGB):
                f["F"].line("x", channel, source=src, color=colour, line_width=2, line_dash=dash,
                            legend_label=f"{k.upper()} {channel.upper()}")
        f["F"].legend.location = "top_left"
        self.figures = f

    def _make_layout(self):
        pn = self.pn
        B = pn.pane.Bokeh
        f = self.figures
        side = pn.Column(
            pn.pane.Markdown("### pbrkit explore\nThe values are pbrkit's models, evaluated in Python."),
            self.model, self.distribution, self.masking, self.fresnel, self.diffuse, self.conductor,
            *self.base, *self.params.values(), *self._colour_widgets(),
            pn.pane.Markdown("**Angles**"), self.theta_v, self.phi_v, self.light_theta, self.light_phi,
            self.theta_d, self.theta_h, self.phi_d, self.exposure, self.compensation,
            pn.pane.Markdown("**Second BRDF and measured materials**"), self.second, self.merl_path,
            self.merl_load, self.fit_model, self.fit_fresnel, self.fit_weighting, self.fit_button, self.status,
            width=330)
        tabs = pn.Tabs(
            ("Lobe", pn.Row(B(f["polar"]), B(f["lobe"]))),
            ("Slices", pn.Column(pn.Row(B(f["theta_h"]), B(f["theta_d"])), pn.Row(B(f["image_a"]), B(f["image_b"])))),
            ("Albedo", pn.Row(B(f["albedo"]))),
            ("Spheres", pn.Column(pn.Row(B(f["sphere_point_a"]), B(f["sphere_point_b"])),
                                  pn.Row(B(f["sphere_env_a"]), B(f["sphere_env_b"])))),
            ("Compare", pn.Column(pn.Row(B(f["difference"]), B(f["difference_image"])),
                                  pn.Row(B(f["sphere_difference"])))),
            ("Terms", pn.Row(B(f["D"]), B(f["G"]), B(f["F"]))),
            dynamic=False)
        return pn.Row(side, tabs, sizing_mode="stretch_width")

    # ------------------------------------------------------------ updates

    #: The groups of views each group of widgets changes (``all``: the BRDFs).
    DEPENDS = {"plane": ("plane", "lobe", "terms", "compare"), "lobe": ("lobe",), "slices": ("slices", "compare"),
               "spheres": ("spheres", "compare"), "albedo": ("albedo",)}

    def _changed(self, group):
        if self._building:
            return
        if group == "all":
            self._sync_widgets()
            self.update_all()
            return
        if not self._brdfs():
            return
        for g in self.DEPENDS[group]:
            self._run(g)

    def _brdfs(self):
        """Build both BRDFs from the widgets; on bad input say why in the status and return False."""
        try:
            self._a, self._b = self.brdf_a(), self.brdf_b()
        except ValueError as exc:
            self.status.object = f"**error:** {exc}"
            return False
        if self.status.object.startswith("**error:**"):
            self.status.object = ""
        return True

    def update_all(self):
        """Recompute every view for the current widgets."""
        if not self._brdfs():
            return
        for group in ("plane", "lobe", "slices", "albedo", "spheres", "terms", "compare"):
            self._run(group)

    def _run(self, group):
        t0 = time.perf_counter()
        with V.view_threads(self.threads):
            getattr(self, f"_update_{group}")()
        self.timings[group] = time.perf_counter() - t0

    def _pairs(self):
        return (("a", self._a), ("b", self._b))

    def _update_plane(self):
        theta_v = math.radians(self.theta_v.value)
        for k, brdf in self._pairs():
            if brdf is None:
                self.sources[f"incidence_{k}"].data = {"x": [], "y": []}
                continue
            p = V.incidence_plane(brdf, theta_v)
            self.sources[f"incidence_{k}"].data = {"x": p["x"], "y": p["y"]}
            if k == "a":
                scale = max(float(np.max(p["value"])), 1e-6)
                self.sources["view_ray"].data = {"x": [0.0, scale * math.sin(theta_v)],
                                                 "y": [0.0, scale * math.cos(theta_v)]}

    def _update_lobe(self):
        theta_v, phi_v = math.radians(self.theta_v.value), math.radians(self.phi_v.value)
        scale = 1e-6
        for k, brdf in self._pairs():
            if brdf is None:
                self.sources[f"lobe_{k}"].data = {"xs": [], "ys": []}
                continue
            lobe = V.lobe_3d(brdf, theta_v, phi_v)
            scale = max(scale, float(np.max(lobe["radius"])))
            self.sources[f"lobe_{k}"].data = _wireframe(lobe)
            if k == "a":
                v = lobe["v"]
        axes = np.array([[[0, 0, 0], [0, 0, scale]], [[0, 0, 0], scale * v]])
        x, y = lobe_projection(axes)
        self.sources["lobe_axes"].data = {"xs": [list(r) for r in x], "ys": [list(r) for r in y]}

    def _update_slices(self):
        th, td, pd = (math.radians(w.value) for w in (self.theta_h, self.theta_d, self.phi_d))
        for k, brdf in self._pairs():
            if brdf is None:
                for name in (f"theta_h_{k}", f"theta_d_{k}"):
                    self.sources[name].data = {"x": [], "y": []}
                self.sources[f"image_{k}"].data = {"image": []}
                continue
            s = V.theta_h_slice(brdf, td, pd)
            self.sources[f"theta_h_{k}"].data = {"x": _deg(s["theta_h"]), "y": np.maximum(s["value"], 1e-6)}
            s = V.theta_d_slice(brdf, th, pd)
            self.sources[f"theta_d_{k}"].data = {"x": _deg(s["theta_d"]), "y": np.maximum(s["value"], 1e-6)}
            img = V.half_diff_image(brdf, pd)
            self.sources[f"image_{k}"].data = {"image": [np.where(img["valid"], img["log_value"], np.nan)]}

    def _update_albedo(self):
        for k, brdf in self._pairs():
            if brdf is None:
                self.sources["albedo_b"].data = {"x": [], "y": []}
                continue
            e = V.directional_albedo(brdf, compensation=self.compensation.value)
            x = _deg(e["theta_v"])
            if k == "a":
                nan = np.full(x.shape, np.nan)
                self.sources["albedo_a"].data = {
                    "x": x, "y": e["value"], "white": nan if e["white"] is None else e["white"],
                    "compensated": nan if e["compensated"] is None else e["compensated"], "furnace": e["furnace"]}
            else:
                self.sources["albedo_b"].data = {"x": x, "y": e["value"]}

    def _update_spheres(self):
        lt, lp = math.radians(self.light_theta.value), math.radians(self.light_phi.value)
        ev = self.exposure.value
        for k, brdf in self._pairs():
            if brdf is None:
                for kind in ("point", "env"):
                    self.sources[f"sphere_{kind}_{k}"].data = {"image": []}
                continue
            p = V.lit_sphere_point(brdf, lt, lp)
            self.sources[f"sphere_point_{k}"].data = {"image": [_rgba_image(p["radiance"], ev)]}
            e = V.lit_sphere_environment(brdf)
            self.sources[f"sphere_env_{k}"].data = {"image": [_rgba_image(e["radiance"], ev)]}

    def _update_terms(self):
        theta_v = math.radians(self.theta_v.value)
        for k, brdf in self._pairs():
            t = None if brdf is None else V.terms(brdf, theta_v)
            if t is None:
                for name in ("d", "g"):
                    self.sources[f"terms_{name}_{k}"].data = {"x": [], "y": []}
                self.sources[f"terms_f_{k}"].data = {"x": [], "r": [], "g": [], "b": []}
                continue
            self.sources[f"terms_d_{k}"].data = {"x": _deg(t["theta_h"]), "y": np.maximum(t["D"], 1e-6)}
            self.sources[f"terms_g_{k}"].data = {"x": _deg(t["theta_l"]), "y": t["G"]}
            self.sources[f"terms_f_{k}"].data = {"x": _deg(t["theta_d"]), "r": t["F"][:, 0], "g": t["F"][:, 1],
                                                 "b": t["F"][:, 2]}

    def _update_compare(self):
        if self._b is None:
            self.sources["difference"].data = {"x": [], "y": []}
            self.sources["difference_image"].data = {"image": []}
            self.sources["sphere_difference"].data = {"image": []}
            return
        c = V.compare(self._a, self._b, math.radians(self.theta_v.value), math.radians(self.phi_d.value),
                      math.radians(self.light_theta.value))
        self.sources["difference"].data = {"x": _deg(c["plane_a"]["theta_l"]), "y": c["value_difference"]}
        self.sources["difference_image"].data = {"image": [c["log_ratio"]]}
        from ..core.color import luminance

        self.sources["sphere_difference"].data = {"image": [np.flipud(luminance(c["sphere_difference"]))]}

    # ------------------------------------------------------------ measured

    def _load_merl(self, show=False):
        path = self.merl_path.value.strip()
        if not path:
            self.status.object = "**error:** give the path of a MERL file"
            return
        try:
            self.measured = read_measured(path)
        except ValueError as exc:
            self.status.object = f"**error:** {exc}"
            return
        self.fitted = None
        self.fit_button.disabled = False
        self.status.object = f"loaded **{self.measured.name}** ({path}); choose 'measured' as the second BRDF"
        if show:
            self.second.value = "measured"  # triggers the update

    def _fit(self):
        """Fit the chosen model to the loaded MERL BRDF (:func:`pbrkit.measured.fit.fit_measured`
        over directions within :data:`FIT_MAX_THETA` degrees of the normal)."""
        if self.measured is None:
            self.status.object = "**error:** load a MERL file first"
            return
        from ..measured.fit import FIT_MAX_THETA, fit_measured

        t0 = time.perf_counter()
        try:
            result = fit_measured(self.measured, model=self.fit_model.value, fresnel=self.fit_fresnel.value,
                                  weighting=self.fit_weighting.value, max_theta=FIT_MAX_THETA)
        except ValueError as exc:
            self.status.object = f"**error:** {exc}"
            return
        self.fitted = V.fitted_brdf(result)
        errors = ", ".join(f"{k} {v:.4g}" for k, v in result.error.items())
        parameters = ", ".join(f"{k} = {_short(v)}" for k, v in result.parameters.items())
        self.status.object = (f"fit of **{self.fit_model.value}** to {self.measured.name} in "
                              f"{time.perf_counter() - t0:.1f} s: {parameters}; error: {errors}")
        if self.second.value == "fit":
            self.update_all()
        else:
            self.second.value = "fit"


def read_measured(path):
    """:func:`pbrkit.measured.merl.read_merl`, shared by the sessions of a server: one
    :class:`~pbrkit.measured.merl.MerlBRDF` per file (and modification time), so that
    the views computed once per measured BRDF (its albedo, its environment sphere)
    are computed once per server."""
    import os

    try:
        st = os.stat(path)
        key = (os.path.abspath(path), st.st_mtime_ns, st.st_size)
    except OSError:
        key = (os.path.abspath(path), None, None)
    return _read_measured(str(path), key)


@functools.lru_cache(maxsize=4)
def _read_measured(path, key):
    from ..measured.merl import read_merl

    return read_merl(path)


def _short(value):
    a = np.asarray(value, dtype=float)
    if a.ndim == 0:
        return f"{float(a):.3g}"
    return "(" + ", ".join(f"{x:.3g}" for x in a.ravel()) + ")"


def explorer(**kwargs):
    """The explorer's Panel layout (:class:`Explorer`'s arguments); servable, and
    shown by Jupyter after ``panel.extension()``."""
    return Explorer(**kwargs).layout


def serve(port=0, open_browser=True, announce=print, **kwargs):
    """Serve the explorer on http://127.0.0.1:PORT/ (only the loopback address, and
    only to requests that name it: :mod:`pbrkit.explore.server`; port 0 picks a
    free one) until Ctrl-C; ``announce`` receives the URL once the server listens.
    Each browser session gets its own :class:`Explorer` built with ``kwargs``.  A
    port that cannot be bound raises :class:`pbrkit.explore.server.ListenError`."""
    from .server import run

    run(lambda: explorer(**kwargs), port=port, open_browser=open_browser, announce=announce)
