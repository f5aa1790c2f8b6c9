// Evaluate pbrkit's generated GLSL (pbrkit shaders -o DATA/shaders) in WebGL2 and
// report the numbers (tests/shaders/test_shaders.py compares them with pbrkit's Python).
//
// /data/cases.json: {files: [...], width: W, cases: [{name, expr, count, inputs:
// [in0, in1, ...]}], lut: {width, height, data}, cube: {size, levels: [faces...]},
// sh: [27 floats]}.  Case k's inputs are up to twelve arrays of 4 * count floats,
// uploaded as RGBA32F textures u_in0..u_in11 (W texels wide, sample i at texel
// (i % W, i / W)); its fragment shader reads them as vec4 a, b, ..., l and writes
// expr (a float or vector, padded to a vec4) into an RGBA32F framebuffer, read back with readPixels.
const fail = (message) => { window.__pbrkitError = String(message); };

async function text(path) {
  const response = await fetch(path);
  if (!response.ok) throw new Error(`${path}: HTTP ${response.status}`);
  return response.text();
}

function compile(gl, type, source, name) {
  const shader = gl.createShader(type);
  gl.shaderSource(shader, source);
  gl.compileShader(shader);
  if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) {
    throw new Error(`${name}: compile error: ${gl.getShaderInfoLog(shader)}`);
  }
  return shader;
}

function program(gl, vertex, fragmentSource, name) {
  const p = gl.createProgram();
  gl.attachShader(p, vertex);
  gl.attachShader(p, compile(gl, gl.FRAGMENT_SHADER, fragmentSource, name));
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(`${name}: link error: ${gl.getProgramInfoLog(p)}`);
  return p;
}

const INPUTS = 12;  // texture units 0..7 and 10..13; the table on 8, the cube on 9
const NAMES = "abcdefghijkl";
const inputUnit = (k) => (k < 8 ? k : k + 2);
const SCRATCH_UNIT = 15;  // textures are created on this unit, so that creating one unbinds nothing in use

function floatTexture(gl, width, height, data, filter, format = gl.RGBA32F) {
  const tex = gl.createTexture();
  gl.activeTexture(gl.TEXTURE0 + SCRATCH_UNIT);
  gl.bindTexture(gl.TEXTURE_2D, tex);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  const channels = { [gl.RGBA32F]: [gl.RGBA, 4], [gl.RG32F]: [gl.RG, 2] }[format];
  gl.texImage2D(gl.TEXTURE_2D, 0, format, width, height, 0, channels[0], gl.FLOAT, data);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, filter);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, filter);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
  return tex;
}

function cubeTexture(gl, cube) {
  // cube.levels[m]: 6 faces (+X -X +Y -Y +Z -Z) of size >> m, rows first (row 0 = t = 0), RGBA float.
  const tex = gl.createTexture();
  gl.activeTexture(gl.TEXTURE0 + SCRATCH_UNIT);
  gl.bindTexture(gl.TEXTURE_CUBE_MAP, tex);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  gl.texStorage2D(gl.TEXTURE_CUBE_MAP, cube.levels.length, gl.RGBA32F, cube.size, cube.size);
  cube.levels.forEach((faces, m) => {
    const n = cube.size >> m;
    faces.forEach((face, f) => {
      gl.texSubImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + f, m, 0, 0, n, n, gl.RGBA, gl.FLOAT, new Float32Array(face));
    });
  });
  gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MIN_FILTER, gl.LINEAR_MIPMAP_LINEAR);
  gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
  gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
  gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
  return tex;
}

