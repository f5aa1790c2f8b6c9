// A sphere grid (a glTF written by tests/engines/test_engine_render_khronos.py) rendered by the
// Khronos glTF Sample Viewer 1.1.0 with a pbrkit bake loaded by the module pbrkit ships
// (loadPbrkitEnvironment), environmentRotation 0 (pbrkit's frame), tone map "None"
// (the viewer then writes pow(c, 1 / 2.2), clamped), no punctual lights, no background (but with background=1);
// the canvas is read back as 8-bit RGBA.  Query: folder (khronos folder under /data),
// gltf (file under /data), width, height, intensity (renderingParameters.iblIntensity),
// nosheen (1: load without the sheen files), background (1: renderEnvironmentMap with
// blurEnvironmentMap false, the bake's level 0 drawn behind everything, into the canvas
// and into the transmission framebuffer that getIBLVolumeRefraction reads; default: none).
import { GltfView, ResourceLoader } from "@khronosgroup/gltf-viewer";
import { report } from "/pages/readback.js";
import { loadPbrkitEnvironment } from "/pbrkit-js/pbrkit-khronos.js";

const q = new URLSearchParams(location.search);

function toBase64(bytes) {
  let s = "";
  for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(s);
}

report(async () => {
  const width = Number(q.get("width")), height = Number(q.get("height"));
  const canvas = document.getElementById("c");
  canvas.width = width;
  canvas.height = height;
  const gl = canvas.getContext("webgl2", { antialias: false, alpha: false, preserveDrawingBuffer: true });
  if (!gl) throw new Error("no WebGL2");
  const view = new GltfView(gl);
  const state = view.createState();
  const loader = new ResourceLoader(view, "/node_modules/@khronosgroup/gltf-viewer/dist/libs/");
  // nosheen=1: the sheen files left out (the module binds black textures, as before pbrkit baked sheen)
  const files = q.get("nosheen") === "1" ? { sheen: null, sheenLut: null, sheenE: null } : {};
  await loadPbrkitEnvironment(state, "/data/" + q.get("folder"), { files });
  state.gltf = await loader.loadGltf("/data/" + q.get("gltf"));
  state.sceneIndex = 0;
  state.cameraIndex = 0;
  Object.assign(state.renderingParameters, {
    toneMap: "None (Linear mapping, clamped at 1.0)", exposure: 1.0,
    renderEnvironmentMap: q.get("background") === "1", blurEnvironmentMap: false,
    clearColor: [0, 0, 0, 1], usePunctual: false, useIBL: true, environmentRotation: 0,
    iblIntensity: Number(q.get("intensity") || 1),
  });
  view.renderFrame(state, width, height);
  const px = new Uint8Array(width * height * 4);
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, px);
  const err = gl.getError();
  if (err !== gl.NO_ERROR) throw new Error(`GL error 0x${err.toString(16)} after renderFrame`);
  return { width, height, rgba8: toBase64(px), mipCount: state.environment.mipCount,
           sheen: state.environment.pbrkit.sheen };
});
