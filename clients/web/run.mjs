#!/usr/bin/env node
// Draws a mirrorbox export (docs/exchange.md) with three.js in headless Chromium and writes
// RUN_DIR/three/<variant>/<view>.exr and timing.json. See README.md.
import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { encodeExr } from './exr.mjs';

const HERE = path.dirname(fileURLToPath(import.meta.url));
const CLIENT = 'three';
const ALL_VARIANTS = ['floor', 'reflector', 'cubecamera'];
const EQUIVALENT = { floor: null, reflector: 'naive', cubecamera: 'cubemap' };
const USAGE = `usage: node clients/web/run.mjs EXPORT_DIR RUN_DIR [--variants floor,reflector,cubecamera]
       [--frames 9] [--warmup 2] [--chromium /usr/bin/chromium-headless-shell]
       [--cube-size 256] [--reflector-samples 4] [--seed 1] [--timeout 600]`;

function fail(message, code = 1) {
  console.error(`run.mjs: ${message}`);
  process.exit(code);
}

function parseArgs(argv) {
  const opts = {
    variants: ALL_VARIANTS, frames: 9, warmup: 2, chromium: '/usr/bin/chromium-headless-shell',
    cubeSize: 256, reflectorSamples: 4, seed: 1, timeout: 600,
  };
  const positional = [];
  const integer = (flag, v, min) => {
    const n = Number(v);
    if (!Number.isInteger(n) || n < min) fail(`${flag} wants an integer ≥ ${min}, got "${v}"\n${USAGE}`);
    return n;
  };
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    if (a === '-h' || a === '--help') { console.log(USAGE); process.exit(0); }
    if (!a.startsWith('--')) { positional.push(a); continue; }
    const v = argv[++i];
    if (v === undefined) fail(`${a} needs a value\n${USAGE}`);
    switch (a) {
      case '--variants':
        opts.variants = v.split(',').filter(Boolean);
        for (const n of opts.variants) if (!ALL_VARIANTS.includes(n)) fail(`unknown variant "${n}" (${ALL_VARIANTS.join(', ')})`);
        if (opts.variants.length === 0) fail('--variants is empty');
        break;
      case '--frames': opts.frames = integer(a, v, 1); break;
      case '--warmup': opts.warmup = integer(a, v, 1); break;
      case '--chromium': opts.chromium = v; break;
      case '--cube-size': opts.cubeSize = integer(a, v, 1); break;
      case '--reflector-samples': opts.reflectorSamples = integer(a, v, 0); break;
      case '--seed': opts.seed = integer(a, v, 0); break;
      case '--timeout': opts.timeout = integer(a, v, 1); break;
      default: fail(`unknown option ${a}\n${USAGE}`);
    }
  }
  if (positional.length !== 2) fail(USAGE);
  [opts.exportDir, opts.runDir] = positional.map((p) => path.resolve(p));
  return opts;
}

// Everything the page will fetch must exist before the browser starts.
function readExport(dir) {
  const need = (rel) => {
    const p = path.join(dir, rel);
    if (!fs.existsSync(p)) fail(`missing export file ${p} (write the export with mirrorbox export-views)`);
    return p;
  };
  const views = JSON.parse(fs.readFileSync(need('views.json'), 'utf8'));
  if (views.format !== 'mirrorbox-views' || views.version !== 1) fail(`${dir}/views.json is not mirrorbox-views version 1`);
  if (!Array.isArray(views.views) || views.views.length === 0) fail(`${dir}/views.json lists no views`);
  const gltf = JSON.parse(fs.readFileSync(need(views.gltf || 'scene.gltf'), 'utf8'));
  for (const x of [...(gltf.buffers || []), ...(gltf.images || [])]) {
    if (x.uri && !x.uri.startsWith('data:')) need(decodeURIComponent(x.uri));
  }
  for (const v of views.views) {
    if (!/^[A-Za-z0-9_-]{1,64}$/.test(v.name)) fail(`view name "${v.name}" is not 1 to 64 letters, digits, - or _`);
    if (!(v.width > 0 && v.height > 0 && v.ssaa > 0)) fail(`view ${v.name}: bad size ${v.width}x${v.height} ssaa ${v.ssaa}`);
  }
  return views;
}

const TYPES = {
  '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.json': 'application/json',
  '.gltf': 'model/gltf+json', '.bin': 'application/octet-stream', '.png': 'image/png', '.jpg': 'image/jpeg',
};

