// pbrkit-three.js inside three.js (tests/engines/test_engine_three.py): load a pbrkit cube
// KTX2 with the shipped module, read every texel back from three's WebGL texture, and
// render with three's own materials to see which texel three samples for a direction
// and which level for a roughness.  Query: module (URL of the module, default
// /pbrkit-js/pbrkit-three.js), cube, levels (KTX2 names under /data),
// bad (comma-separated files the module must reject), dirs (JSON list of directions),
// roughness (JSON list).
import * as THREE from "three";
import { readCubeTexels, report } from "/pages/readback.js";

const q = new URLSearchParams(location.search);
// module: the pbrkit-three.js to test (default the package's; a bake ships a copy).
const { createPbrkitCubeTexture, loadPbrkitCubeKTX2 } = await import(q.get("module") || "/pbrkit-js/pbrkit-three.js");

// Mean of the central 2 x 2 pixels of a 4 x 4 float render of `scene` by `camera`.
function renderCentre(renderer, scene, camera) {
  const rt = new THREE.WebGLRenderTarget(4, 4, { type: THREE.FloatType, depthBuffer: true });
  renderer.setRenderTarget(rt);
  renderer.render(scene, camera);
  const px = new Float32Array(4 * 4 * 4);
  renderer.readRenderTargetPixels(rt, 0, 0, 4, 4, px);
  renderer.setRenderTarget(null);
  rt.dispose();
  const out = [0, 0, 0, 0];
  for (const [x, y] of [[1, 1], [1, 2], [2, 1], [2, 2]]) {
    for (let c = 0; c < 4; c++) out[c] += px[4 * (4 * y + x) + c] / 4;
  }
  return out;
}

function cameraAlong(d) {
  const camera = new THREE.PerspectiveCamera(1, 1, 0.01, 10);
  camera.position.set(0, 0, 0);
  camera.up.set(...(Math.abs(d[1]) > 0.9 ? [1, 0, 0] : [0, 1, 0]));
  camera.lookAt(new THREE.Vector3(...d));
  camera.updateMatrixWorld();
  return camera;
}

// A plane at distance 1 along d facing the camera (world normal -d).
function planeAlong(d, material) {
  const plane = new THREE.Mesh(new THREE.PlaneGeometry(1, 1), material);
  plane.position.set(...d);
  plane.lookAt(0, 0, 0);
  return plane;
}

report(async () => {
  const renderer = new THREE.WebGLRenderer({ canvas: document.getElementById("c"), antialias: false });
  const gl = renderer.getContext();
  const result = { three: THREE.REVISION };

  // Files the module must refuse, with its messages.
  result.rejected = {};
  for (const name of (q.get("bad") || "").split(",").filter(Boolean)) {
    const buffer = await (await fetch("/data/" + name)).arrayBuffer();
    try {
      createPbrkitCubeTexture(buffer, name);
      result.rejected[name] = null;
    } catch (e) {
      result.rejected[name] = String(e.message);
    }
  }

  const tex = await loadPbrkitCubeKTX2("/data/" + q.get("cube"));
  result.texture = {
    isCubeTexture: tex.isCubeTexture === true, isCompressedCubeTexture: tex.isCompressedCubeTexture === true,
    isPMREMTexture: tex.isPMREMTexture === true, format: tex.format, type: tex.type, flipY: tex.flipY,
    generateMipmaps: tex.generateMipmaps, minFilter: tex.minFilter,
    levels: tex.image[0].mipmaps.length, size: tex.image[0].width,
    constants: { RGBAFormat: THREE.RGBAFormat, HalfFloatType: THREE.HalfFloatType,
                 LinearMipmapLinearFilter: THREE.LinearMipmapLinearFilter },
  };

  // 1. Which texel three samples for world direction d: background and a mirror plane.
  const dirs = JSON.parse(q.get("dirs") || "[]");
  result.background = [];
  result.basic = [];
  for (const d of dirs) {
    const scene = new THREE.Scene();
    scene.background = tex;
    result.background.push(renderCentre(renderer, scene, cameraAlong(d)));
    // MeshBasicMaterial's envmap chunk handles only non-PMREM cubes (ENVMAP_TYPE_CUBE):
    // it gets the file loaded with { pmrem: false }; the PMREM-marked
    // texture itself is recorded too (three r187 ignores it there).
    const basicTex = await loadPbrkitCubeKTX2("/data/" + q.get("cube"), { pmrem: false });
    const mirror = new THREE.Scene();
    mirror.add(planeAlong(d, new THREE.MeshBasicMaterial({ color: 0xffffff, envMap: basicTex })));
    result.basic.push(renderCentre(renderer, mirror, cameraAlong(d)));
    const ignored = new THREE.Scene();
    ignored.add(planeAlong(d, new THREE.MeshBasicMaterial({ color: 0xffffff, envMap: tex })));
    result.basicPMREM = result.basicPMREM || [];
    result.basicPMREM.push(renderCentre(renderer, ignored, cameraAlong(d)));
  }

  // 2. Which level MeshStandardMaterial reads for a roughness (constant-per-level chain).
  result.standard = [];
  for (const r of JSON.parse(q.get("roughness") || "[]")) {
    const levelsTex = await loadPbrkitCubeKTX2("/data/" + q.get("levels"));
    const scene = new THREE.Scene();
    scene.environment = levelsTex;
    const material = new THREE.MeshStandardMaterial({ color: 0xffffff, metalness: 1, roughness: r });
    scene.add(planeAlong([0, 0, -1], material));
    result.standard.push(renderCentre(renderer, scene, cameraAlong([0, 0, -1])));
  }

  // 3. Every texel of every level of every face, read back from three's GL texture.
  renderer.initTexture(tex);
  const glTexture = renderer.properties.get(tex).__webglTexture;
  if (!glTexture) throw new Error("three holds no WebGL texture for the cube after initTexture");
  gl.bindTexture(gl.TEXTURE_CUBE_MAP, glTexture);
  result.gl = {
    immutableLevels: gl.getTexParameter(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_IMMUTABLE_LEVELS),
    minFilter: gl.getTexParameter(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MIN_FILTER),
    LINEAR_MIPMAP_LINEAR: gl.LINEAR_MIPMAP_LINEAR,
  };
  gl.bindTexture(gl.TEXTURE_CUBE_MAP, null);
  result.texels = readCubeTexels(gl, glTexture, result.texture.size, result.texture.levels);
  renderer.resetState();
  return result;
});
