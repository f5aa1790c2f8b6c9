// Load pbrkit's KTX1 files with Filament's own public loaders and read back what
// Filament samples from them (tests/engines/test_engine_filament.py).
//
// /data/probe.json (written by the test) names the files and what to read:
//   {"ibl": "ibl.ktx", "sky": "sky.ktx", "skySize": N,
//    "skyViews": [{"forward": [x,y,z], "up": [x,y,z]}, ...],
//    "probes": [{"dir": [x,y,z], "roughness": r}, ...]}
//
// * The IBL file goes through `engine.createIblFromKtx1(buffer)` and the skybox file
//   through `engine.createSkyFromKtx1(buffer)`, nothing else touches their bytes.
// * Sky: a camera at the origin with a 90 degree vertical field of view and an
//   N x N viewport, looking along each `forward` with `up`, so that each pixel's
//   ray goes through one texel centre of level 0 (skybox.mat samples lod 0).
// * Probes: a glTF quad (gltfio, its ubershader material: base colour 1,
//   metallic 1, roughness r) facing the camera along `dir`, read at the one pixel
//   whose view ray hits its centre, where v = n = r = dir.  With f0 = 1 Filament's
//   specular IBL term is E * prefiltered(r, lod) * energyCompensation with
//   E = dfg.y and energyCompensation = 1 / dfg.y, so the pixel is the reflections
//   cube sampled at lod = (levels - 1) r (2 - r); the test picks r for integer lods.
// * Post-processing is off and the view renders into an RGBA32F render target;
//   its texture is read with gl.readPixels(FLOAT) through a framebuffer of our own
//   (Filament's JS API has no readPixels), so the values are float, not 8-bit.
// * The IBL file is also loaded with createSkyFromKtx1 and seen the same way
//   ("iblSky"), which shows its level 0 (the probes cannot reach lod 0: Filament
//   clamps the perceptual roughness from below).
// Result: {"shfloats", "sky": [[r,g,b,a, ...] per view, rows bottom first], "iblSky",
//          "probes": [[r,g,b,a] per probe], "iblLevels", "skyLevels", "glRenderer"}.

import { fail, fetchBytes, readFloatTarget, renderFrame as drawFrame } from "./filament_common.js";

const sleep = (ms) => new Promise((ok) => setTimeout(ok, ms));
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const normalize = (a) => scale(a, 1 / Math.hypot(a[0], a[1], a[2]));
const perpendicular = (d) => normalize(cross(d, Math.abs(d[1]) < 0.9 ? [0, 1, 0] : [1, 0, 0]));

// A GLB of one quad per material: node "q<i>" is a 2 x 2 square in the xy plane
// facing +z, with a metallic-roughness material (base colour 1, metallic 1,
// roughness r_i).
function quadsGlb(roughnesses) {
  const positions = new Float32Array([-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0]);
  const normals = new Float32Array([0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1]);
  const indices = new Uint16Array([0, 1, 2, 0, 2, 3, 0, 0]); // padded to 4 bytes
  const bin = new Uint8Array(48 + 48 + 16);
  bin.set(new Uint8Array(positions.buffer), 0);
  bin.set(new Uint8Array(normals.buffer), 48);
  bin.set(new Uint8Array(indices.buffer), 96);
  const gltf = {
    asset: { version: "2.0" },
    scene: 0,
    scenes: [{ nodes: roughnesses.map((_, i) => i) }],
    nodes: roughnesses.map((_, i) => ({ name: `q${i}`, mesh: i })),
    meshes: roughnesses.map((_, i) => ({
      primitives: [{ attributes: { POSITION: 0, NORMAL: 1 }, indices: 2, material: i }],
    })),
    materials: roughnesses.map((r, i) => ({
      name: `m${i}`,
      pbrMetallicRoughness: { baseColorFactor: [1, 1, 1, 1], metallicFactor: 1, roughnessFactor: r },
    })),
    buffers: [{ byteLength: bin.length }],
    bufferViews: [
      { buffer: 0, byteOffset: 0, byteLength: 48, target: 34962 },
      { buffer: 0, byteOffset: 48, byteLength: 48, target: 34962 },
      { buffer: 0, byteOffset: 96, byteLength: 12, target: 34963 },
    ],
    accessors: [
      { bufferView: 0, componentType: 5126, count: 4, type: "VEC3", min: [-1, -1, 0], max: [1, 1, 0] },
      { bufferView: 1, componentType: 5126, count: 4, type: "VEC3" },
      { bufferView: 2, componentType: 5123, count: 6, type: "SCALAR" },
    ],
  };
  let json = new TextEncoder().encode(JSON.stringify(gltf));
  const jsonLength = (json.length + 3) & ~3;
  const total = 12 + 8 + jsonLength + 8 + bin.length;
  const glb = new Uint8Array(total);
  const words = new DataView(glb.buffer);
  words.setUint32(0, 0x46546c67, true); // "glTF"
  words.setUint32(4, 2, true);
  words.setUint32(8, total, true);
  words.setUint32(12, jsonLength, true);
  words.setUint32(16, 0x4e4f534a, true); // "JSON"
  glb.fill(0x20, 20, 20 + jsonLength);
  glb.set(json, 20);
  words.setUint32(20 + jsonLength, bin.length, true);
  words.setUint32(24 + jsonLength, 0x004e4942, true); // "BIN"
  glb.set(bin, 28 + jsonLength);
  return glb;
}

