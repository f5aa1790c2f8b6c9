// pbrkit-khronos.js: load a pbrkit bake (`pbrkit bake --target khronos`) into the
// Khronos glTF Sample Viewer (npm @khronosgroup/gltf-viewer, tested with 1.1.0).
//
// The folder holds
//   specular.ktx2    GGX-prefiltered radiance, RGBA16F cube, M levels, level m at
//                    roughness m / (M - 1) (the viewer's lod = r (u_MipCount - 1))
//   lambertian.ktx2  Lambertian radiance E / pi, RGBA16F cube, one level
//   lut_ggx.ktx2     the (A, B) split-sum table (specular = F0 A + B), R16G16 float,
//                    u = n.v, v = roughness, row 0 = roughness 0
//   charlie.ktx2     Charlie-prefiltered radiance (KHR_materials_sheen IBL), RGBA16F
//                    cube, as many levels as specular.ktx2, level m at sheen roughness
//                    m / (M - 1) (the viewer's lod = sheenRoughness (u_MipCount - 1))
//   lut_charlie.ktx2 (0, 0, E_sheen, 1), RGBA16F: the viewer reads .b, u = n.v,
//                    v = sheen roughness
//   lut_sheen_E.ktx2 (E_sheen, 0), R16G16 float: the viewer reads .r (albedo scaling)
// all in pbrkit's cube layout, which is the viewer's (no mirror).  The three sheen
// files are optional: a folder without them (a bake from before pbrkit baked sheen)
// gets 1 x 1 black sheen textures, as before.
//
// The viewer's public API (GltfView, GltfState, ResourceLoader) loads environments
// only from a Radiance .hdr, which it re-filters on the GPU.  There is no entry point
// for pre-filtered textures, so this module builds the object that
// ResourceLoader.loadEnvironment returns (GltfState.environment) itself and fills it
// with WebGL textures made from the three files.  It relies on these internals of
// gltf-viewer 1.1.0 (dist/gltf-viewer.module.js: _loadEnvironmentFromPanorama,
// gltfWebGl.setTexture, gltfRenderer.applyEnvironmentMap, EnvironmentRenderer):
//   * state.environment fields read by the renderer: diffuseEnvMap, specularEnvMap,
//     sheenEnvMap, lut, sheenLUT, sheenELUT (texture infos {index, texCoord, linear,
//     generateMips}), mipCount (u_MipCount), iblIntensityScale;
//   * environment.textures[i] = {sampler, source, type, glTexture, initialized}: a
//     texture with glTexture set and initialized = true is bound as it is (no upload,
//     no sampler state applied), environment.images[source] must exist
//     ({mimeType: "image/texture" (ImageMimeType.GLTEXTURE), image: glTexture});
//   * the texture types it samples: samplerCube for the three env maps, sampler2D for
//     the LUTs (u_GGXLUT read as .rg).
// sheenEnvMap, sheenLUT and sheenELUT are charlie.ktx2, lut_charlie.ktx2 and
// lut_sheen_E.ktx2 when the folder has them (HTTP 404: a 1 x 1 black texture, and
// KHR_materials_sheen gets no image-based sheen; `files: {sheen: null}` skips them).
// The viewer rotates environment lookups about +Y by
// state.renderingParameters.environmentRotation (default 90 degrees: world +Z sees
// the cube's +X); set it to 0 to see pbrkit's frame unchanged.
//
// Usage:
//   import { GltfView } from "@khronosgroup/gltf-viewer";
//   import { loadPbrkitEnvironment } from "./pbrkit-khronos.js";
//   const view = new GltfView(gl), state = view.createState();
//   await loadPbrkitEnvironment(state, "bake/khronos/");   // sets state.environment
//
// No dependency (it uses only the WebGL2 context of the view).

const KTX2_IDENTIFIER = [0xab, 0x4b, 0x54, 0x58, 0x20, 0x32, 0x30, 0xbb, 0x0d, 0x0a, 0x1a, 0x0a];
const VK_FORMATS = { 97: { name: "R16G16B16A16_SFLOAT", channels: 4 }, 83: { name: "R16G16_SFLOAT", channels: 2 } };
const SHEEN_FILES = { sheen: "charlie.ktx2", sheenLut: "lut_charlie.ktx2", sheenE: "lut_sheen_E.ktx2" };
const GLTEXTURE_MIME = "image/texture"; // ImageMimeType.GLTEXTURE of gltf-viewer 1.1.0

/**
 * Parse an uncompressed KTX 2.0 file written by pbrkit with a half-float format
 * (R16G16B16A16_SFLOAT or R16G16_SFLOAT), 2D or cube.  Returns {vkFormat, channels,
 * width, height, faces, levels: [[Uint16Array per face], ...]}, level 0 first.
 */
