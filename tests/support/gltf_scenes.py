"""Shared test helper: small glTF scenes written with pygltflib (a textured quad and a
camera looking at it), for the tests of the glTF loader, its material extensions and
the renderers that read them."""

from __future__ import annotations

import math

import numpy as np

from pbrkit.rendering.scene import Camera, EnvironmentSpec, GltfObject, Scene


def _png(pixels):
    import imageio.v3 as iio

    return iio.imwrite("<bytes>", np.asarray(pixels, dtype=np.uint8), extension=".png")


def write_quad_glb(path, *, texture=None, mr_texture=None, normal_texture=None, sampler=None, node_matrix=None,
                   extensions_required=(), uv=None, material_extras=None, light=None, alpha=None, base_alpha=1.0,
                   emissive=(0.2, 0.1, 0.0)):
    """A unit quad in the XY plane (z = 0, facing +Z) with glTF UVs (v down: image top at +Y),
    placed by a parent node (translation (0, 0, -1)) and a child node (matrix or scale 2)."""
    import pygltflib as g

    positions = np.array([[-0.5, -0.5, 0], [0.5, -0.5, 0], [0.5, 0.5, 0], [-0.5, 0.5, 0]], dtype=np.float32)
    normals = np.tile(np.array([0, 0, 1], dtype=np.float32), (4, 1))
    uvs = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], dtype=np.float32) if uv is None else np.asarray(uv, np.float32)
    indices = np.array([0, 1, 2, 0, 2, 3], dtype=np.uint16)
    chunks = [positions.tobytes(), normals.tobytes(), uvs.tobytes(), indices.tobytes()]
    images = []
    for tex in (texture, mr_texture, normal_texture):
        if tex is not None:
            images.append(_png(tex))
    blob = b""
    views = []
    for data in chunks + images:
        while len(blob) % 4:
            blob += b"\0"
        views.append(g.BufferView(buffer=0, byteOffset=len(blob), byteLength=len(data)))
        blob += data
    accessors = [
        g.Accessor(bufferView=0, componentType=g.FLOAT, count=4, type=g.VEC3, min=[-0.5, -0.5, 0], max=[0.5, 0.5, 0]),
        g.Accessor(bufferView=1, componentType=g.FLOAT, count=4, type=g.VEC3),
        g.Accessor(bufferView=2, componentType=g.FLOAT, count=4, type=g.VEC2),
        g.Accessor(bufferView=3, componentType=g.UNSIGNED_SHORT, count=6, type=g.SCALAR),
    ]
    pbr = g.PbrMetallicRoughness(baseColorFactor=[1.0, 0.5, 1.0, base_alpha], metallicFactor=0.5, roughnessFactor=0.8)
    gl_images, textures = [], []
    if texture is not None:
        gl_images.append(g.Image(bufferView=4, mimeType="image/png"))
        textures.append(g.Texture(source=0, sampler=0 if sampler else None))
        pbr.baseColorTexture = g.TextureInfo(index=0)
    if mr_texture is not None:
        gl_images.append(g.Image(bufferView=4 + len(gl_images), mimeType="image/png"))
        textures.append(g.Texture(source=len(gl_images) - 1))
        pbr.metallicRoughnessTexture = g.TextureInfo(index=len(textures) - 1)
    normal_info = None
    if normal_texture is not None:
        gl_images.append(g.Image(bufferView=4 + len(gl_images), mimeType="image/png"))
        textures.append(g.Texture(source=len(gl_images) - 1))
        normal_info = g.NormalMaterialTexture(index=len(textures) - 1, scale=1.0)
    material = g.Material(pbrMetallicRoughness=pbr, emissiveFactor=list(emissive), doubleSided=True,
                          extensions=material_extras or {}, normalTexture=normal_info, **(alpha or {}))
    child = g.Node(mesh=0)
    if node_matrix is not None:
        child.matrix = list(np.asarray(node_matrix, dtype=float).T.ravel())  # column-major
    else:
        child.scale = [2.0, 2.0, 2.0]
    nodes = [g.Node(children=[1], translation=[0.0, 0.0, -1.0]), child]
    extensions = {}
    if light is not None:
        nodes.append(g.Node(translation=[0.0, 3.0, 0.0], rotation=[-math.sin(math.pi / 4), 0.0, 0.0,
                                                                   math.cos(math.pi / 4)],
                            extensions={"KHR_lights_punctual": {"light": 0}}))
        extensions["KHR_lights_punctual"] = {"lights": [light]}
    gltf = g.GLTF2(
        asset=g.Asset(version="2.0"), scene=0, scenes=[g.Scene(nodes=[0] + ([2] if light else []))], nodes=nodes,
        meshes=[g.Mesh(primitives=[g.Primitive(attributes=g.Attributes(POSITION=0, NORMAL=1, TEXCOORD_0=2),
                                               indices=3, material=0)])],
        materials=[material], accessors=accessors, bufferViews=views, buffers=[g.Buffer(byteLength=len(blob))],
        images=gl_images, textures=textures,
        samplers=[g.Sampler(**sampler)] if sampler else [],
        extensionsRequired=list(extensions_required), extensionsUsed=list(extensions_required) + list(
            (material_extras or {}).keys()) + (["KHR_lights_punctual"] if light else []),
        extensions=extensions,
    )
    gltf.set_binary_blob(blob)
    gltf.save_binary(str(path))
    return path


def quad_scene(path, width=4, height=4, fov=20.0, color=(0.0, 0.0, 0.0)):
    """A camera 6 units in front of the quad of :func:`write_quad_glb` (looking down -Z), the
    model at ``path`` and a constant environment of ``color`` (black by default)."""
    cam = Camera(position=(0.0, 0.0, 5.0), look_at=(0.0, 0.0, -1.0), fov=fov, width=width, height=height)
    return Scene(camera=cam, environment=EnvironmentSpec(color=color), objects=(GltfObject(str(path)),))