// /client/… is this folder (the pages and node_modules/three), /export/… the export.
function serve(exportDir, failures) {
  const roots = { client: HERE, export: exportDir };
  const server = http.createServer((req, res) => {
    const url = new URL(req.url, 'http://localhost');
    let parts;
    try {
      parts = decodeURIComponent(url.pathname).split('/');
    } catch {
      failures.push(`the page asked for a malformed path ${url.pathname}`);
      res.writeHead(400).end();
      return;
    }
    const [, top, ...rest] = parts;
    const root = roots[top];
    const file = root && path.resolve(root, rest.join('/'));
    if (url.pathname === '/favicon.ico') { res.writeHead(204).end(); return; }
    if (!file || !file.startsWith(root + path.sep) || !fs.existsSync(file) || !fs.statSync(file).isFile()) {
      failures.push(`the page asked for ${url.pathname}: not found`);
      res.writeHead(404).end();
      return;
    }
    res.writeHead(200, {
      'Content-Type': TYPES[path.extname(file)] || 'application/octet-stream',
      'Cache-Control': 'no-store',
      // Cross-origin isolation: performance.now() at its finest resolution.
      'Cross-Origin-Opener-Policy': 'same-origin',
      'Cross-Origin-Embedder-Policy': 'require-corp',
    });
    fs.createReadStream(file).pipe(res);
  });
  return new Promise((resolve) => server.listen(0, '127.0.0.1', () => resolve(server)));
}

function writeAtomic(file, data) {
  const tmp = `${file}.tmp-${process.pid}`;
  fs.writeFileSync(tmp, data);
  fs.renameSync(tmp, file);
}

