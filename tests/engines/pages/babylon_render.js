// Babylon.js (npm `babylonjs`, UMD global BABYLON) renders a sphere grid lit only by a
// pbrkit bake, loaded through Babylon's own public API
// (CubeTexture.CreateFromPrefilteredData on babylon/environment.env, or the DDS), in a
// right-handed scene, with PBRMaterial spheres; the page reads back what it drew.
//
// Query: scene=/data/scene.json:
//   camera   {position, look_at, up, fov (vertical, degrees), width, height}: the canvas size
//   spheres  [{center, radius, base_color (linear), metallic, roughness}]
//   segments MeshBuilder.CreateSphere segments
//   env, dds  URLs of the bake's babylon/environment.env and babylon/specular.dds
//   generic  optional {url, lodScale}: the bake's generic specular.dds, for a diagnostic variant
//   lut      optional {url, size}: a DFG table (float32 RGBA, size x size, row 0 first = the
//            smoothest row; R = DFG1, G = DFG2) used as scene.environmentBRDFTexture in the
//            variants that ask for it (lut: "table"), in place of Babylon's own
//   variants [{name, texture: "env"|"dds"|"generic", lut: "babylon"|"table", brdf: {...}, material: {...}}]:
//            one linear render each; brdf / material override the settings below
//   engineOptions  optional extra Engine options (diagnostics, e.g. useExactSrgbConversions)
//   canvas   the variant whose canvas render (Babylon's own image processing, 8-bit) to return
//
// Each variant is rendered with scene.imageProcessingConfiguration.applyByPostProcess = true
// (no post-process attached: the material writes linear radiance, clamped to [0, 30]) into a
// float32 RenderTargetTexture and read back as float32 RGBA.  The canvas render is Babylon's
// default output path: image processing in the material (tone mapping off, exposure 1,
// contrast 1, no vignette / curves / grading / dithering), then its linear -> gamma
// conversion, 8-bit.
//
// Material settings (PBRMaterial, metallic workflow), everything else Babylon's default:
//   brdf.mixIblRadianceWithIrradiance = false  Babylon 8+ mixes the prefiltered radiance with
//       the irradiance by alphaG (MIX_IBL_RADIANCE_WITH_IRRADIANCE); pbrkit (and the split
//       sum) does not.
//   brdf.baseDiffuseModel = LAMBERT  the default E-Oren-Nayar bends the SH lookup direction
//       towards the view for a diffuse roughness > 0 (0 here, so no effect); Lambert is
//       what pbrkit does.
//   useRadianceOcclusion = false, useHorizonOcclusion = false  occlusion terms from an AO
//       texture / bump map (neither is used, so no effect); pbrkit has none.
//   enableSpecularAntiAliasing = false  adds screen-space normal variance to alphaG.
//   forceIrradianceInFragment = true  evaluate the SH per pixel (pbrkit does), not per vertex.
//   kept at Babylon's defaults and matched on pbrkit's side:
//   brdf.useEnergyConservation = true (MS_BRDF_ENERGY_CONSERVATION: specular x 1 + F0 (1/DFG.y - 1),
//       pbrkit's --energy-compensation), brdf.useLegacySpecularEnergyConservation = true
//       (diffuse colour base (1 - 0.04)(1 - metallic), no specular weight on the diffuse:
//       pbrkit's urp_mobile model), brdf.useSmithVisibilityHeightCorrelated = true,
//       brdf.useSphericalHarmonics = true (irradiance E / pi from the .env's polynomial).
const q = new URLSearchParams(location.search);
const B = window.BABYLON;

const MATERIAL = {
  useRadianceOcclusion: false,
  useHorizonOcclusion: false,
  enableSpecularAntiAliasing: false,
  forceIrradianceInFragment: true,
  environmentIntensity: 1,
};
const BRDF = {
  mixIblRadianceWithIrradiance: false,
  baseDiffuseModel: B.Constants.MATERIAL_DIFFUSE_MODEL_LAMBERT,
  useEnergyConservation: true,
  useLegacySpecularEnergyConservation: true,
  useSmithVisibilityHeightCorrelated: true,
  useSphericalHarmonics: true,
};
// material defines reported per variant (what the shader was compiled with)
const DEFINES = [
  "METALLICWORKFLOW", "REFLECTION", "REFLECTIONMAP_3D", "REFLECTIONMAP_OPPOSITEZ", "RGBDREFLECTION",
  "LODBASEDMICROSFURACE", "USESPHERICALFROMREFLECTIONMAP", "USESPHERICALINVERTEX", "SPHERICAL_HARMONICS",
  "ENVIRONMENTBRDF", "ENVIRONMENTBRDF_RGBD", "BRDF_V_HEIGHT_CORRELATED", "MS_BRDF_ENERGY_CONSERVATION",
  "LEGACY_SPECULAR_ENERGY_CONSERVATION", "MIX_IBL_RADIANCE_WITH_IRRADIANCE", "BASE_DIFFUSE_MODEL",
  "RADIANCEOCCLUSION", "HORIZONOCCLUSION", "SPECULARAA", "IMAGEPROCESSINGPOSTPROCESS", "IMAGEPROCESSING",
  "TONEMAPPING", "EXPOSURE", "CONTRAST", "VIGNETTE", "DITHER", "LINEARSPECULARREFLECTION",
  "REALTIME_FILTERING", "ALPHAFRESNEL", "SPECULARTERM",
];

