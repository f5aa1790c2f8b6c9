// A sphere grid rendered by three.js r187 with a pbrkit bake (tests/engines/test_engine_render_three.py):
// scene.environment = loadPbrkitCubeKTX2(...) (the module pbrkit ships), MeshStandardMaterial
// spheres, no lights, no tone mapping, sRGB output to the canvas, read back as 8-bit RGBA.
// Query: cube (KTX2 under /data), scene (JSON: {camera: {position, look_at, up, fov, width,
// height}, spheres: [{center, radius, base_color, metallic, roughness}], environment_intensity
// (scene.environmentIntensity, default 1)), segments (sphere
// width segments, default 128), float (1: also render into a float target and return linear RGB).
import * as THREE from "three";
import { report } from "/pages/readback.js";
import { loadPbrkitCubeKTX2 } from "/pbrkit-js/pbrkit-three.js";

const q = new URLSearchParams(location.search);

function toBase64(bytes) {
  let s = "";
  for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(s);
}

report(async () => {
  const desc = JSON.parse(q.get("scene"));
  const cam = desc.camera;
  const canvas = document.getElementById("c");
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, alpha: false, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  renderer.setSize(cam.width, cam.height, false);
  renderer.toneMapping = THREE.NoToneMapping;
  renderer.outputColorSpace = THREE.SRGBColorSpace;
  renderer.setClearColor(0x000000, 1);

  const scene = new THREE.Scene();
  scene.environment = await loadPbrkitCubeKTX2("/data/" + q.get("cube"));
  scene.environmentIntensity = desc.environment_intensity ?? 1.0;
  const segments = Number(q.get("segments") || 128);
  const geometry = new THREE.SphereGeometry(1, segments, segments / 2);
  for (const s of desc.spheres) {
    const color = new THREE.Color().setRGB(...s.base_color, THREE.LinearSRGBColorSpace);
    const material = new THREE.MeshStandardMaterial({ color, metalness: s.metallic, roughness: s.roughness });
    const mesh = new THREE.Mesh(geometry, material);
    mesh.position.set(...s.center);
    mesh.scale.setScalar(s.radius);
    scene.add(mesh);
  }
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
  if (err !== gl.NO_ERROR) throw new Error(`GL error 0x${err.toString(16)} after render`);
  const result = { three: THREE.REVISION, width: cam.width, height: cam.height, rgba8: toBase64(px),
                   environmentLevels: scene.environment.image[0].mipmaps.length };
  if (q.get("float") === "1") {
    // The same frame into a float target: three writes linear values there (no output transfer).
    const rt = new THREE.WebGLRenderTarget(cam.width, cam.height, { type: THREE.FloatType, depthBuffer: true });
    renderer.setRenderTarget(rt);
    renderer.render(scene, camera);
    const f = new Float32Array(cam.width * cam.height * 4);
    renderer.readRenderTargetPixels(rt, 0, 0, cam.width, cam.height, f);
    renderer.setRenderTarget(null);
    result.linear = toBase64(new Uint8Array(f.buffer));
  }
  return result;
});
