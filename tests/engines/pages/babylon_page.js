// Babylon.js (npm `babylonjs`, UMD global BABYLON) loads pbrkit's .env and RGBA16F DDS
// through its own public API, CubeTexture.CreateFromPrefilteredData, in a right-handed
// scene; then this page reads back what Babylon holds:
//
//   texels   every face of every level of the WebGL cube texture Babylon made
//            (texture.getInternalTexture()), attached to a framebuffer and read
//            with readPixels as RGBA float32: row 0 first = texel row t = 0;
//   samples  textureLod(cube, dir, lod) at the directions and levels of `dirs`
//            (float32 x, y, z, lod), drawn by a small raw WebGL2 pass on Babylon's
//            own GL context into an RGBA32F target, nearest filtering (a sampler
//            object, so Babylon's texture state is left alone): GL's own
//            direction -> face / texel mapping;
//   polynomial, lodGenerationScale   what the texture carries;
//   render   the centre pixel of a mirror PBR sphere (metallic 1, roughness 0,
//            reflectionTexture = the cube) seen from +x, -x, +z, -z: which cube
//            direction Babylon's shader samples for a world reflection direction;
//            renderLeftHanded: the same in a left-handed scene (the default).
//
// Floats are returned base64-encoded (little-endian float32).
const q = new URLSearchParams(location.search);
const B = window.BABYLON;

function b64(floats) {
  const bytes = new Uint8Array(floats.buffer, floats.byteOffset, floats.byteLength);
  let s = "";
  for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000));
  return btoa(s);
}

function vec(v) {
  return [v.x, v.y, v.z];
}

async function loadCube(url, scene) {
  const tex = B.CubeTexture.CreateFromPrefilteredData(url, scene);
  const t0 = performance.now();
  while (!tex.isReady()) {
    if (performance.now() - t0 > 60000) throw new Error(`${url}: not ready after 60 s`);
    await new Promise((ok) => setTimeout(ok, 20));
  }
  return tex;
}

function glTexture(tex) {
  const internal = tex.getInternalTexture();
  return internal._hardwareTexture ? internal._hardwareTexture.underlyingResource : internal._webGLTexture;
}

function readTexels(gl, webglTex, size) {
  const levels = Math.round(Math.log2(size)) + 1;
  let total = 0;
  for (let m = 0; m < levels; m++) total += 6 * (size >> m) * (size >> m) * 4;
  const out = new Float32Array(total);
  const fb = gl.createFramebuffer();
  gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
  let offset = 0;
  for (let m = 0; m < levels; m++) {
    const n = size >> m;
    for (let face = 0; face < 6; face++) {
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_CUBE_MAP_POSITIVE_X + face, webglTex, m);
      const status = gl.checkFramebufferStatus(gl.FRAMEBUFFER);
      if (status !== gl.FRAMEBUFFER_COMPLETE) throw new Error(`level ${m} face ${face}: framebuffer status 0x${status.toString(16)}`);
      gl.readPixels(0, 0, n, n, gl.RGBA, gl.FLOAT, out.subarray(offset, offset + n * n * 4));
      offset += n * n * 4;
    }
  }
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  gl.deleteFramebuffer(fb);
  return out;
}

const VS = `#version 300 es
void main() { vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2); gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0); }`;
const FS = `#version 300 es
precision highp float;
uniform highp samplerCube cube;
uniform highp sampler2D dirs;
out vec4 colour;
void main() {
  vec4 d = texelFetch(dirs, ivec2(gl_FragCoord.xy), 0);
  colour = textureLod(cube, d.xyz, d.w);
}`;

function compile(gl, type, source) {
  const s = gl.createShader(type);
  gl.shaderSource(s, source);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
  return s;
}

function sampleCube(gl, webglTex, dirs) {
  const count = dirs.length / 4;
  const width = Math.min(count, 256);
  const height = Math.ceil(count / width);
  const padded = new Float32Array(width * height * 4);
  padded.set(dirs);
  const prog = gl.createProgram();
  gl.attachShader(prog, compile(gl, gl.VERTEX_SHADER, VS));
  gl.attachShader(prog, compile(gl, gl.FRAGMENT_SHADER, FS));
  gl.linkProgram(prog);
  if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));

  const dirTex = gl.createTexture();
  gl.activeTexture(gl.TEXTURE1);
  gl.bindTexture(gl.TEXTURE_2D, dirTex);
  gl.pixelStorei(gl.UNPACK_FLIP_Y_WEBGL, false);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 4);
  gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, width, height, 0, gl.RGBA, gl.FLOAT, padded);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);

  gl.activeTexture(gl.TEXTURE0);
  gl.bindTexture(gl.TEXTURE_CUBE_MAP, webglTex);
  const sampler = gl.createSampler();
  gl.samplerParameteri(sampler, gl.TEXTURE_MIN_FILTER, gl.NEAREST_MIPMAP_NEAREST);
  gl.samplerParameteri(sampler, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
  gl.bindSampler(0, sampler);
  gl.bindSampler(1, null);

  const target = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_2D, target);
  gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, width, height, 0, gl.RGBA, gl.FLOAT, null);
  const fb = gl.createFramebuffer();
  gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
  gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, target, 0);
  gl.activeTexture(gl.TEXTURE0);
  gl.bindTexture(gl.TEXTURE_CUBE_MAP, webglTex);

  gl.useProgram(prog);
  gl.uniform1i(gl.getUniformLocation(prog, "cube"), 0);
  gl.uniform1i(gl.getUniformLocation(prog, "dirs"), 1);
  gl.viewport(0, 0, width, height);
  gl.disable(gl.BLEND);
  gl.disable(gl.DEPTH_TEST);
  gl.disable(gl.CULL_FACE);
  gl.disable(gl.SCISSOR_TEST);
  gl.colorMask(true, true, true, true);
  gl.bindVertexArray(null);
  gl.drawArrays(gl.TRIANGLES, 0, 3);
  const out = new Float32Array(width * height * 4);
  gl.readPixels(0, 0, width, height, gl.RGBA, gl.FLOAT, out);

  gl.bindSampler(0, null);
  gl.deleteSampler(sampler);
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  gl.deleteFramebuffer(fb);
  gl.deleteTexture(target);
  gl.deleteTexture(dirTex);
  gl.deleteProgram(prog);
  const err = gl.getError();
  if (err !== gl.NO_ERROR) throw new Error(`WebGL error 0x${err.toString(16)} in the sampling pass`);
  return out.subarray(0, count * 4);
}