async function main() {
  const probe = JSON.parse(new TextDecoder().decode(await fetchBytes("probe.json")));
  await new Promise((ok) => Filament.init([], ok));

  const canvas = document.getElementById("c");
  const engine = Filament.Engine.create(canvas);
  const gl = engine.context;
  const scene = engine.createScene();
  const renderer = engine.createRenderer();
  const swapChain = engine.createSwapChain();
  const camera = engine.createCamera(Filament.EntityManager.get().create());
  camera.setExposureDirect(1.0);
  renderer.setClearOptions({ clearColor: [0, 0, 0, 0], clear: true });

  // Filament's own loaders, on the files exactly as pbrkit wrote them.
  const ibl = engine.createIblFromKtx1(await fetchBytes(probe.ibl));
  ibl.setIntensity(1.0); // iblLuminance = intensity x exposure = 1
  scene.setIndirectLight(ibl);
  const sky = engine.createSkyFromKtx1(await fetchBytes(probe.sky));
  scene.setSkybox(sky);

  const n = probe.skySize;
  const Usage = { COLOR_ATTACHMENT: 1, DEPTH_ATTACHMENT: 2, SAMPLEABLE: 16 };
  const color = Filament.Texture.Builder().width(n).height(n).levels(1)
    .sampler(Filament.Texture$Sampler.SAMPLER_2D).format(Filament.Texture$InternalFormat.RGBA32F)
    .usage(Usage.COLOR_ATTACHMENT | Usage.SAMPLEABLE).build(engine);
  const depth = Filament.Texture.Builder().width(n).height(n).levels(1)
    .sampler(Filament.Texture$Sampler.SAMPLER_2D).format(Filament.Texture$InternalFormat.DEPTH32F)
    .usage(Usage.DEPTH_ATTACHMENT).build(engine);
  const target = Filament.RenderTarget.Builder()
    .texture(Filament.RenderTarget$AttachmentPoint.COLOR, color)
    .texture(Filament.RenderTarget$AttachmentPoint.DEPTH, depth)
    .build(engine);

  const view = engine.createView();
  view.setScene(scene);
  view.setCamera(camera);
  view.setRenderTarget(target);
  view.setPostProcessingEnabled(false);

  const renderFrame = () => drawFrame(renderer, swapChain, view);

  const readTarget = (w, h) => Array.from(readFloatTarget(gl, w, h, n, n));

  // Sky: one N x N view per face; then the same with the IBL file loaded as a
  // skybox too (createSkyFromKtx1 of its bytes), which shows level 0 of the IBL.
  const skyViews = async () => {
    const images = [];
    view.setViewport([0, 0, n, n]);
    camera.setProjectionFov(90, 1, 0.05, 10, Filament.Camera$Fov.VERTICAL);
    for (const { forward, up } of probe.skyViews) {
      camera.lookAt([0, 0, 0], forward, up);
      await renderFrame();
      images.push(readTarget(n, n));
    }
    return images;
  };
  const skyImages = await skyViews();
  scene.setSkybox(engine.createSkyFromKtx1(await fetchBytes(probe.ibl)));
  const iblSkyImages = await skyViews();
  scene.setSkybox(sky);

  // Probes: quads of the IBL's roughness levels, one 3 x 3 view each.
  const roughnesses = [...new Set(probe.probes.map((p) => p.roughness))];
  const loader = engine.createAssetLoader();
  const asset = loader.createAsset(quadsGlb(roughnesses));
  if (!asset) throw new Error("gltfio could not create the quad asset");
  await new Promise((ok) => asset.loadResources(ok, null, null, 1));
  const quads = roughnesses.map((_, i) => asset.getEntitiesByName(`q${i}`)[0]);
  const tcm = engine.getTransformManager();
  const probeValues = [];
  view.setViewport([0, 0, 3, 3]);
  camera.setProjectionFov(10, 1, 0.5, 20, Filament.Camera$Fov.VERTICAL);
  for (const { dir, roughness } of probe.probes) {
    const d = normalize(dir);
    const quad = quads[roughnesses.indexOf(roughness)];
    const x = perpendicular(d);
    const y = cross(d, x);
    // Column-major model matrix taking the quad's +z to d, at the origin.
    tcm.setTransform(tcm.getInstance(quad), [...x, 0, ...y, 0, ...d, 0, 0, 0, 0, 1]);
    scene.addEntity(quad);
    camera.lookAt(scale(d, 5), [0, 0, 0], y);
    await renderFrame();
    const pixels = readTarget(3, 3);
    probeValues.push(pixels.slice(16, 20)); // pixel (1, 1): the ray through the quad's centre
    scene.remove(quad);
  }

  window.__pbrkitResult = {
    shfloats: ibl.shfloats,
    sky: skyImages,
    iblSky: iblSkyImages,
    probes: probeValues,
    iblLevels: ibl.getReflectionsTexture().getLevels(engine),
    skyLevels: sky.getTexture().getLevels(engine),
    glRenderer: gl.getParameter(gl.RENDERER),
  };
}

main().catch(fail);