async function main() {
  const opts = parseArgs(process.argv.slice(2));
  const views = readExport(opts.exportDir);
  if (views.contract.lighting !== 'direct, no shadows') {
    console.error(`warning: views.json's lighting is "${views.contract.lighting}": this client draws direct light `
      + 'without shadows or light through mirrors, so its floor includes that difference');
  }
  const threePackage = path.join(HERE, 'node_modules', 'three', 'package.json');
  if (!fs.existsSync(threePackage)) fail(`three is not installed in ${HERE}: run scripts/install-web-clients.sh`);
  const threeVersion = JSON.parse(fs.readFileSync(threePackage, 'utf8')).version;
  if (!fs.existsSync(opts.chromium)) fail(`no Chromium at ${opts.chromium} (give --chromium PATH)`);
  const { default: puppeteer } = await import('puppeteer-core');

  const failures = [];
  const consoleErrors = [];
  const server = await serve(opts.exportDir, failures);
  const base = `http://127.0.0.1:${server.address().port}`;
  let browser;
  const watchdog = setTimeout(() => {
    console.error(`run.mjs: timed out after ${opts.timeout} s (--timeout); nothing written`);
    if (browser) browser.process()?.kill('SIGKILL');
    process.exit(1);
  }, opts.timeout * 1000);
  const started = Date.now();
  try {
    browser = await puppeteer.launch({
      executablePath: opts.chromium,
      headless: 'shell',
      args: ['--enable-unsafe-swiftshader', '--use-angle=swiftshader', '--no-sandbox', '--ignore-gpu-blocklist'],
    });
    const page = await browser.newPage();
    page.setDefaultTimeout(opts.timeout * 1000);
    page.on('console', (msg) => {
      const type = msg.type();
      if (type === 'error') { consoleErrors.push(msg.text()); console.error(`page error: ${msg.text()}`); }
      else if (/WebGL: INVALID|GL_INVALID|CONTEXT_LOST/.test(msg.text())) {
        consoleErrors.push(msg.text()); // WebGL reports its errors as warnings
        console.error(`page WebGL error: ${msg.text()}`);
      } else if ((type === 'warn' || type === 'warning') && !/GPU stall due to ReadPixels/.test(msg.text())) {
        console.error(`page warning: ${msg.text()}`);
      }
    });
    page.on('pageerror', (err) => failures.push(`page exception: ${err.message}`));
    // GLTFLoader's FileLoader re-wraps fetch's body stream; Chromium then reports the finished
    // request as net::ERR_ABORTED. A file that really fails to load fails the loader (and a
    // missing one the server), so only other network errors count here.
    page.on('requestfailed', (req) => {
      const why = req.failure()?.errorText;
      if (why !== 'net::ERR_ABORTED') failures.push(`request failed: ${req.url()} (${why})`);
    });
    const check = () => {
      if (failures.length || consoleErrors.length) {
        throw new Error([...failures, ...consoleErrors.map((e) => `console error: ${e}`)].join('\n'));
      }
    };
    await page.goto(`${base}/client/three/page.html`, { waitUntil: 'load' });
    await page.waitForFunction('window.mirrorboxReady === true || window.mirrorboxFailed', { timeout: 60000 })
      .catch(() => { check(); throw new Error('the page did not start (client.mjs never loaded)'); });
    const failed = await page.evaluate(() => window.mirrorboxFailed);
    if (failed) failures.push(`the page did not start: ${failed}`);
    check();
    const info = await page.evaluate((o) => window.mirrorbox.init(o), {
      gltfUrl: `${base}/export/${views.gltf || 'scene.gltf'}`,
      views: views.views,
      contract: views.contract,
      variants: opts.variants,
      cubeSize: opts.cubeSize,
      reflectorSamples: opts.reflectorSamples,
      clipBias: 0,
      seed: opts.seed,
    });
    check();
    if (!threeVersion.startsWith(`0.${info.revision}.`)) fail(`three ${threeVersion} installed but the page runs r${info.revision}`);
    if (!info.isolated) console.error('warning: the page is not cross-origin isolated: performance.now() is coarser (100 µs)');
    const extras = info.gltfExtras || {};
    for (const key of ['ambient', 'background', 'terminal']) {
      const a = extras[key];
      const b = views.contract[key];
      if (!a || a.some((x, i) => Math.abs(x - b[i]) > 1e-6)) {
        console.error(`warning: scene.gltf's extras.mirrorbox.${key} ${JSON.stringify(a)} differs from views.json's ${JSON.stringify(b)}; using views.json's`);
      }
    }
    console.log(`three ${threeVersion} on ${info.device} (${info.driver.split(';')[0]}); mirrors: ${info.mirrors[opts.variants[0]]}; subpixel bits: ${info.subpixelBits}`);

    const results = {}; // view -> { times, images }
    for (const view of views.views) {
      const t0 = Date.now();
      const r = await page.evaluate((v, f, w) => window.mirrorbox.runView(v, f, w), view, opts.frames, opts.warmup);
      check();
      if (r.cameraDiff > 1e-5) console.error(`warning: view ${view.name}: three's camera differs from views.json's matrices by ${r.cameraDiff}`);
      results[view.name] = r;
      const med = (a) => a.slice().sort((x, y) => x - y)[a.length >> 1];
      const summary = opts.variants.map((n) => `${n} ${med(r.times[n]).toFixed(2)} ms`).join(', ');
      console.log(`view ${view.name} ${view.width}x${view.height} ssaa ${view.ssaa}: ${summary} (median; sync alone ${r.syncMs.toFixed(2)} ms; ${((Date.now() - t0) / 1000).toFixed(1)} s)`);
    }
    await browser.close();
    browser = null;

    // All views drew: write each file under a temporary name, then rename it.
    const syncMs = Math.max(...Object.values(results).map((r) => r.syncMs));
    const timingText = 'wall clock (performance.now, cross-origin isolated) around the frame (cube faces, renderer.render '
      + 'with its Reflector passes) + gl.finish() + a 1x1 readRenderTargetPixels (Chromium\'s finish() is only a flush; '
      + `the readback waits for the GPU and adds ~${syncMs.toFixed(2)} ms, measured alone and not subtracted); `
      + 'warm frames only, interleaved: each round draws every variant once in a shuffled order';
    for (const name of opts.variants) {
      const dir = path.join(opts.runDir, CLIENT, name);
      fs.mkdirSync(dir, { recursive: true });
      for (const view of views.views) {
        const floats = new Float32Array(new Uint8Array(Buffer.from(results[view.name].images[name], 'base64')).buffer);
        writeAtomic(path.join(dir, `${view.name}.exr`), encodeExr(view.width, view.height, floats));
      }
      const parameters = {
        ssaa: views.views[0].ssaa,
        frames: opts.frames,
        warmup: opts.warmup,
        sync_overhead_ms: Number(syncMs.toFixed(4)),
        shading: 'MeshLambertMaterial, DoubleSide, file normals, front-only emission; AmbientLight π·A; PointLight decay 2, distance 0',
        target: 'WebGLRenderTarget FloatType RGBA, readRenderTargetPixels, box filter in JS',
      };
      if (name === 'floor') parameters.mirrors = 'removed';
      if (name === 'reflector') {
        Object.assign(parameters, {
          texture: 'canvas size (width×ssaa × height×ssaa), HalfFloatType',
          multisample: opts.reflectorSamples,
          clip_bias: 0,
          shader: 'ReflectorShader with reflectance × reflected colour instead of blendOverlay',
        });
      }
      if (name === 'cubecamera') {
        Object.assign(parameters, {
          cube_size: opts.cubeSize,
          cube_type: 'HalfFloatType',
          placement: "mirror's centre, updated every frame with the mirror hidden",
          material: 'MeshBasicMaterial envMap (MultiplyOperation), colour = reflectance, reflection vector per fragment (patched)',
          history: 'the cubes show the other mirrors as the previous frame left them (one reflection deeper per frame)',
        });
      }
      const timing = {
        format: 'mirrorbox-timing',
        version: 1,
        engine: 'three.js',
        engine_version: threeVersion,
        device: info.device,
        driver: info.driver,
        timing: timingText,
        parameters,
        ...(EQUIVALENT[name] ? { equivalent: EQUIVALENT[name] } : {}),
        views: Object.fromEntries(views.views.map((v) => [v.name, results[v.name].times[name].map((ms) => Number(ms.toFixed(4)))])),
      };
      writeAtomic(path.join(dir, 'timing.json'), `${JSON.stringify(timing, null, 2)}\n`);
    }
    console.log(`wrote ${path.join(opts.runDir, CLIENT)}/{${opts.variants.join(',')}} in ${((Date.now() - started) / 1000).toFixed(1)} s`);
  } catch (err) {
    console.error(`run.mjs: ${err.message.split('\n').join('\nrun.mjs: ')}`);
    console.error('run.mjs: failed; nothing written');
    if (browser) await browser.close().catch(() => {});
    process.exitCode = 1;
  } finally {
    clearTimeout(watchdog);
    server.close();
  }
}

main().catch((err) => fail(err.stack || String(err)));
