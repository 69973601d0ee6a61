// What both engine pages do with the pixels they read back (served to the pages as
// /client/pixels.mjs): the box filter of the view's sub-pixel grid and the transfer to node.

// Mean of each pixel's s × s block of a W × H RGBA float readback, rows flipped (GL reads
// bottom-up; EXR line 0 is the top): the view's width × height RGB floats.
export function boxFilter(rgba, W, H, view) {
  const s = view.ssaa;
  const out = new Float32Array(view.width * view.height * 3);
  for (let y = 0; y < view.height; y++) {
    for (let x = 0; x < view.width; x++) {
      let r = 0, g = 0, b = 0;
      for (let j = 0; j < s; j++) {
        const row = H - 1 - (y * s + j);
        for (let i = 0; i < s; i++) {
          const k = (row * W + x * s + i) * 4;
          r += rgba[k]; g += rgba[k + 1]; b += rgba[k + 2];
        }
      }
      const o = (y * view.width + x) * 3;
      out[o] = r / (s * s); out[o + 1] = g / (s * s); out[o + 2] = b / (s * s);
    }
  }
  return out;
}

// Float32 pixels as base64, for page.evaluate's JSON (chunked: apply() takes few arguments).
export function base64(floats) {
  const bytes = new Uint8Array(floats.buffer, floats.byteOffset, floats.byteLength);
  let s = '';
  for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000));
  return btoa(s);
}