async function renderMirror(engine, scene, tex, gl) {
  // A mirror sphere at the origin; the centre pixel reflects the view ray straight back,
  // so it shows the cube where Babylon looks for world direction = camera position.
  const sphere = B.MeshBuilder.CreateSphere("mirror", { diameter: 2, segments: 48 }, scene);
  const mat = new B.PBRMaterial("mirror", scene);
  mat.metallic = 1;
  mat.roughness = 0;
  mat.albedoColor = new B.Color3(1, 1, 1);
  mat.reflectionTexture = tex;
  sphere.material = mat;
  const views = { "+x": [5, 0, 0], "-x": [-5, 0, 0], "+z": [0, 0, 5], "-z": [0, 0, -5] };
  const out = {};
  for (const [name, p] of Object.entries(views)) {
    // a fresh camera per view: a camera's cached view matrix does not follow a handedness change
    const camera = new B.FreeCamera(`camera ${name}`, new B.Vector3(p[0], p[1], p[2]), scene);
    camera.fov = 0.5;
    camera.minZ = 0.1;
    camera.setTarget(B.Vector3.Zero());
    scene.activeCamera = camera;
    await scene.whenReadyAsync();
    scene.render();
    const px = new Uint8Array(4);
    gl.readPixels(32, 32, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
    out[name] = Array.from(px);
    scene.activeCamera = null;
    camera.dispose();
  }
  sphere.dispose();
  mat.dispose();
  return out;
}

async function main() {
  const canvas = document.getElementById("c");
  const engine = new B.Engine(canvas, false, { preserveDrawingBuffer: true, stencil: false, antialias: false });
  const gl = canvas.getContext("webgl2");
  if (!gl || engine.webGLVersion < 2) throw new Error("no WebGL2");
  if (!gl.getExtension("EXT_color_buffer_float")) throw new Error("no EXT_color_buffer_float");
  const scene = new B.Scene(engine);
  scene.useRightHandedSystem = true;
  scene.clearColor = new B.Color4(0, 0, 0, 1);
  scene.imageProcessingConfiguration.exposure = Number(q.get("exposure") || "1");
  const dirs = new Float32Array(await (await fetch(q.get("dirs"))).arrayBuffer());

  const report = { version: B.Engine.Version, renderer: gl.getParameter(gl.RENDERER), useRightHandedSystem: scene.useRightHandedSystem };
  for (const kind of ["env", "dds"]) {
    const url = q.get(kind);
    if (!url) continue;
    const tex = await loadCube(url, scene);
    const internal = tex.getInternalTexture();
    const size = internal.width;
    const webglTex = glTexture(tex);
    const render = await renderMirror(engine, scene, tex, gl);
    // the same views in a left-handed scene (Babylon's default), for comparison
    scene.useRightHandedSystem = false;
    scene.markAllMaterialsAsDirty(B.Constants.MATERIAL_AllDirtyFlag);
    const renderLeftHanded = await renderMirror(engine, scene, tex, gl);
    scene.useRightHandedSystem = true;
    scene.markAllMaterialsAsDirty(B.Constants.MATERIAL_AllDirtyFlag);
    engine.wipeCaches(true);
    const texels = readTexels(gl, webglTex, size);
    const samples = sampleCube(gl, webglTex, dirs);
    engine.wipeCaches(true);
    const sp = tex.sphericalPolynomial;
    const polynomial = sp ? Object.fromEntries(["x", "y", "z", "xx", "yy", "zz", "yz", "zx", "xy"].map((k) => [k, vec(sp[k])])) : null;
    report[kind] = {
      size,
      isCube: tex.isCube,
      type: internal.type,
      format: internal.format,
      invertZ: tex.invertZ,
      lodGenerationScale: tex.lodGenerationScale,
      polynomial,
      texels: b64(texels),
      samples: b64(samples),
      render,
      renderLeftHanded,
    };
  }
  window.__pbrkitResult = report;
}

main().catch((e) => {
  window.__pbrkitError = String(e && e.stack ? e.stack : e);
});
