// What the Filament pages share: error reporting, fetching from /data, frames that
// really drew, and reading a float render target back.
//
// * Filament's JS API has no readPixels: each 2D texture's storage is noted
//   (texStorage2D is how Filament's GL backend allocates immutable textures) so
//   that the render target's colour texture can be found again and read through
//   a framebuffer of our own (readFloatTarget).
// * Renderer.render skips a frame (draws nothing) while the GPU fences of earlier
//   frames are pending, so renderFrame counts draw calls and renders again until a
//   frame drew.
// Importing this module installs both hooks; import it before Filament starts.

export const fail = (message) => {
  window.__pbrkitError = String(message && message.stack ? message.stack : message);
};
window.addEventListener("error", (e) => fail(e.message));
window.addEventListener("unhandledrejection", (e) => fail(e.reason));

const storages = [];
const texStorage2D = WebGL2RenderingContext.prototype.texStorage2D;
WebGL2RenderingContext.prototype.texStorage2D = function (target, levels, format, w, h) {
  texStorage2D.call(this, target, levels, format, w, h);
  if (target === this.TEXTURE_2D) {
    storages.push({ texture: this.getParameter(this.TEXTURE_BINDING_2D), format, w, h });
  }
};

let draws = 0;
for (const name of ["drawArrays", "drawElements", "drawElementsInstanced", "drawArraysInstanced"]) {
  const original = WebGL2RenderingContext.prototype[name];
  WebGL2RenderingContext.prototype[name] = function (...args) {
    draws++;
    return original.apply(this, args);
  };
}

export const fetchBytes = async (name) => {
  const response = await fetch(`/data/${name}`);
  if (!response.ok) throw new Error(`/data/${name}: HTTP ${response.status}`);
  return new Uint8Array(await response.arrayBuffer());
};

export async function renderFrame(renderer, swapChain, view) {
  for (let tries = 0; ; tries++) {
    if (tries > 300) throw new Error("Filament skipped every frame (renderer.render drew nothing)");
    const before = draws;
    renderer.render(swapChain, view);
    await new Promise((ok) => requestAnimationFrame(ok)); // lets WebGL fences signal
    if (draws > before) return;
  }
}

// The w x h corner of the one RGBA32F texture of size n x m (the view's render
// target), as a Float32Array, rows bottom first.
export function readFloatTarget(gl, w, h, n = w, m = h) {
  const found = storages.filter((s) => s.format === gl.RGBA32F && s.w === n && s.h === m);
  if (found.length !== 1) throw new Error(`found ${found.length} RGBA32F ${n}x${m} textures`);
  const previous = gl.getParameter(gl.READ_FRAMEBUFFER_BINDING);
  const previousPack = gl.getParameter(gl.PIXEL_PACK_BUFFER_BINDING);
  const fbo = gl.createFramebuffer();
  gl.bindFramebuffer(gl.READ_FRAMEBUFFER, fbo);
  gl.framebufferTexture2D(gl.READ_FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, found[0].texture, 0);
  gl.bindBuffer(gl.PIXEL_PACK_BUFFER, null);
  const pixels = new Float32Array(w * h * 4);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT, pixels);
  gl.bindBuffer(gl.PIXEL_PACK_BUFFER, previousPack);
  gl.bindFramebuffer(gl.READ_FRAMEBUFFER, previous);
  gl.deleteFramebuffer(fbo);
  return pixels;
}
