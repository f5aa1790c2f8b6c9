"""Rendering a scene two ways with the same BRDF: real-time shading with an
IBL bake (:mod:`~pbrkit.rendering.realtime`) and Monte Carlo ground truth
(:mod:`~pbrkit.rendering.reference`), compared in :mod:`~pbrkit.rendering.compare`.

Scenes (:mod:`~pbrkit.rendering.scene`), punctual lights
(:mod:`~pbrkit.rendering.lights`, :mod:`~pbrkit.rendering.punctual`), geometry
(:mod:`~pbrkit.rendering.primitives` for spheres and planes,
:mod:`~pbrkit.rendering.gltf`, :mod:`~pbrkit.rendering.textures` and
:mod:`~pbrkit.rendering.tangents` for glTF meshes, :mod:`~pbrkit.rendering.geometry`
for ray casting and surface data), the environment light
(:mod:`~pbrkit.rendering.environment`), primary rays
(:mod:`~pbrkit.rendering.primary`) and the command (:mod:`~pbrkit.rendering.run`)."""