async function main() {
  const gl = document.getElementById("c").getContext("webgl2");
  if (!gl) throw new Error("no WebGL2");
  if (!gl.getExtension("EXT_color_buffer_float")) throw new Error("no EXT_color_buffer_float");
  const floatLinear = !!gl.getExtension("OES_texture_float_linear");
  const spec = JSON.parse(await text("/data/cases.json"));
  const library = (await Promise.all(spec.files.map((f) => text(`/data/${f}`)))).join("\n");
  const W = spec.width;

  const vertex = compile(gl, gl.VERTEX_SHADER, `#version 300 es
in vec2 p;
void main() { gl_Position = vec4(p, 0.0, 1.0); }`, "vertex");
  const quad = gl.createBuffer();
  gl.bindBuffer(gl.ARRAY_BUFFER, quad);
  gl.bufferData(gl.ARRAY_BUFFER, new Float32Array([-1, -1, 1, -1, -1, 1, 1, 1]), gl.STATIC_DRAW);

  // Shared inputs: the DFG table (RG32F: bilinear needs OES_texture_float_linear for pbrkit_sampleDFG;
  // pbrkit_fetchDFG needs nothing), the specular cube, the SH coefficients.
  const lut = spec.lut ? floatTexture(gl, spec.lut.width, spec.lut.height, new Float32Array(spec.lut.data),
                                      floatLinear ? gl.LINEAR : gl.NEAREST, gl.RG32F) : null;
  const cube = spec.cube ? cubeTexture(gl, spec.cube) : null;

  const results = {};
  const started = performance.now();
  for (const c of spec.cases) {
    const H = Math.ceil(c.count / W);
    const source = `#version 300 es
precision highp float;
precision highp int;
${library}
${[...Array(INPUTS).keys()].map((k) => `uniform highp sampler2D u_in${k};`).join("\n")}
uniform highp sampler2D u_lut;
uniform highp samplerCube u_cube;
uniform vec3 u_sh[9];
out vec4 o_value;
vec4 pad4(float x) { return vec4(x, 0.0, 0.0, 0.0); }
vec4 pad4(vec2 x) { return vec4(x, 0.0, 0.0); }
vec4 pad4(vec3 x) { return vec4(x, 0.0); }
vec4 pad4(vec4 x) { return x; }
void main() {
  ivec2 q = ivec2(gl_FragCoord.xy);
${[...NAMES].map((v, k) => `  vec4 ${v} = texelFetch(u_in${k}, q, 0);`).join("\n")}
  o_value = pad4(${c.expr});
}`;
    const p = program(gl, vertex, source, c.name);
    gl.useProgram(p);
    const textures = [];
    for (let k = 0; k < INPUTS; k++) {
      const data = new Float32Array(W * H * 4);
      if (k < c.inputs.length) data.set(c.inputs[k]);
      textures.push(floatTexture(gl, W, H, data, gl.NEAREST));
    }
    const target = floatTexture(gl, W, H, null, gl.NEAREST);
    for (let k = 0; k < INPUTS; k++) {
      gl.activeTexture(gl.TEXTURE0 + inputUnit(k));
      gl.bindTexture(gl.TEXTURE_2D, textures[k]);
      gl.uniform1i(gl.getUniformLocation(p, `u_in${k}`), inputUnit(k));
    }
    if (lut) {
      gl.activeTexture(gl.TEXTURE8);
      gl.bindTexture(gl.TEXTURE_2D, lut);
      gl.uniform1i(gl.getUniformLocation(p, "u_lut"), 8);
    }
    if (cube) {
      gl.activeTexture(gl.TEXTURE9);
      gl.bindTexture(gl.TEXTURE_CUBE_MAP, cube);
      gl.uniform1i(gl.getUniformLocation(p, "u_cube"), 9);
    }
    if (spec.sh) {
      const where = gl.getUniformLocation(p, "u_sh");
      if (where) gl.uniform3fv(where, new Float32Array(spec.sh));
    }
    const fb = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, target, 0);
    if (gl.checkFramebufferStatus(gl.FRAMEBUFFER) !== gl.FRAMEBUFFER_COMPLETE) {
      throw new Error(`${c.name}: RGBA32F framebuffer incomplete`);
    }
    gl.viewport(0, 0, W, H);
    const where = gl.getAttribLocation(p, "p");
    gl.bindBuffer(gl.ARRAY_BUFFER, quad);
    gl.enableVertexAttribArray(where);
    gl.vertexAttribPointer(where, 2, gl.FLOAT, false, 0, 0);
    gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4);
    const out = new Float32Array(W * H * 4);
    gl.readPixels(0, 0, W, H, gl.RGBA, gl.FLOAT, out);
    const error = gl.getError();
    if (error !== gl.NO_ERROR) throw new Error(`${c.name}: GL error ${error}`);
    // NaN and infinities become null in JSON: the test reads them as NaN and fails on them.
    results[c.name] = Array.from(out.subarray(0, 4 * c.count));
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.deleteFramebuffer(fb);
    textures.concat([target]).forEach((t) => gl.deleteTexture(t));
    gl.deleteProgram(p);
  }
  window.__pbrkitResult = {
    renderer: gl.getParameter(gl.RENDERER),
    floatLinear,
    seconds: (performance.now() - started) / 1000,
    results,
  };
}

main().catch((e) => fail(e && e.stack ? e.stack : e));