export function parsePbrkitKTX2(buffer, name = "KTX2 file") {
  const bytes = buffer instanceof ArrayBuffer ? new Uint8Array(buffer)
    : new Uint8Array(buffer.buffer, buffer.byteOffset, buffer.byteLength);
  const fail = (why) => { throw new Error(`${name}: ${why}`); };
  if (bytes.length < 80 || KTX2_IDENTIFIER.some((b, i) => bytes[i] !== b)) fail("not a KTX 2.0 file");
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const u32 = (at) => view.getUint32(at, true);
  const u64 = (at) => view.getUint32(at, true) + 2 ** 32 * view.getUint32(at + 4, true);
  const vkFormat = u32(12), width = u32(20), height = u32(24), depth = u32(28);
  const layers = u32(32), faces = u32(36), levelCount = Math.max(1, u32(40)), scheme = u32(44);
  const format = VK_FORMATS[vkFormat];
  if (!format) fail(`vkFormat ${vkFormat} is not supported (R16G16B16A16_SFLOAT 97 or R16G16_SFLOAT 83)`);
  if (scheme !== 0) fail(`supercompressionScheme ${scheme}: only uncompressed files are supported`);
  if (faces !== 1 && faces !== 6) fail(`faceCount ${faces} must be 1 or 6`);
  if (depth !== 0 || layers !== 0) fail("array and 3D textures are not supported");
  if (width === 0 || height === 0 || (faces === 6 && width !== height)) fail(`bad size ${width} x ${height}`);
  if (80 + 24 * levelCount > bytes.length) fail("file ends inside the level index");
  const levels = [];
  for (let m = 0; m < levelCount; m++) {
    const offset = u64(80 + 24 * m), length = u64(88 + 24 * m);
    const w = Math.max(1, width >> m), h = Math.max(1, height >> m);
    const faceBytes = w * h * 2 * format.channels;
    if (length !== faces * faceBytes) fail(`level ${m}: ${length} bytes, expected ${faces * faceBytes}`);
    if (offset + length > bytes.length) fail(`level ${m} extends past the end of the file`);
    const level = [];
    for (let f = 0; f < faces; f++) {
      const start = offset + f * faceBytes;
      level.push((bytes.byteOffset + start) % 2 === 0
        ? new Uint16Array(bytes.buffer, bytes.byteOffset + start, faceBytes / 2)
        : new Uint16Array(bytes.slice(start, start + faceBytes).buffer));
    }
    levels.push(level);
  }
  return { vkFormat, channels: format.channels, width, height, faces, levels };
}

function prepareUpload(gl) {
  gl.bindBuffer(gl.PIXEL_UNPACK_BUFFER, null);
  gl.pixelStorei(gl.UNPACK_FLIP_Y_WEBGL, false);
  gl.pixelStorei(gl.UNPACK_PREMULTIPLY_ALPHA_WEBGL, false);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 4);
  gl.pixelStorei(gl.UNPACK_ROW_LENGTH, 0);
  gl.pixelStorei(gl.UNPACK_SKIP_ROWS, 0);
  gl.pixelStorei(gl.UNPACK_SKIP_PIXELS, 0);
}

