#!/usr/bin/env node
// Draws a mirrorbox export (docs/exchange.md) with web engines in headless Chromium — three.js
// and Babylon.js — and writes RUN_DIR/<client>/<variant>/<view>.exr and timing.json. See README.md.
import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { encodeExr } from './exr.mjs';

const HERE = path.dirname(fileURLToPath(import.meta.url));

// Every client: its page, its variants (and the mirrorbox method each is meant to match), the
// package whose version it reports, and what its timing.json says about the variants.
const CLIENTS = {
  three: {
    engine: 'three.js',
    package: 'three',
    page: 'three/page.html',
    variants: ['floor', 'reflector', 'cubecamera'],
    equivalent: { floor: null, reflector: 'naive', cubecamera: 'cubemap' },
    checkVersion: (version, info) => version.startsWith(`0.${info.revision}.`) || `three ${version} installed but the page runs r${info.revision}`,
    timing: (syncMs) => 'wall clock (performance.now, cross-origin isolated) around the frame (cube faces, renderer.render '
      + 'with its Reflector passes) + gl.finish() + a 1x1 readRenderTargetPixels (Chromium\'s finish() is only a flush; '
      + `the readback waits for the GPU and adds ~${syncMs.toFixed(2)} ms, measured alone and not subtracted); `
      + 'warm frames only, interleaved: each round draws every variant once in a shuffled order',
    // Short knobs (they name the variant in reports: no spaces, ≤ 20 characters); the prose is in notes.
    parameters(name, opts) {
      const parameters = { material: 'lambert' };
      let notes = 'Shading: MeshLambertMaterial, DoubleSide, the file\'s face normals, emission from the front only '
        + '(patched); AmbientLight of intensity π·A; PointLight decay 2, distance 0 (candela = W/sr). Output: '
        + 'WebGLRenderTarget FloatType RGBA, readRenderTargetPixels, box filter in JS.';
      if (name === 'floor') {
        parameters.mirrors = 'removed';
        notes += ' The mirrors\' meshes are removed.';
      }
      if (name === 'reflector') {
        Object.assign(parameters, { msaa: opts.reflectorSamples, target: 'half', clip_bias: 0 });
        notes += ' Each mirror is a Reflector with its render target at the canvas size (width×ssaa by '
          + 'height×ssaa), HalfFloatType, as shipped; its shader multiplies the reflected colour by the '
          + 'reflectance instead of its blendOverlay with a colour; the mirror\'s back is its child, hidden '
          + 'while it renders. A facing Reflector met in its view renders its own view nested: two levels.';
      }
      if (name === 'cubecamera') {
        // Its cubes refresh every frame from the previous frame's: the saved image (one draw
        // after warm-up and timed frames) shows that many frames of history, as our cubemap at
        // --history warmup + frames.
        Object.assign(parameters, { cube_size: opts.cubeSize, cube_type: 'half', history: opts.warmup + opts.frames });
        notes += ' Each mirror has a CubeCamera at its centre, updated every frame with the mirror hidden; '
          + 'the mirror is a MeshBasicMaterial with the cube as envMap (MultiplyOperation, colour = '
          + 'reflectance), its reflection vector per fragment (patched: as shipped it is per vertex); the '
          + 'cubes show the other mirrors as the previous frame left them (one reflection deeper per frame).';
      }
      return { parameters, notes };
    },
  },
  babylon: {
    engine: 'Babylon.js',
    package: '@babylonjs/core',
    page: 'babylon/page.html',
    variants: ['floor', 'mirrortexture', 'probe'],
    equivalent: { floor: null, mirrortexture: 'feedback', probe: 'cubemap' },
    checkVersion: (version, info) => version === info.version || `@babylonjs/core ${version} installed but the page runs ${info.version}`,
    timing: (syncMs) => 'wall clock (performance.now, cross-origin isolated) around the frame (Scene.render: its '
      + 'MirrorTexture / ReflectionProbe passes, then the camera\'s pass into its float output target) + gl.finish() + a 1x1 '
      + `gl.readPixels of that target (Chromium's finish() is only a flush; the readback waits for the GPU and adds ~${syncMs.toFixed(2)} ms, `
      + 'measured alone and not subtracted); warm frames only, interleaved: each round draws every variant once in a shuffled order',
    // Short knobs (they name the variant in reports: no spaces, ≤ 20 characters); the prose is in notes.
    parameters(name, opts) {
      const parameters = { material: 'pbr-lambert', light_falloff: 'physical' };
      let notes = "Scene: right-handed (glTF's axes, no handedness flip), loaded with Babylon's glTF loader "
        + '(SceneLoader ImportMeshAsync, @babylonjs/loaders); camera from views.json (TargetCamera, vertical fov, near/far); '
        + 'clear colour the background. Diffuse: the loader\'s PBRMaterial with Lambert\'s 1/π diffuse (brdf.baseDiffuseModel '
        + 'LAMBERT), metallicF0Factor 0 and no legacy specular energy conservation (no specular lobe, no (1 − F) on the diffuse), '
        + 'ambientColor white × scene.ambientColor A (ρ·A), two-sided lighting without culling on the file\'s face normals, '
        + 'front-only emission (a material plugin zeroing the emission on back faces), textures as the loader makes them '
        + '(sRGB buffers, bilinear, no mip-maps) with anisotropic filtering off. Point lights: FALLOFF_PHYSICAL (1/r²), '
        + 'luminous intensity (candela = W/sr), specular black. Output: PBR\'s image processing "applied by a post process" '
        + '(none is added; skipFinalColorClamp), so it is linear and unclamped; the scene\'s image processing is disabled. '
        + 'The camera renders into its outputRenderTarget, a float RGBA RenderTargetTexture without MSAA, read back with '
        + 'gl.readPixels (rows flipped) and box-filtered in JS.';
      if (name === 'floor') {
        parameters.mirrors = 'removed';
        notes += ' The mirrors\' meshes are disposed.';
      }
      const back = ' The mirror\'s back is a copy of its triangles, winding reversed and normals negated, diffuse with '
        + 'back_albedo, culled on the mirror\'s front.';
      if (name === 'mirrortexture') {
        Object.assign(parameters, {
          texture_type: opts.mirrorType, texture_size: 'canvas', blur_kernel: 0, clip_plane: 'shipped', levels: 1,
        });
        notes += ' Each mirror is a MirrorTexture at the canvas size (width×ssaa by height×ssaa), '
          + `${{ byte: 'UNSIGNED_BYTE (Babylon\'s default)', half: 'HALF_FLOAT', float: 'FLOAT' }[opts.mirrorType]}, `
          + 'bilinear, no mip-maps, blurKernel 0, adaptiveBlurKernel 0, mirrorPlane = the mirror\'s plane with its normal into '
          + 'the mirror (Babylon keeps plane·x ≤ 0), its clip plane as shipped (scene.clipPlane = mirrorPlane during its pass), '
          + 'renderList every other mesh (the other mirrors and their backs included), refreshed every frame. The mirror is a '
          + 'StandardMaterial with only that reflectionTexture (level 1; diffuse, specular, emissive and ambient black, lighting '
          + 'off) times a Fresnel term whose left and right colours are both the reflectance (R·(1 − f) + f·R = R). One level of '
          + 'reflection: a mirror seen in a mirror shows its own MirrorTexture, rendered for the main camera\'s reflection in it, '
          + 'looked up with the reflected camera\'s projection (measured: no pixel needing two reflections is right except where '
          + 'the second reflection sees the background). Equivalent: feedback at --history 0 (one texture per mirror per frame, '
          + 'the mirrors inside it textured with what their textures hold), which shows terminal there instead.' + back;
      }
      if (name === 'probe') {
        Object.assign(parameters, {
          cube_size: opts.cubeSize, cube_type: 'half', refresh: 'every_frame', invert_z: false,
          history: opts.warmup + opts.frames, // as three's cubecamera (above)
        });
        notes += ` Each mirror has a ReflectionProbe at its centre (${opts.cubeSize}² faces, half float, no mip-maps, `
          + 'near/far the camera\'s, no clip plane), renderList every other mesh (the other mirrors and their backs included), '
          + 'refreshed every frame, its cube cleared to terminal before the first. The mirror is a StandardMaterial with the '
          + 'probe\'s cube as reflectionTexture, looked up per fragment along the view direction reflected about the mesh normal '
          + '(the face normal), times the reflectance (a Fresnel term with both colours the reflectance). The cube\'s invertZ is '
          + 'set false: as shipped, a right-handed scene\'s probe is looked up with z reversed (every mirror showed what lies '
          + 'behind it). The cubes show the other mirrors as the previous frame left them (one reflection deeper per frame).' + back;
      }
      return { parameters, notes };
    },
  },
};
const ALL_VARIANTS = [...new Set(Object.values(CLIENTS).flatMap((c) => c.variants))];
const USAGE = `usage: node clients/web/run.mjs EXPORT_DIR RUN_DIR [--clients three,babylon]
       [--variants ${ALL_VARIANTS.join(',')}]
       [--frames 9] [--warmup 2] [--chromium /usr/bin/chromium-headless-shell]
       [--cube-size 256] [--reflector-samples 4] [--mirror-type half] [--seed 1] [--timeout 600]
       [--allow-unsupported-lighting]   (score an export lit with shadows or through mirrors anyway)`;

