// pbrkit-three.js: load a pbrkit bake (`pbrkit bake --target three`) into three.js.
//
// The file is an uncompressed KTX 2.0 cube map, VK_FORMAT_R16G16B16A16_SFLOAT,
// faces +X -X +Y -Y +Z -Z, every level of the prefiltered chain stored.  three's
// KTX2Loader (r187) turns such a file into a 2D DataTexture (it ignores the face
// count of uncompressed files), so this module reads it itself and builds a
// THREE.CompressedCubeTexture (RGBAFormat + HalfFloatType: three uploads it face by
// face and level by level with texSubImage2D).
//
// PMREM: the texture is marked `isPMREMTexture = true`, so three uses the chain as
// it is instead of re-filtering it with its PMREMGenerator.  three then reads level
// lod = (M - 1) r (2 - r) for roughness r (Filament's curve), which is why the three
// bake stores level m at r_m = 1 - sqrt(1 - m / (M - 1)); its diffuse term is pi
// times the last (roughness 1) level.
//
// x mirror: three samples a cube texture that is not a render target at
// (-d.x, d.y, d.z) for the world direction d (the `flipEnvMap` / envMapRotation
// premultiply of WebGLMaterials and WebGLBackground).  The three bake is written
// already mirrored, C(b) = L(-b.x, b.y, b.z), so three shows L(d) in world
// direction d.  A generic (unmirrored) pbrkit cube loaded with this module would
// appear mirrored in x.
//
// Materials: MeshStandardMaterial / MeshPhysicalMaterial (scene.environment or
// envMap) and scene.background take the texture as is.  three r187's MeshBasic /
// MeshLambert / MeshPhong env-map code samples only cubes *not* marked as PMREM
// (it ignores this texture); give them one loaded with { pmrem: false }.
//
// Usage:
//   import { loadPbrkitCubeKTX2 } from "./pbrkit-three.js";
//   const env = await loadPbrkitCubeKTX2("bake/three/specular.ktx2");
//   scene.environment = env;          // or material.envMap = env
//
// Depends only on "three" (tested with three 0.187.0).
import {
  CompressedCubeTexture,
  HalfFloatType,
  LinearFilter,
  LinearMipmapLinearFilter,
  LinearSRGBColorSpace,
  RGBAFormat,
} from "three";

const KTX2_IDENTIFIER = [0xab, 0x4b, 0x54, 0x58, 0x20, 0x32, 0x30, 0xbb, 0x0d, 0x0a, 0x1a, 0x0a];
const VK_FORMAT_R16G16B16A16_SFLOAT = 97;

/**
 * Parse the bytes of a KTX 2.0 cube written by pbrkit (uncompressed RGBA16F, six
 * faces).  Returns {size, levels: [[face0, ..., face5] (Uint16Array each), ...]},
 * level 0 first.  Throws an Error for anything else.
 */
export function parsePbrkitCubeKTX2(buffer, name = "KTX2 file") {
  const bytes = buffer instanceof ArrayBuffer ? new Uint8Array(buffer)
    : new Uint8Array(buffer.buffer, buffer.byteOffset, buffer.byteLength);
  const fail = (why) => { throw new Error(`${name}: ${why}`); };
  if (bytes.length < 80 || KTX2_IDENTIFIER.some((b, i) => bytes[i] !== b)) fail("not a KTX 2.0 file");
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const u32 = (at) => view.getUint32(at, true);
  const u64 = (at) => view.getUint32(at, true) + 2 ** 32 * view.getUint32(at + 4, true);
  const vkFormat = u32(12), width = u32(20), height = u32(24), depth = u32(28);
  const layers = u32(32), faces = u32(36), levelCount = Math.max(1, u32(40)), scheme = u32(44);
  if (vkFormat !== VK_FORMAT_R16G16B16A16_SFLOAT) {
    fail(`vkFormat ${vkFormat} is not supported: pbrkit-three loads only R16G16B16A16_SFLOAT (97) cube maps ` +
         "(bake with --target three)");
  }
  if (scheme !== 0) fail(`supercompressionScheme ${scheme}: only uncompressed files are supported`);
  if (faces !== 6) fail(`faceCount ${faces}: not a cube map`);
  if (depth !== 0 || layers !== 0) fail("array and 3D textures are not supported");
  if (width !== height || width === 0) fail(`cube faces must be square, got ${width} x ${height}`);
  if (80 + 24 * levelCount > bytes.length) fail("file ends inside the level index");
  const levels = [];
  for (let m = 0; m < levelCount; m++) {
    const offset = u64(80 + 24 * m), length = u64(88 + 24 * m);
    const n = Math.max(1, width >> m);
    const faceBytes = n * n * 8;
    if (length !== 6 * faceBytes) fail(`level ${m}: ${length} bytes, expected ${6 * faceBytes}`);
    if (offset + length > bytes.length) fail(`level ${m} extends past the end of the file`);
    const level = [];
    for (let f = 0; f < 6; f++) {
      const start = bytes.byteOffset + offset + f * faceBytes;
      level.push(start % 2 === 0 ? new Uint16Array(bytes.buffer, start, faceBytes / 2)
        : new Uint16Array(bytes.slice(offset + f * faceBytes, offset + (f + 1) * faceBytes).buffer));
    }
    levels.push(level);
  }
  return { size: width, levels };
}

/**
 * A THREE.CompressedCubeTexture holding every level of every face of a pbrkit
 * RGBA16F cube KTX2 (ArrayBuffer or typed array), ready to use as
 * `scene.environment` / `material.envMap` without PMREM.  `pmrem: false` leaves
 * `isPMREMTexture` unset (for MeshBasic/Lambert/Phong env maps, see above).
 */
export function createPbrkitCubeTexture(buffer, name, { pmrem = true } = {}) {
  const { size, levels } = parsePbrkitCubeKTX2(buffer, name);
  const faces = [];
  for (let f = 0; f < 6; f++) {
    const mipmaps = levels.map((level, m) => {
      const n = Math.max(1, size >> m);
      return { data: level[f], width: n, height: n };
    });
    faces.push({ width: size, height: size, mipmaps });
  }
  const texture = new CompressedCubeTexture(faces, RGBAFormat, HalfFloatType);
  texture.flipY = false;
  texture.generateMipmaps = false;
  texture.minFilter = LinearMipmapLinearFilter;
  texture.magFilter = LinearFilter;
  texture.colorSpace = LinearSRGBColorSpace;
  texture.isPMREMTexture = pmrem; // true: use the baked chain as it is (no PMREMGenerator)
  texture.name = name || "pbrkit cube";
  texture.needsUpdate = true;
  return texture;
}

/** Fetch `url` and return {@link createPbrkitCubeTexture} of it (a Promise). */
export async function loadPbrkitCubeKTX2(url, options) {
  const response = await fetch(url);
  if (!response.ok) throw new Error(`${url}: HTTP ${response.status}`);
  return createPbrkitCubeTexture(await response.arrayBuffer(), String(url), options);
}