/** A WebGL2 texture (cube or 2D, every level) of a parsed half-float KTX2. */
export function uploadPbrkitKTX2(gl, ktx) {
  const cube = ktx.faces === 6;
  const target = cube ? gl.TEXTURE_CUBE_MAP : gl.TEXTURE_2D;
  const [internal, format] = ktx.channels === 4 ? [gl.RGBA16F, gl.RGBA] : [gl.RG16F, gl.RG];
  const texture = gl.createTexture();
  prepareUpload(gl);
  gl.bindTexture(target, texture);
  gl.texStorage2D(target, ktx.levels.length, internal, ktx.width, ktx.height);
  ktx.levels.forEach((level, m) => {
    const w = Math.max(1, ktx.width >> m), h = Math.max(1, ktx.height >> m);
    level.forEach((data, f) => {
      gl.texSubImage2D(cube ? gl.TEXTURE_CUBE_MAP_POSITIVE_X + f : gl.TEXTURE_2D, m, 0, 0, w, h, format,
                       gl.HALF_FLOAT, data);
    });
  });
  gl.texParameteri(target, gl.TEXTURE_MIN_FILTER, ktx.levels.length > 1 ? gl.LINEAR_MIPMAP_LINEAR : gl.LINEAR);
  gl.texParameteri(target, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
  gl.texParameteri(target, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
  gl.texParameteri(target, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
  if (cube) gl.texParameteri(target, gl.TEXTURE_WRAP_R, gl.CLAMP_TO_EDGE);
  gl.bindTexture(target, null);
  return texture;
}

function blank(gl, cube, channels) {
  const n = channels === 4 ? 4 : 2;
  const level = Array.from({ length: cube ? 6 : 1 }, () => new Uint16Array(n));
  return uploadPbrkitKTX2(gl, { faces: cube ? 6 : 1, channels: n, width: 1, height: 1, levels: [level] });
}

function contextOf(target) {
  const view = target && (target.context ? target : target.view || target._view);
  const gl = view && view.context;
  if (!gl || typeof gl.texStorage2D !== "function") {
    throw new Error("pbrkit-khronos: pass a GltfView, GltfState or ResourceLoader with a WebGL2 context");
  }
  return gl;
}

/**
 * Build a Sample Viewer environment (the object ResourceLoader.loadEnvironment
 * returns) from pbrkit's khronos files.  `target`: a GltfState (its environment is
 * set), GltfView or ResourceLoader.  `folder`: URL of the khronos folder, or
 * `files: {specular, lambertian, lut, sheen, sheenLut, sheenE}` (URLs or ArrayBuffers;
 * the three sheen files optional: null, or a URL answering 404, gives black) in
 * `options`.  Returns the environment; `environment.pbrkit` records what was loaded.
 */
export async function loadPbrkitEnvironment(target, folder = "", options = {}) {
  const gl = contextOf(target);
  const base = folder && !folder.endsWith("/") ? folder + "/" : folder;
  const files = { specular: base + "specular.ktx2", lambertian: base + "lambertian.ktx2", lut: base + "lut_ggx.ktx2",
                  ...Object.fromEntries(Object.entries(SHEEN_FILES).map(([key, name]) => [key, base + name])),
                  ...(options.files || {}) };
  const parsed = {};
  for (const [key, file] of Object.entries(files)) {
    const optional = key in SHEEN_FILES;
    if (optional && (file === null || file === undefined)) continue;
    let buffer = file;
    if (!(file instanceof ArrayBuffer) && !ArrayBuffer.isView(file)) {
      const response = await fetch(file);
      if (optional && response.status === 404) continue;
      if (!response.ok) throw new Error(`${file}: HTTP ${response.status}`);
      buffer = await response.arrayBuffer();
    }
    parsed[key] = parsePbrkitKTX2(buffer, typeof file === "string" ? file : key);
  }
  const { specular, lambertian, lut, sheen, sheenLut, sheenE } = parsed;
  if (specular.faces !== 6 || specular.channels !== 4) throw new Error("specular.ktx2 must be an RGBA16F cube");
  if (lambertian.faces !== 6 || lambertian.channels !== 4) throw new Error("lambertian.ktx2 must be an RGBA16F cube");
  if (lut.faces !== 1) throw new Error("lut_ggx.ktx2 must be a 2D table");
  if (sheen && (sheen.faces !== 6 || sheen.channels !== 4)) throw new Error("charlie.ktx2 must be an RGBA16F cube");
  if (sheen && sheen.levels.length !== specular.levels.length) {
    throw new Error(`charlie.ktx2 has ${sheen.levels.length} levels, specular.ktx2 ${specular.levels.length}: ` +
                    "the viewer samples both with one u_MipCount");
  }
  if (sheenLut && (sheenLut.faces !== 1 || sheenLut.channels !== 4)) {
    throw new Error("lut_charlie.ktx2 must be an RGBA16F 2D table (the viewer reads .b)");
  }
  if (sheenE && sheenE.faces !== 1) throw new Error("lut_sheen_E.ktx2 must be a 2D table");

  const environment = { images: [], textures: [], samplers: [], mipCount: specular.levels.length,
                        iblIntensityScale: 1.0 };
  const add = (key, glTexture, cube) => {
    const type = cube ? gl.TEXTURE_CUBE_MAP : gl.TEXTURE_2D;
    const mipmapped = key === "specularEnvMap" || (key === "sheenEnvMap" && sheen);
    environment.samplers.push({ name: key, magFilter: gl.LINEAR, wrapS: gl.CLAMP_TO_EDGE, wrapT: gl.CLAMP_TO_EDGE,
                                minFilter: mipmapped ? gl.LINEAR_MIPMAP_LINEAR : gl.LINEAR });
    environment.images.push({ mimeType: GLTEXTURE_MIME, image: glTexture, type, miplevel: 0, name: key });
    const index = environment.textures.length;
    environment.textures.push({ sampler: index, source: index, type, glTexture, initialized: true,
                                mipLevelCount: 0 });
    environment[key] = { index, texCoord: 0, linear: true, samplerName: "", strength: 1, scale: 1,
                         generateMips: false, extensions: undefined };
  };
  add("diffuseEnvMap", uploadPbrkitKTX2(gl, lambertian), true);
  add("specularEnvMap", uploadPbrkitKTX2(gl, specular), true);
  add("sheenEnvMap", sheen ? uploadPbrkitKTX2(gl, sheen) : blank(gl, true, 4), true);
  add("lut", uploadPbrkitKTX2(gl, lut), false);
  add("sheenLUT", sheenLut ? uploadPbrkitKTX2(gl, sheenLut) : blank(gl, false, 4), false);
  add("sheenELUT", sheenE ? uploadPbrkitKTX2(gl, sheenE) : blank(gl, false, 4), false);
  environment.pbrkit = { files, specularSize: specular.width, specularLevels: specular.levels.length,
                         lambertianSize: lambertian.width, lutSize: [lut.width, lut.height],
                         lutChannels: lut.channels, sheen: Boolean(sheen && sheenLut && sheenE),
                         sheenSize: sheen ? sheen.width : 0, sheenLutSize: sheenLut ? [sheenLut.width, sheenLut.height] : [0, 0],
                         sheenESize: sheenE ? [sheenE.width, sheenE.height] : [0, 0] };
  if (target && "environment" in target && "renderingParameters" in target) target.environment = environment;
  return environment;
}
