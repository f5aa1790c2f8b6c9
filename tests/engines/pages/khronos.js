// pbrkit-khronos.js inside the Khronos glTF Sample Viewer 1.1.0
// (tests/engines/test_engine_khronos.py): load pbrkit's khronos folder into a real
// GltfView / GltfState with the shipped module, read the WebGL textures the state's
// environment holds back from the GPU, and render a sphere glTF (written by the test)
// with the viewer's own renderer.  Query: module (URL of the module, default
// /pbrkit-js/pbrkit-khronos.js), folder (under /data), gltf (file under /data,
// optional), renders (JSON list of {scene, rotation}).
import { GltfView, ResourceLoader } from "@khronosgroup/gltf-viewer";
import { read2DTexels, readCubeTexels, report } from "/pages/readback.js";

const q = new URLSearchParams(location.search);
// module: the pbrkit-khronos.js to test (default the package's; a bake ships a copy).
const { loadPbrkitEnvironment } = await import(q.get("module") || "/pbrkit-js/pbrkit-khronos.js");

report(async () => {
  const canvas = document.getElementById("c");
  const gl = canvas.getContext("webgl2", { antialias: false, alpha: false, preserveDrawingBuffer: true });
  if (!gl) throw new Error("no WebGL2");
  const view = new GltfView(gl);
  const state = view.createState();
  // createResourceLoader() needs the libktx / draco globals; loadGltf needs libPath for mikktspace.
  const loader = new ResourceLoader(view, "/node_modules/@khronosgroup/gltf-viewer/dist/libs/");

  const env = await loadPbrkitEnvironment(state, "/data/" + q.get("folder"));
  if (state.environment !== env) throw new Error("loadPbrkitEnvironment did not set state.environment");
  const result = { mipCount: env.mipCount, iblIntensityScale: env.iblIntensityScale, pbrkit: env.pbrkit };

  // The renderer draws, then the GL textures the state holds are read back.
  const gltf = q.get("gltf") ? await loader.loadGltf("/data/" + q.get("gltf")) : undefined;
  state.gltf = gltf;
  state.cameraIndex = 0;
  Object.assign(state.renderingParameters, {
    toneMap: "None (Linear mapping, clamped at 1.0)", exposure: 1.0, renderEnvironmentMap: false,
    clearColor: [0, 0, 0, 1], usePunctual: false, useIBL: true,
  });
  result.renders = [];
  for (const { scene, rotation } of JSON.parse(q.get("renders") || "[]")) {
    state.sceneIndex = scene;
    state.renderingParameters.environmentRotation = rotation;
    view.renderFrame(state, canvas.width, canvas.height);
    const px = new Uint8Array(4);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.readPixels((canvas.width - 1) / 2, (canvas.height - 1) / 2, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
    const err = gl.getError();
    if (err !== gl.NO_ERROR) throw new Error(`GL error 0x${err.toString(16)} after renderFrame`);
    result.renders.push({ scene, rotation, centre: Array.from(px) });
  }

  const e = state.environment;
  const glTextureOf = (info) => e.textures[info.index].glTexture;
  result.specular = readCubeTexels(gl, glTextureOf(e.specularEnvMap), env.pbrkit.specularSize, env.mipCount);
  result.lambertian = readCubeTexels(gl, glTextureOf(e.diffuseEnvMap), env.pbrkit.lambertianSize, 1);
  result.lut = read2DTexels(gl, glTextureOf(e.lut), ...env.pbrkit.lutSize);
  return result;
});
