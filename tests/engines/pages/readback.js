// Read the texels an engine holds in a WebGL2 texture back from the GPU, with a small
// raw WebGL2 pass on the engine's own context: a full-screen triangle into an
// RGBA32F framebuffer, each fragment sampling the texture (NEAREST through a sampler
// object, so the engine's texture parameters are untouched) at a direction / texel
// given in a float texture.  Used by three.html and khronos.html.

const VS = `#version 300 es
void main() {
  vec2 p = vec2(float((gl_VertexID & 1) << 2), float((gl_VertexID & 2) << 1));
  gl_Position = vec4(p - 1.0, 0.0, 1.0);
}`;

const FS_CUBE = `#version 300 es
precision highp float;
uniform highp sampler2D uQuery;
uniform highp samplerCube uTex;
out vec4 outColor;
void main() {
  vec4 q = texelFetch(uQuery, ivec2(gl_FragCoord.xy), 0);
  outColor = textureLod(uTex, q.xyz, q.w);
}`;

const FS_2D = `#version 300 es
precision highp float;
uniform highp sampler2D uQuery;
uniform highp sampler2D uTex;
out vec4 outColor;
void main() {
  vec4 q = texelFetch(uQuery, ivec2(gl_FragCoord.xy), 0);
  outColor = textureLod(uTex, q.xy, q.w);
}`;

function program(gl, fs) {
  const p = gl.createProgram();
  for (const [type, src] of [[gl.VERTEX_SHADER, VS], [gl.FRAGMENT_SHADER, fs]]) {
    const s = gl.createShader(type);
    gl.shaderSource(s, src);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error("readback shader: " + gl.getShaderInfoLog(s));
    gl.attachShader(p, s);
  }
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error("readback link: " + gl.getProgramInfoLog(p));
  return p;
}

function floatTexture(gl, w, h, data) {
  const t = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_2D, t);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
  gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, w, h, 0, gl.RGBA, gl.FLOAT, data);
  return t;
}