function b64(view) {
  const bytes = new Uint8Array(view.buffer, view.byteOffset, view.byteLength);
  let s = "";
  for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000));
  return btoa(s);
}

function flipRows(data, width, height) {
  // GL read-backs start at the bottom row; return rows top first
  const row = width * 4;
  const out = new data.constructor(data.length);
  for (let y = 0; y < height; y++) out.set(data.subarray((height - 1 - y) * row, (height - y) * row), y * row);
  return out;
}

async function waitReady(thing, what) {
  const t0 = performance.now();
  while (!thing.isReady()) {
    if (performance.now() - t0 > 60000) throw new Error(`${what}: not ready after 60 s`);
    await new Promise((ok) => setTimeout(ok, 20));
  }
}

async function loadCube(url, scene) {
  const tex = B.CubeTexture.CreateFromPrefilteredData(url, scene);
  await waitReady(tex, url);
  return tex;
}

async function tableTexture(lut, scene) {
  const data = new Float32Array(await (await fetch(lut.url)).arrayBuffer());
  if (data.length !== lut.size * lut.size * 4) throw new Error(`${lut.url}: ${data.length} floats, expected ${lut.size ** 2 * 4}`);
  // row 0 of the data = v = 0 (invertY false): the table's smoothest row, as pbrkit samples it
  const tex = B.RawTexture.CreateRGBATexture(data, lut.size, lut.size, scene, false, false,
                                             B.Texture.BILINEAR_SAMPLINGMODE, B.Constants.TEXTURETYPE_FLOAT);
  tex.wrapU = B.Texture.CLAMP_ADDRESSMODE;
  tex.wrapV = B.Texture.CLAMP_ADDRESSMODE;
  await waitReady(tex, lut.url);
  return tex;
}

function definesOf(mesh) {
  const d = mesh.subMeshes[0].materialDefines;
  const out = {};
  for (const k of DEFINES) out[k] = d ? d[k] : null;
  return out;
}

async function renderReady(scene, rtt) {
  await scene.whenReadyAsync();
  for (let i = 0; i < 200; i++) {
    scene.render();
    if (!rtt || rtt.isReadyForRendering()) return;
    await new Promise((ok) => setTimeout(ok, 20));
  }
  throw new Error("render target never ready");
}

