"""Rendering a scene two ways with the same BRDF: real-time shading with an
IBL bake (:mod:`~pbrkit.render.realtime`) and Monte Carlo ground truth
(:mod:`~pbrkit.render.reference`), compared in :mod:`~pbrkit.render.compare`.

Scenes (:mod:`~pbrkit.render.scene`), punctual lights
(:mod:`~pbrkit.render.lights`, :mod:`~pbrkit.render.punctual`), geometry
(:mod:`~pbrkit.render.primitives` for spheres and planes,
:mod:`~pbrkit.render.gltf`, :mod:`~pbrkit.render.textures` and
:mod:`~pbrkit.render.tangents` for glTF meshes, :mod:`~pbrkit.render.geometry`
for ray casting and surface data), the environment light
(:mod:`~pbrkit.render.environment`), primary rays
(:mod:`~pbrkit.render.primary`) and the command (:mod:`~pbrkit.render.run`)."""
