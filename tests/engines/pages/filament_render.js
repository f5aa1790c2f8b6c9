// Filament renders a sphere grid lit by pbrkit's `--target filament` bake
// (tests/engines/test_engine_render_filament.py), for comparison with
// `pbrkit render --mode realtime` of the same scene.
//
// /data/render.json (written by the test):
//   {"glb": "spheres.glb", "ibl": "filament/ibl.ktx", "sky": "filament/skybox.ktx",
//    "width": W, "height": H,
//    "camera": {"eye": [x,y,z], "center": [x,y,z], "up": [x,y,z], "fov": deg, "near": n, "far": f},
//    "variants": [{"sh": true, "specularAAVariance": null}, ...]}
//
// * The IBL file goes through `engine.createIblFromKtx1(buffer)`; the light is built
//   as the bake's manifest says, IndirectLight.Builder().reflections(
//   ibl.getReflectionsTexture()).irradianceSh(3, ibl.shfloats), intensity 1 (with
//   setExposureDirect(1) the shader's iblLuminance is 1).  The skybox file goes
//   through `engine.createSkyFromKtx1(buffer)` (background only; not compared).
// * The spheres are the test's glTF (one UV-sphere mesh per material), loaded by
//   gltfio's AssetLoader with its built-in ubershader materials.
// * Camera: setProjectionFov(fov, W / H, near, far, VERTICAL) and lookAt(eye,
//   center, up), the pbrkit scene's pinhole camera.
// * No punctual lights; post-processing off (no tone mapping, no dithering, no
//   anti-aliasing): the view renders into an RGBA32F render target that is read
//   back with gl.readPixels(FLOAT), so the values are Filament's linear radiance.
// * Variants (one page load): "sh": false builds the light with all-zero SH
//   (specular IBL alone; Filament's SH sentinel is only for a light built without
//   irradiance, so zeros really mean no diffuse); "specularAAVariance": a number
//   sets the ubershader's `_specularAntiAliasingVariance` (the value behind
//   MaterialInstance::setSpecularAntiAliasingVariance, default 0.15) on every
//   material instance, 0 switching gltfio's specular anti-aliasing off.
// Result: {"images": [[r,g,b,a, ...] per variant, rows bottom first], "glRenderer",
//          "iblLevels", "shfloats"}.

import { fail, fetchBytes, readFloatTarget, renderFrame as drawFrame } from "./filament_common.js";

async function main() {
  const job = JSON.parse(new TextDecoder().decode(await fetchBytes("render.json")));
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

  // Filament's own loaders, on the bake's files as pbrkit wrote them.
  const loaded = engine.createIblFromKtx1(await fetchBytes(job.ibl));
  const reflections = loaded.getReflectionsTexture();
  const shfloats = loaded.shfloats;
  if (!shfloats || shfloats.length !== 27) throw new Error("createIblFromKtx1 gave no 27 shfloats");
  scene.setSkybox(engine.createSkyFromKtx1(await fetchBytes(job.sky)));

  const loader = engine.createAssetLoader();
  const asset = loader.createAsset(await fetchBytes(job.glb));
  if (!asset) throw new Error("gltfio could not create the sphere asset");
  await new Promise((ok) => asset.loadResources(ok, null, null, 1));
  scene.addEntities(asset.getEntities());
  // the material instance of each sphere (FilamentInstance.getMaterialInstances is
  // not bound in the 1.53.4 build: go through the RenderableManager)
  const rm = engine.getRenderableManager();
  const materials = asset.getRenderableEntities().map((e) => rm.getMaterialInstanceAt(rm.getInstance(e), 0));

  const { width: w, height: h } = job;
  const Usage = { COLOR_ATTACHMENT: 1, DEPTH_ATTACHMENT: 2, SAMPLEABLE: 16 };
  const color = Filament.Texture.Builder().width(w).height(h).levels(1)
    .sampler(Filament.Texture$Sampler.SAMPLER_2D).format(Filament.Texture$InternalFormat.RGBA32F)
    .usage(Usage.COLOR_ATTACHMENT | Usage.SAMPLEABLE).build(engine);
  const depth = Filament.Texture.Builder().width(w).height(h).levels(1)
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
  view.setViewport([0, 0, w, h]);
  view.setPostProcessingEnabled(false);
  const cam = job.camera;
  camera.setProjectionFov(cam.fov, w / h, cam.near, cam.far, Filament.Camera$Fov.VERTICAL);
  camera.lookAt(cam.eye, cam.center, cam.up);

  const renderFrame = () => drawFrame(renderer, swapChain, view);

  const readTarget = () => Array.from(readFloatTarget(gl, w, h), (x) => Math.round(x * 1e6) / 1e6);

  const images = [];
  for (const variant of job.variants) {
    const sh = variant.sh === false ? new Array(27).fill(0) : shfloats;
    const light = Filament.IndirectLight.Builder().reflections(reflections).irradianceSh(3, sh)
      .intensity(1.0).build(engine);
    scene.setIndirectLight(light);
    if (variant.specularAAVariance != null) {
      for (const mi of materials) mi.setFloatParameter("_specularAntiAliasingVariance", variant.specularAAVariance);
    }
    await renderFrame();
    await renderFrame(); // the first frame after a change may still use the previous uniforms
    images.push(readTarget());
  }

  window.__pbrkitResult = {
    images,
    glRenderer: gl.getParameter(gl.RENDERER),
    iblLevels: reflections.getLevels(engine),
    shfloats: Array.from(shfloats),
    materials: materials.length,
  };
}

main().catch(fail);
