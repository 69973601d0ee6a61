// What both engine pages share (served to them as /client/pixels.mjs): the box filter of the
// view's sub-pixel grid, the transfer of the pixels to node, and the seeded order of the
// interleaved rounds.

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

// A seeded shuffle (mulberry32 draws, Fisher–Yates), so that a run's interleaved order is
// reproducible: `const shuffled = seededShuffle(seed); shuffled(list)`.
export function seededShuffle(seed) {
  let a = seed >>> 0;
  const rand = () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
  return (list) => {
    const out = list.slice();
    for (let i = out.length - 1; i > 0; i--) {
      const j = Math.floor(rand() * (i + 1));
      [out[i], out[j]] = [out[j], out[i]];
    }
    return out;
  };
}