// queries: Float32Array of (x, y, z, lod) for a cube or (u, v, 0, lod) for a 2D
// texture; returns a Float32Array of RGBA per query.
function run(gl, target, texture, queries) {
  if (!gl.getExtension("EXT_color_buffer_float")) throw new Error("readback needs EXT_color_buffer_float");
  const n = queries.length / 4;
  const w = Math.min(n, 64), h = Math.ceil(n / w);
  const padded = new Float32Array(w * h * 4);
  padded.set(queries);
  for (const e of [gl.BLEND, gl.DEPTH_TEST, gl.CULL_FACE, gl.SCISSOR_TEST, gl.STENCIL_TEST, gl.RASTERIZER_DISCARD]) {
    gl.disable(e);
  }
  gl.colorMask(true, true, true, true);
  gl.bindBuffer(gl.PIXEL_UNPACK_BUFFER, null);
  gl.bindBuffer(gl.PIXEL_PACK_BUFFER, null);
  gl.pixelStorei(gl.UNPACK_FLIP_Y_WEBGL, false);
  gl.pixelStorei(gl.UNPACK_PREMULTIPLY_ALPHA_WEBGL, false);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 4);
  gl.pixelStorei(gl.UNPACK_ROW_LENGTH, 0);
  gl.pixelStorei(gl.UNPACK_SKIP_ROWS, 0);
  gl.pixelStorei(gl.UNPACK_SKIP_PIXELS, 0);
  gl.pixelStorei(gl.PACK_ALIGNMENT, 4);

  const prog = program(gl, target === gl.TEXTURE_CUBE_MAP ? FS_CUBE : FS_2D);
  const vao = gl.createVertexArray();
  gl.activeTexture(gl.TEXTURE0);
  const queryTex = floatTexture(gl, w, h, padded);
  const outTex = floatTexture(gl, w, h, null);
  const fbo = gl.createFramebuffer();
  gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
  gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, outTex, 0);
  gl.drawBuffers([gl.COLOR_ATTACHMENT0]);
  if (gl.checkFramebufferStatus(gl.FRAMEBUFFER) !== gl.FRAMEBUFFER_COMPLETE) throw new Error("RGBA32F FBO incomplete");

  const sampler = gl.createSampler();
  gl.samplerParameteri(sampler, gl.TEXTURE_MIN_FILTER, gl.NEAREST_MIPMAP_NEAREST);
  gl.samplerParameteri(sampler, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
  for (const p of [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T, gl.TEXTURE_WRAP_R]) {
    gl.samplerParameteri(sampler, p, gl.CLAMP_TO_EDGE);
  }

  gl.useProgram(prog);
  gl.bindVertexArray(vao);
  gl.activeTexture(gl.TEXTURE0);
  gl.bindTexture(gl.TEXTURE_2D, queryTex);
  gl.bindSampler(0, null);
  gl.activeTexture(gl.TEXTURE1);
  gl.bindTexture(target, texture);
  gl.bindSampler(1, sampler);
  gl.uniform1i(gl.getUniformLocation(prog, "uQuery"), 0);
  gl.uniform1i(gl.getUniformLocation(prog, "uTex"), 1);
  gl.viewport(0, 0, w, h);
  gl.drawArrays(gl.TRIANGLES, 0, 3);
  const out = new Float32Array(w * h * 4);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT, out);
  const err = gl.getError();
  if (err !== gl.NO_ERROR) throw new Error(`readback: GL error 0x${err.toString(16)}`);

  gl.bindSampler(1, null);
  gl.bindTexture(target, null);
  gl.activeTexture(gl.TEXTURE0);
  gl.bindTexture(gl.TEXTURE_2D, null);
  gl.bindVertexArray(null);
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  gl.useProgram(null);
  for (const o of [queryTex, outTex]) gl.deleteTexture(o);
  gl.deleteFramebuffer(fbo);
  gl.deleteSampler(sampler);
  gl.deleteVertexArray(vao);
  gl.deleteProgram(prog);
  return out.subarray(0, n * 4);
}

// OpenGL 4.6 table 8.19 (pbrkit CONVENTIONS "Cube maps"): the direction of face f at
// face coordinates sc, tc in [-1, 1].
export function faceDirection(f, sc, tc) {
  return [[1, -tc, -sc], [-1, -tc, sc], [sc, 1, tc], [sc, -1, -tc], [sc, -tc, 1], [-sc, -tc, -1]][f];
}

// Every texel of levels 0..levels-1 of a size x size cube texture, sampled at its
// centre direction with lod = level (NEAREST): a plain array, order [level][face]
// [row][column][rgba], row 0 = t = 0.
export function readCubeTexels(gl, texture, size, levels) {
  const q = [];
  for (let m = 0; m < levels; m++) {
    const n = Math.max(1, size >> m);
    for (let f = 0; f < 6; f++) {
      for (let i = 0; i < n; i++) {
        for (let j = 0; j < n; j++) {
          q.push(...faceDirection(f, (2 * j + 1) / n - 1, (2 * i + 1) / n - 1), m);
        }
      }
    }
  }
  return Array.from(run(gl, gl.TEXTURE_CUBE_MAP, texture, new Float32Array(q)));
}

// Every texel of level 0 of a width x height 2D texture at its centre (NEAREST):
// order [row][column][rgba], row 0 = t = 0.
export function read2DTexels(gl, texture, width, height) {
  const q = [];
  for (let i = 0; i < height; i++) {
    for (let j = 0; j < width; j++) q.push((j + 0.5) / width, (i + 0.5) / height, 0, 0);
  }
  return Array.from(run(gl, gl.TEXTURE_2D, texture, new Float32Array(q)));
}

// Report helper: run `main` and set window.__pbrkitResult / __pbrkitError.
export function report(main) {
  main().then((r) => { window.__pbrkitResult = r; },
              (e) => { window.__pbrkitError = String(e && e.stack ? e.stack : e); });
}
