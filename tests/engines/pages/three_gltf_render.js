// glTF files (tests/engines/test_engine_three_khr_extensions.py: the KHR_materials_* sphere grids)
// rendered by three.js r187 as three_render.js renders its sphere grid: scene.environment =
// loadPbrkitCubeKTX2(...) (the module pbrkit ships), scene.environmentIntensity, no lights,
// no tone mapping, sRGB output to the canvas, read back as 8-bit RGBA, a PerspectiveCamera
// built from pbrkit's camera description; the meshes and materials are GLTFLoader's (it makes
// a MeshPhysicalMaterial of a material with KHR_materials_clearcoat, _ior, _specular, _sheen,
// _iridescence or _anisotropy).  Several files in one page (one browser start).
// Query: cube (KTX2 under /data), scene (JSON: {assets: [{gltf (file under /data), camera:
// {position, look_at, up, fov, width, height}}], environment_intensity}).
// Result: {three, environmentLevels, images: [{width, height, rgba8, materials: [{name, type,
// tangents (the geometry has TANGENT), the physical parameters, normalMap / clearcoatNormalMap
// (size, filters, wraps, colour space) with normalScale / clearcoatNormalScale}]}]}.
import * as THREE from "three";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
import { report } from "/pages/readback.js";
import { loadPbrkitCubeKTX2 } from "/pbrkit-js/pbrkit-three.js";

const q = new URLSearchParams(location.search);

function toBase64(bytes) {
  let s = "";
  for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(s);
}

const PARAMETERS = ["metalness", "roughness", "ior", "specularIntensity", "clearcoat", "clearcoatRoughness",
                    "sheen", "sheenRoughness", "iridescence", "iridescenceIOR", "iridescenceThicknessMinimum",
                    "iridescenceThicknessMaximum", "anisotropy", "anisotropyRotation"];
const COLOURS = ["color", "emissive", "specularColor", "sheenColor"];

const MAPS = ["normalMap", "clearcoatNormalMap"];  // with their scales (normalScale, clearcoatNormalScale)

function summary(material, geometry) {
  const out = { name: material.name, type: material.type, tangents: geometry.attributes.tangent !== undefined };
  for (const p of PARAMETERS) if (material[p] !== undefined) out[p] = material[p];
  for (const c of COLOURS) if (material[c] !== undefined) out[c] = material[c].toArray();
  for (const m of MAPS) {
    const map = material[m];
    if (map) {
      out[m] = { width: map.image.width, height: map.image.height, minFilter: map.minFilter,
                 magFilter: map.magFilter, wrapS: map.wrapS, wrapT: map.wrapT, colorSpace: map.colorSpace };
      out[m.replace("Map", "Scale")] = material[m.replace("Map", "Scale")].toArray();
    }
  }
  return out;
}

report(async () => {
  const desc = JSON.parse(q.get("scene"));
  const canvas = document.getElementById("c");
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, alpha: false, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  renderer.toneMapping = THREE.NoToneMapping;
  renderer.outputColorSpace = THREE.SRGBColorSpace;
  renderer.setClearColor(0x000000, 1);
  const environment = await loadPbrkitCubeKTX2("/data/" + q.get("cube"));
  const loader = new GLTFLoader();
  const images = [];
  for (const asset of desc.assets) {
    const cam = asset.camera;
    renderer.setSize(cam.width, cam.height, false);
    const scene = new THREE.Scene();
    scene.environment = environment;
    scene.environmentIntensity = desc.environment_intensity ?? 1.0;
    const gltf = await loader.loadAsync("/data/" + asset.gltf);
    scene.add(gltf.scene);
    const materials = [];
    gltf.scene.traverse((o) => { if (o.isMesh) materials.push(summary(o.material, o.geometry)); });
    const camera = new THREE.PerspectiveCamera(cam.fov, cam.width / cam.height, 0.1, 100);
    camera.position.set(...cam.position);
    camera.up.set(...(cam.up || [0, 1, 0]));
    camera.lookAt(new THREE.Vector3(...cam.look_at));
    camera.updateMatrixWorld();
    renderer.render(scene, camera);
    const gl = renderer.getContext();
    const px = new Uint8Array(cam.width * cam.height * 4);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.readPixels(0, 0, cam.width, cam.height, gl.RGBA, gl.UNSIGNED_BYTE, px);
    const err = gl.getError();
    if (err !== gl.NO_ERROR) throw new Error(`GL error 0x${err.toString(16)} after rendering ${asset.gltf}`);
    images.push({ width: cam.width, height: cam.height, rgba8: toBase64(px), materials });
  }
  return { three: THREE.REVISION, environmentLevels: environment.image[0].mipmaps.length, images };
});