async function main() {
  const spec = await (await fetch(q.get("scene"))).json();
  const cam = spec.camera;
  const canvas = document.getElementById("c");
  canvas.width = cam.width;
  canvas.height = cam.height;
  const engine = new B.Engine(canvas, false, { preserveDrawingBuffer: true, stencil: false, antialias: false,
                                              ...(spec.engineOptions || {}) });
  engine.setHardwareScalingLevel(1);
  const gl = canvas.getContext("webgl2");
  if (!gl || engine.webGLVersion < 2) throw new Error("no WebGL2");
  if (!gl.getExtension("EXT_color_buffer_float")) throw new Error("no EXT_color_buffer_float");
  if (engine.getRenderWidth() !== cam.width || engine.getRenderHeight() !== cam.height) {
    throw new Error(`render size ${engine.getRenderWidth()} x ${engine.getRenderHeight()}`);
  }

  const scene = new B.Scene(engine);
  scene.useRightHandedSystem = true;
  scene.clearColor = new B.Color4(0, 0, 0, 0);
  scene.fogEnabled = false;
  const ip = scene.imageProcessingConfiguration;
  ip.toneMappingEnabled = false;
  ip.exposure = 1;
  ip.contrast = 1;
  ip.vignetteEnabled = false;
  ip.colorCurvesEnabled = false;
  ip.colorGradingEnabled = false;
  ip.ditheringEnabled = false;

  const textures = { env: await loadCube(spec.env, scene) };
  if (spec.dds) textures.dds = await loadCube(spec.dds, scene);
  if (spec.generic) {
    // diagnostic: pbrkit's generic chain (lod = r (M - 1), not z-mirrored) sampled the way
    // pbrkit samples it, through public texture settings: linearSpecularLOD gives
    // lod = log2(N) r lodGenerationScale, so scale = (M - 1) / log2(N); invertZ undoes the
    // right-handed scene's z negation (Babylon computes the SH from the DDS itself)
    const t = await loadCube(spec.generic.url, scene);
    t.linearSpecularLOD = true;
    t.lodGenerationScale = spec.generic.lodScale;
    t.invertZ = true;
    textures.generic = t;
  }
  // A PBRMaterial takes scene.environmentBRDFTexture when it is constructed (creating
  // Babylon's own, an RGBD PNG expanded to half float, when there is none), so the
  // materials are made per variant, after the DFG texture is chosen.
  new B.PBRMaterial("probe", scene).dispose();
  const babylonLut = scene.environmentBRDFTexture;
  if (!babylonLut) throw new Error("no default environmentBRDFTexture");
  await waitReady(babylonLut, "environmentBRDFTexture");
  const table = spec.lut ? await tableTexture(spec.lut, scene) : null;

  const camera = new B.UniversalCamera("camera", new B.Vector3(...cam.position), scene);
  camera.upVector = new B.Vector3(...cam.up);
  camera.fovMode = B.Camera.FOVMODE_VERTICAL_FIXED;
  camera.fov = (cam.fov * Math.PI) / 180;
  camera.minZ = 0.05;
  camera.maxZ = 100;
  camera.setTarget(new B.Vector3(...cam.look_at));
  scene.activeCamera = camera;

  const spheres = spec.spheres.map((s, i) => {
    const mesh = B.MeshBuilder.CreateSphere(`sphere${i}`, { diameter: 2 * s.radius, segments: spec.segments }, scene);
    mesh.position = new B.Vector3(...s.center);
    return mesh;
  });

  function configure(variant) {
    scene.environmentTexture = textures[variant.texture || "env"];
    scene.environmentBRDFTexture = variant.lut === "table" ? table : babylonLut;
    spec.spheres.forEach((s, i) => {
      const mesh = spheres[i];
      if (mesh.material) mesh.material.dispose();
      const mat = new B.PBRMaterial(`material${i}`, scene);
      mat.albedoColor = new B.Color3(...s.base_color);
      mat.metallic = s.metallic;
      mat.roughness = s.roughness;
      for (const [k, v] of Object.entries({ ...MATERIAL, ...(variant.material || {}) })) mat[k] = v;
      for (const [k, v] of Object.entries({ ...BRDF, ...(variant.brdf || {}) })) mat.brdf[k] = v;
      mesh.material = mat;
    });
  }

  const rtt = new B.RenderTargetTexture("linear", { width: cam.width, height: cam.height }, scene, false, true,
                                        B.Constants.TEXTURETYPE_FLOAT, false, B.Texture.NEAREST_SAMPLINGMODE, true);
  rtt.renderList = spheres;
  rtt.activeCamera = camera;
  rtt.clearColor = new B.Color4(0, 0, 0, 0);
  scene.customRenderTargets.push(rtt);

  const report = {
    version: B.Engine.Version,
    renderer: gl.getParameter(gl.RENDERER),
    useRightHandedSystem: scene.useRightHandedSystem,
    width: cam.width,
    height: cam.height,
    environment: {},
    variants: {},
  };
  for (const [k, t] of Object.entries(textures)) {
    report.environment[k] = { size: t.getSize().width, lodGenerationScale: t.lodGenerationScale, isRGBD: t.isRGBD,
                              invertZ: t.invertZ, hasPolynomial: !!t.sphericalPolynomial };
  }
  const lutSize = babylonLut.getSize();
  const lutTexels = await babylonLut.readPixels();
  report.brdfTexture = { isRGBD: babylonLut.isRGBD, width: lutSize.width, height: lutSize.height,
                         type: babylonLut.getInternalTexture().type, texelsKind: lutTexels.constructor.name,
                         texels: b64(lutTexels) };

  ip.applyByPostProcess = true; // linear output from the material
  for (const variant of spec.variants) {
    configure(variant);
    await renderReady(scene, rtt);
    const data = await rtt.readPixels();
    const floats = new Float32Array(data.buffer, data.byteOffset, data.byteLength / 4);
    report.variants[variant.name] = {
      linear: b64(flipRows(floats, cam.width, cam.height)),
      defines: definesOf(spheres[0]),
      metallicDefines: definesOf(spheres[spheres.length - 1]),
    };
  }
  scene.customRenderTargets.length = 0;

  if (spec.canvas) {
    ip.applyByPostProcess = false; // Babylon's own output path: image processing in the material
    configure(spec.variants.find((v) => v.name === spec.canvas));
    await renderReady(scene, null);
    scene.render();
    const px = new Uint8Array(cam.width * cam.height * 4);
    gl.readPixels(0, 0, cam.width, cam.height, gl.RGBA, gl.UNSIGNED_BYTE, px);
    report.canvas = { rgba: b64(flipRows(px, cam.width, cam.height)), defines: definesOf(spheres[0]) };
  }
  const err = gl.getError();
  if (err !== gl.NO_ERROR) throw new Error(`WebGL error 0x${err.toString(16)}`);
  window.__pbrkitResult = report;
}

main().catch((e) => {
  window.__pbrkitError = String(e && e.stack ? e.stack : e);
});