function fail(message, code = 1) {
  console.error(`run.mjs: ${message}`);
  process.exit(code);
}

function parseArgs(argv) {
  const opts = {
    clients: Object.keys(CLIENTS), variants: null, frames: 9, warmup: 2, chromium: '/usr/bin/chromium-headless-shell',
    cubeSize: 256, reflectorSamples: 4, mirrorType: 'half', seed: 1, timeout: 600, allowLighting: false,
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
    if (a === '--allow-unsupported-lighting') { opts.allowLighting = true; continue; }
    const v = argv[++i];
    if (v === undefined) fail(`${a} needs a value\n${USAGE}`);
    switch (a) {
      case '--clients':
        opts.clients = [...new Set(v.split(',').filter(Boolean))];
        for (const n of opts.clients) if (!CLIENTS[n]) fail(`unknown client "${n}" (${Object.keys(CLIENTS).join(', ')})`);
        if (opts.clients.length === 0) fail('--clients is empty');
        break;
      case '--variants':
        opts.variants = [...new Set(v.split(',').filter(Boolean))];
        for (const n of opts.variants) if (!ALL_VARIANTS.includes(n)) fail(`unknown variant "${n}" (${ALL_VARIANTS.join(', ')})`);
        if (opts.variants.length === 0) fail('--variants is empty');
        break;
      case '--frames': opts.frames = integer(a, v, 1); break;
      case '--warmup': opts.warmup = integer(a, v, 1); break;
      case '--chromium': opts.chromium = v; break;
      case '--cube-size': opts.cubeSize = integer(a, v, 1); break;
      case '--reflector-samples': opts.reflectorSamples = integer(a, v, 0); break;
      case '--mirror-type':
        if (!['byte', 'half', 'float'].includes(v)) fail(`--mirror-type is byte, half or float, not "${v}"`);
        opts.mirrorType = v;
        break;
      case '--seed': opts.seed = integer(a, v, 0); break;
      case '--timeout': opts.timeout = integer(a, v, 1); break;
      default: fail(`unknown option ${a}\n${USAGE}`);
    }
  }
  if (positional.length !== 2) fail(USAGE);
  [opts.exportDir, opts.runDir] = positional.map((p) => path.resolve(p));
  // Each client draws the listed variants it has (all of its own without --variants); a client
  // with none of them is skipped.
  opts.plan = opts.clients
    .map((name) => ({ name, variants: CLIENTS[name].variants.filter((n) => !opts.variants || opts.variants.includes(n)) }))
    .filter((c) => c.variants.length > 0);
  if (opts.plan.length === 0) fail(`no client of ${opts.clients.join(', ')} has the variants ${opts.variants.join(', ')}`);
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
  // Read here once: the mirrors every client must find (checked after each draws).
  Object.defineProperty(views, 'mirrorCount', { value: countMirrors(gltf), enumerable: false });
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

// /client/… is this folder (the pages and node_modules), /export/… the export.
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

// The mirrors a client must find: the meshes (one per glTF primitive, as three.js' and Babylon's
// loaders make them) of every node whose primitive's material is a mirror.
function countMirrors(gltf) {
  const mirror = (gltf.materials || []).map((m) => Boolean(m.extras && m.extras.mirrorbox_mirror));
  const meshes = gltf.meshes || [];
  return (gltf.nodes || [])
    .filter((n) => Number.isInteger(n.mesh) && meshes[n.mesh])
    .reduce((sum, n) => sum + meshes[n.mesh].primitives.filter((p) => mirror[p.material]).length, 0);
}

function writeAtomic(file, data) {
  const tmp = `${file}.tmp-${process.pid}`;
  fs.writeFileSync(tmp, data);
  fs.renameSync(tmp, file);
}

async function main() {
  const opts = parseArgs(process.argv.slice(2));
  const views = readExport(opts.exportDir);
  // These clients draw direct light without shadows or light through mirrors: another
  // lighting would be scored as their error (their floor's too), so it is refused unless asked
  // for, and then said in every variant's timing.json.
  const unsupportedLighting = views.contract.lighting !== 'direct, no shadows';
  if (unsupportedLighting && !opts.allowLighting) {
    fail(`views.json's lighting is "${views.contract.lighting}": these clients draw direct light without shadows `
      + 'or light through mirrors, so the score would count that as their error; export a scene without '
      + 'lighting.shadows and lighting.mirrored_lights, or give --allow-unsupported-lighting', 2);
  }
  const versions = {};
  for (const { name } of opts.plan) {
    const pkg = path.join(HERE, 'node_modules', CLIENTS[name].package, 'package.json');
    if (!fs.existsSync(pkg)) fail(`${CLIENTS[name].package} is not installed in ${HERE}: run scripts/install-web-clients.sh`);
    versions[name] = JSON.parse(fs.readFileSync(pkg, 'utf8')).version;
  }
  if (!fs.existsSync(opts.chromium)) fail(`no Chromium at ${opts.chromium} (give --chromium PATH)`);
  const { default: puppeteer } = await import('puppeteer-core').catch((e) => fail(
    `puppeteer-core cannot be loaded from ${HERE}/node_modules (${e.message.split('\n')[0]}): run scripts/install-web-clients.sh`));
  const mirrorsInExport = views.mirrorCount;

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
  // Clients whose folder was put in place, and staged folders not yet: what a failure says
  // and removes.
  const written = [];
  const stagedDirs = [];
  try {
    browser = await puppeteer.launch({
      executablePath: opts.chromium,
      headless: 'shell',
      args: ['--enable-unsafe-swiftshader', '--use-angle=swiftshader', '--no-sandbox', '--ignore-gpu-blocklist'],
    });
    const check = () => {
      if (failures.length || consoleErrors.length) {
        throw new Error([...failures, ...consoleErrors.map((e) => `console error: ${e}`)].join('\n'));
      }
    };
    const drawn = {}; // client -> { info, results }
    // One client after the other, each in its own page (its own WebGL context); a client's
    // variants are interleaved frame by frame, the clients are not.
    for (const { name: client, variants } of opts.plan) {
      const spec = CLIENTS[client];
      const page = await browser.newPage();
      page.setDefaultTimeout(opts.timeout * 1000);
      page.on('console', (msg) => {
        const type = msg.type();
        if (type === 'error') { consoleErrors.push(msg.text()); console.error(`${client} page error: ${msg.text()}`); }
        else if (/WebGL: INVALID|GL_INVALID|CONTEXT_LOST/.test(msg.text())) {
          consoleErrors.push(msg.text()); // WebGL reports its errors as warnings
          console.error(`${client} page WebGL error: ${msg.text()}`);
        } else if ((type === 'warn' || type === 'warning') && !/GPU stall due to ReadPixels/.test(msg.text())) {
          console.error(`${client} page warning: ${msg.text()}`);
        }
      });
      page.on('pageerror', (err) => failures.push(`${client} page exception: ${err.message}`));
      // GLTFLoader's FileLoader re-wraps fetch's body stream; Chromium then reports the finished
      // request as net::ERR_ABORTED. A file that really fails to load fails the loader (and a
      // missing one the server), so only other network errors count here.
      page.on('requestfailed', (req) => {
        const why = req.failure()?.errorText;
        if (why !== 'net::ERR_ABORTED') failures.push(`request failed: ${req.url()} (${why})`);
      });
      const t0 = Date.now();
      await page.goto(`${base}/client/${spec.page}`, { waitUntil: 'load' });
      await page.waitForFunction('window.mirrorboxReady === true || window.mirrorboxFailed', { timeout: 60000 })
        .catch(() => { check(); throw new Error(`the ${client} page did not start (client.mjs never loaded)`); });
      const failed = await page.evaluate(() => window.mirrorboxFailed);
      if (failed) failures.push(`the ${client} page did not start: ${failed}`);
      check();
      const info = await page.evaluate((o) => window.mirrorbox.init(o), {
        gltfUrl: `${base}/export/${views.gltf || 'scene.gltf'}`,
        views: views.views,
        contract: views.contract,
        variants,
        cubeSize: opts.cubeSize,
        reflectorSamples: opts.reflectorSamples,
        mirrorType: opts.mirrorType,
        clipBias: 0,
        seed: opts.seed,
      });
      check();
      const versionOk = spec.checkVersion(versions[client], info);
      if (versionOk !== true) fail(versionOk);
      if (!info.isolated) console.error(`warning: the ${client} page is not cross-origin isolated: performance.now() is coarser (100 µs)`);
      const extras = info.gltfExtras || {};
      for (const key of ['ambient', 'background', 'terminal']) {
        const a = extras[key];
        const b = views.contract[key];
        if (!a || a.some((x, i) => Math.abs(x - b[i]) > 1e-6)) {
          console.error(`warning: scene.gltf's extras.mirrorbox.${key} ${JSON.stringify(a)} differs from views.json's ${JSON.stringify(b)}; using views.json's`);
        }
      }
      // Every mirror of the export found: a mirror the client did not recognise (its extra
      // lost) would be drawn as a diffuse surface and scored as the method's error.
      for (const v of variants) {
        if (info.mirrors[v] !== mirrorsInExport) {
          throw new Error(`the ${client} client found ${info.mirrors[v]} mirrors in variant ${v}; the export has `
            + `${mirrorsInExport} (meshes whose material has extras.mirrorbox_mirror)`);
        }
      }
      console.log(`${spec.engine} ${versions[client]} on ${info.device} (${info.driver.split(';')[0]}); mirrors: ${info.mirrors[variants[0]]}; subpixel bits: ${info.subpixelBits}; loaded in ${((Date.now() - t0) / 1000).toFixed(1)} s`);

      const results = {}; // view -> { times, images }
      for (const view of views.views) {
        const t1 = Date.now();
        const r = await page.evaluate((v, f, w) => window.mirrorbox.runView(v, f, w), view, opts.frames, opts.warmup);
        check();
        // The camera is the export's or the images are of another view: an error, not a warning.
        if (!(r.cameraDiff <= 1e-5)) {
          throw new Error(`view ${view.name}: ${spec.engine}'s camera differs from views.json's matrices by ${r.cameraDiff} (at most 1e-5)`);
        }
        results[view.name] = r;
        const med = (a) => a.slice().sort((x, y) => x - y)[a.length >> 1];
        const summary = variants.map((n) => `${n} ${med(r.times[n]).toFixed(2)} ms`).join(', ');
        console.log(`${client} view ${view.name} ${view.width}x${view.height} ssaa ${view.ssaa}: ${summary} (median; sync alone ${r.syncMs.toFixed(2)} ms; ${((Date.now() - t1) / 1000).toFixed(1)} s)`);
      }
      await page.close();
      check();
      drawn[client] = { info, results, variants };
    }
    await browser.close();
    browser = null;

    // Every client drew every view: each client's folder is written whole under a temporary
    // name, then put in place of an earlier run's (whose other variants would have been scored
    // beside these).
    for (const { name: client } of opts.plan) {
      const spec = CLIENTS[client];
      const { info, results, variants } = drawn[client];
      const syncMs = Math.max(...Object.values(results).map((r) => r.syncMs));
      const final = path.join(opts.runDir, client);
      // Hidden (a leading dot): `mirrorbox score` takes it for no client while it is written,
      // nor after a killed run left it.
      const staged = path.join(opts.runDir, `.${client}.tmp-${process.pid}`);
      fs.rmSync(staged, { recursive: true, force: true });
      stagedDirs.push(staged);
      for (const name of variants) {
        const dir = path.join(staged, name);
        fs.mkdirSync(dir, { recursive: true });
        for (const view of views.views) {
          const floats = new Float32Array(new Uint8Array(Buffer.from(results[view.name].images[name], 'base64')).buffer);
          writeAtomic(path.join(dir, `${view.name}.exr`), encodeExr(view.width, view.height, floats));
        }
        const own = spec.parameters(name, opts);
        const parameters = own.parameters;
        if (unsupportedLighting) parameters.lighting = 'unsupported';
        const lit = unsupportedLighting
          ? ` The export's lighting ("${views.contract.lighting}") is not drawn: direct light only, no shadows, `
            + 'no light through mirrors (--allow-unsupported-lighting).'
          : '';
        const notes = `${own.notes ?? ''}${lit} Timing: ${opts.frames} timed frames after ${opts.warmup} warm-up `
          + `frames per view; the wait for the GPU (finish + 1×1 readback) costs ${syncMs.toFixed(3)} ms alone.`;
        const timing = {
          format: 'mirrorbox-timing',
          version: 1,
          engine: spec.engine,
          engine_version: versions[client],
          device: info.device,
          driver: info.driver,
          timing: spec.timing(syncMs),
          parameters,
          ...(spec.equivalent[name] ? { equivalent: spec.equivalent[name] } : {}),
          notes: notes.trim(),
          views: Object.fromEntries(views.views.map((v) => [v.name, results[v.name].times[name].map((ms) => Number(ms.toFixed(4)))])),
          // Which export the run was drawn from: score refuses it against another.
          scene_hashes: Object.fromEntries(views.views.map((v) => [v.name, v.scene_hash])),
        };
        writeAtomic(path.join(dir, 'timing.json'), `${JSON.stringify(timing, null, 2)}\n`);
      }
      fs.rmSync(final, { recursive: true, force: true });
      fs.renameSync(staged, final);
      stagedDirs.pop();
      written.push(client);
      console.log(`wrote ${final}/{${variants.join(',')}}`);
    }
    console.log(`done in ${((Date.now() - started) / 1000).toFixed(1)} s`);
  } catch (err) {
    console.error(`run.mjs: ${err.message.split('\n').join('\nrun.mjs: ')}`);
    for (const dir of stagedDirs) fs.rmSync(dir, { recursive: true, force: true });
    console.error(written.length
      ? `run.mjs: failed after writing ${written.join(', ')}'s folder; the rest not written`
      : 'run.mjs: failed; nothing written');
    if (browser) await browser.close().catch(() => {});
    process.exitCode = 1;
  } finally {
    clearTimeout(watchdog);
    server.close();
  }
}

main().catch((err) => fail(err.stack || String(err)));
