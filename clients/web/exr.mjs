// A minimal OpenEXR writer: single part, scanline, NO_COMPRESSION, channels B, G, R as
// 32-bit FLOAT (alphabetical, as OpenEXR requires), INCREASING_Y: line 0 is the top row.
// The file mirrorbox's `compare` and `score` read (docs/exchange.md, "In: a run folder").

const FLOAT = 2; // OpenEXR pixel type: UINT 0, HALF 1, FLOAT 2

function attribute(name, type, value) {
  const head = Buffer.from(`${name}\0${type}\0`, 'latin1');
  const size = Buffer.alloc(4);
  size.writeInt32LE(value.length);
  return Buffer.concat([head, size, value]);
}

function int32s(...values) {
  const b = Buffer.alloc(4 * values.length);
  values.forEach((v, i) => b.writeInt32LE(v, 4 * i));
  return b;
}

function float32s(...values) {
  const b = Buffer.alloc(4 * values.length);
  values.forEach((v, i) => b.writeFloatLE(v, 4 * i));
  return b;
}

const CHANNELS = ['B', 'G', 'R']; // sorted by name; each is an offset into an RGB pixel below
const RGB_INDEX = { R: 0, G: 1, B: 2 };

/**
 * Encodes an image as EXR.
 * @param {number} width
 * @param {number} height
 * @param {Float32Array} rgb - width × height × 3 linear values, row 0 the top row
 * @returns {Buffer}
 */
export function encodeExr(width, height, rgb) {
  if (!Number.isInteger(width) || !Number.isInteger(height) || width < 1 || height < 1) {
    throw new Error(`EXR: bad size ${width}x${height}`);
  }
  if (rgb.length !== width * height * 3) {
    throw new Error(`EXR: ${rgb.length} values for ${width}x${height}x3`);
  }
  const chlist = Buffer.concat([
    ...CHANNELS.map((c) =>
      Buffer.concat([Buffer.from(`${c}\0`, 'latin1'), int32s(FLOAT), Buffer.from([0, 0, 0, 0]), int32s(1, 1)]),
    ),
    Buffer.from([0]),
  ]);
  const box = int32s(0, 0, width - 1, height - 1);
  const header = Buffer.concat([
    Buffer.from([0x76, 0x2f, 0x31, 0x01]), // magic 20000630
    Buffer.from([2, 0, 0, 0]), // version 2, single-part scanline, no flags
    attribute('channels', 'chlist', chlist),
    attribute('compression', 'compression', Buffer.from([0])),
    attribute('dataWindow', 'box2i', box),
    attribute('displayWindow', 'box2i', box),
    attribute('lineOrder', 'lineOrder', Buffer.from([0])), // INCREASING_Y
    attribute('pixelAspectRatio', 'float', float32s(1)),
    attribute('screenWindowCenter', 'v2f', float32s(0, 0)),
    attribute('screenWindowWidth', 'float', float32s(1)),
    Buffer.from([0]), // end of header
  ]);
  const lineBytes = width * CHANNELS.length * 4;
  const chunkBytes = 8 + lineBytes; // y, data size, data
  const tableBytes = 8 * height;
  const out = Buffer.alloc(header.length + tableBytes + chunkBytes * height);
  header.copy(out, 0);
  let offset = header.length + tableBytes;
  for (let y = 0; y < height; y++) {
    out.writeBigUInt64LE(BigInt(offset), header.length + 8 * y);
    out.writeInt32LE(y, offset);
    out.writeInt32LE(lineBytes, offset + 4);
    let p = offset + 8;
    for (const c of CHANNELS) {
      const k = RGB_INDEX[c];
      for (let x = 0; x < width; x++) {
        out.writeFloatLE(rgb[(y * width + x) * 3 + k], p);
        p += 4;
      }
    }
    offset += chunkBytes;
  }
  return out;
}
