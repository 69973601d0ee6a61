// The three.js client of mirrorbox's exchange (docs/exchange.md), run in a page by ../run.mjs.
// It loads the export's scene.gltf with three's GLTFLoader, shades it by the contract
// (docs/shading.md; ../README.md gives every conversion) and, per view and variant, renders
// linear radiance into a float render target, reads it back and box-filters it.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { Reflector } from 'three/addons/objects/Reflector.js';
import { boxFilter, base64, seededShuffle } from '../pixels.mjs';

// Reflector's shader with one line changed: the shipped one blends the reflected colour with
// `color` by an overlay, which is not a reflectance; this one multiplies it by the mirror's
// reflectance (the contract's L = R ⊙ L(reflected ray)).
const SHIPPED_LINE = 'gl_FragColor = vec4( blendOverlay( base.rgb, color ), 1.0 );';
const ReflectanceShader = {
  ...Reflector.ReflectorShader,
  name: 'ReflectanceShader',
  fragmentShader: Reflector.ReflectorShader.fragmentShader.replace(
    SHIPPED_LINE,
    'gl_FragColor = vec4( color * base.rgb, 1.0 );',
  ),
};
if (ReflectanceShader.fragmentShader === Reflector.ReflectorShader.fragmentShader) {
  throw new Error(`Reflector.ReflectorShader no longer contains "${SHIPPED_LINE}": update client.mjs`);
}

const linear = (rgb) => new THREE.Color().setRGB(rgb[0], rgb[1], rgb[2], THREE.LinearSRGBColorSpace);

let renderer;
let gl;
let target; // the float render target every variant draws into
let size = { width: 0, height: 0 };
const built = {}; // variant name -> { scene, cubes?, reflectors? }
let settings;

// Diffuse: Lambert, two-sided (DoubleSide flips the file's face normal on back faces),
// emission from the front only (three's emissive is two-sided: patched out on back faces).
const lamberts = new Map();
function lambert(source) {
  let m = lamberts.get(source);
  if (m) return m;
  m = new THREE.MeshLambertMaterial({
    name: source.name,
    color: source.color,
    map: source.map,
    emissive: source.emissive,
    emissiveMap: source.emissiveMap,
    emissiveIntensity: source.emissiveIntensity,
    side: THREE.DoubleSide,
  });
  m.onBeforeCompile = (shader) => {
    const chunk = '#include <emissivemap_fragment>';
    if (!shader.fragmentShader.includes(chunk)) throw new Error(`no ${chunk} in MeshLambertMaterial`);
    shader.fragmentShader = shader.fragmentShader.replace(
      chunk,
      `${chunk}\n\tif ( ! gl_FrontFacing ) totalEmissiveRadiance = vec3( 0.0 );`,
    );
  };
  m.customProgramCacheKey = () => 'mirrorbox-front-emission';
  lamberts.set(source, m);
  return m;
}

function backOfMirror(info) {
  return new THREE.MeshLambertMaterial({ color: linear(info.back_albedo), side: THREE.BackSide });
}

// A mirror's rectangle from its triangles: centre, axes (right × up = the front normal n_f of
// its first triangle), width and height. The axes are the pair of edges of the first triangle
// that gives the smallest bounding rectangle (the rectangle's own sides).
function mirrorFrame(mesh) {
  mesh.updateWorldMatrix(true, false);
  const pos = mesh.geometry.getAttribute('position');
  const pts = [];
  for (let i = 0; i < pos.count; i++) pts.push(new THREE.Vector3().fromBufferAttribute(pos, i).applyMatrix4(mesh.matrixWorld));
  const [a, b, c] = pts;
  const normal = new THREE.Vector3().subVectors(b, a).cross(new THREE.Vector3().subVectors(c, a)).normalize();
  let best = null;
  for (const [p, q] of [[a, b], [b, c], [c, a]]) {
    const right = new THREE.Vector3().subVectors(q, p).normalize();
    const up = new THREE.Vector3().crossVectors(normal, right);
    const us = pts.map((v) => v.dot(right));
    const vs = pts.map((v) => v.dot(up));
    const [u0, u1, v0, v1] = [Math.min(...us), Math.max(...us), Math.min(...vs), Math.max(...vs)];
    const area = (u1 - u0) * (v1 - v0);
    if (!best || area < best.area) {
      const centre = right.clone().multiplyScalar((u0 + u1) / 2)
        .addScaledVector(up, (v0 + v1) / 2)
        .addScaledVector(normal, a.dot(normal));
      best = { area, right, up, normal, centre, width: u1 - u0, height: v1 - v0 };
    }
  }
  return best;
}

// The cube mirror: MeshBasicMaterial with the cube as envMap (MultiplyOperation: reflectance ×
// the cube's radiance). Shipped, MeshBasicMaterial reflects per vertex (vReflect, interpolated
// across the quad: wrong directions on a large mirror near the camera); patched to reflect
// the exact view direction per fragment about the mirror's face normal, as mirrorbox's cubemap.
function cubeMirrorMaterial(info, cubeTarget, normal) {
  const m = new THREE.MeshBasicMaterial({ color: linear(info.reflectance), envMap: cubeTarget.texture, side: THREE.FrontSide });
  m.onBeforeCompile = (shader) => {
    shader.uniforms.mbMirrorNormal = { value: normal.clone() };
    const swap = (src, from, to) => {
      if (!src.includes(from)) throw new Error(`MeshBasicMaterial has no "${from}": update cubeMirrorMaterial`);
      return src.replace(from, to);
    };
    shader.vertexShader = swap(shader.vertexShader, '#include <envmap_vertex>',
      '#include <envmap_vertex>\n\tvMbWorldPosition = ( modelMatrix * vec4( transformed, 1.0 ) ).xyz;');
    shader.vertexShader = `varying vec3 vMbWorldPosition;\n${shader.vertexShader}`;
    // Checked as the outer swap: a renamed line would have left the per-vertex reflection, unsaid.
    shader.fragmentShader = swap(shader.fragmentShader, '#include <envmap_fragment>',
      swap(THREE.ShaderChunk.envmap_fragment, 'vec3 reflectVec = vReflect;',
        'vec3 reflectVec = reflect( normalize( vMbWorldPosition - cameraPosition ), mbMirrorNormal );'));
    shader.fragmentShader = `varying vec3 vMbWorldPosition;\nuniform vec3 mbMirrorNormal;\n${shader.fragmentShader}`;
  };
  m.customProgramCacheKey = () => 'mirrorbox-cube-mirror-per-fragment';
  return m;
}

function buildVariant(name, gltfScene, contract, view) {
  const root = gltfScene.clone(true);
  const scene = new THREE.Scene();
  scene.background = linear(contract.background);
  // three's Lambert adds irradiance × ρ/π for an AmbientLight's colour × intensity: π·A gives ρ·A.
  scene.add(new THREE.AmbientLight(linear(contract.ambient), Math.PI));
  scene.add(root);
  const mirrors = [];
  root.traverse((o) => {
    if (o.isLight) {
      if (!o.isPointLight) throw new Error(`light "${o.name}" is a ${o.type}: only point lights are in the contract`);
      o.decay = 2; // 1/r²
      o.distance = 0; // no cut-off; intensity: candela = the contract's W/sr (physically based since r155)
    }
    if (!o.isMesh) return;
    const info = o.material.userData && o.material.userData.mirrorbox_mirror;
    if (info) mirrors.push({ mesh: o, info });
    else o.material = lambert(o.material);
  });
  const v = { scene, mirrors: mirrors.length };
  const W = view.width * view.ssaa;
  const H = view.height * view.ssaa;
  if (name === 'floor') {
    for (const { mesh } of mirrors) mesh.removeFromParent();
  } else if (name === 'reflector') {
    v.reflectors = mirrors.map(({ mesh, info }) => {
      const f = mirrorFrame(mesh);
      const reflector = new Reflector(new THREE.PlaneGeometry(f.width, f.height), {
        color: linear(info.reflectance),
        textureWidth: W,
        textureHeight: H,
        clipBias: settings.clipBias,
        multisample: settings.reflectorSamples,
        shader: ReflectanceShader,
      });
      reflector.name = `reflector ${info.name}`;
      reflector.position.copy(f.centre);
      reflector.quaternion.setFromRotationMatrix(new THREE.Matrix4().makeBasis(f.right, f.up, f.normal));
      scene.add(reflector);
      // The mirror's back, as a child: hidden with the reflector while it draws its reflection
      // (the reflection camera sees the back of the mirror's plane, right at its clip plane).
      mesh.removeFromParent();
      reflector.add(new THREE.Mesh(reflector.geometry, backOfMirror(info)));
      return reflector;
    });
  } else if (name === 'cubecamera') {
    const c = view.camera;
    v.cubes = mirrors.map(({ mesh, info }) => {
      const f = mirrorFrame(mesh);
      const cubeTarget = new THREE.WebGLCubeRenderTarget(settings.cubeSize, { type: THREE.HalfFloatType });
      // Before its first update a cube shows the terminal radiance (the depth cap), as
      // mirrorbox's cubemap's first frame.
      const clear = renderer.getClearColor(new THREE.Color());
      renderer.setClearColor(linear(contract.terminal), 1);
      cubeTarget.clear(renderer);
      renderer.setClearColor(clear, 1);
      const cubeCamera = new THREE.CubeCamera(c.near, c.far, cubeTarget);
      cubeCamera.position.copy(f.centre);
      scene.add(cubeCamera);
      const front = new THREE.Mesh(mesh.geometry, cubeMirrorMaterial(info, cubeTarget, f.normal));
      front.name = `cube mirror ${info.name}`;
      front.matrixAutoUpdate = false;
      front.matrix.copy(mesh.matrixWorld);
      scene.add(front);
      mesh.material = backOfMirror(info);
      return { camera: cubeCamera, front, back: mesh };
    });
  } else {
    throw new Error(`unknown variant ${name}`);
  }
  return v;
}

function resize(view) {
  const W = view.width * view.ssaa;
  const H = view.height * view.ssaa;
  if (size.width === W && size.height === H) return;
  size = { width: W, height: H };
  renderer.setSize(W, H, false);
  if (target) target.dispose();
  target = new THREE.WebGLRenderTarget(W, H, {
    type: THREE.FloatType,
    format: THREE.RGBAFormat,
    minFilter: THREE.NearestFilter,
    magFilter: THREE.NearestFilter,
    depthBuffer: true,
    samples: 0,
  });
  for (const v of Object.values(built)) {
    for (const r of v.reflectors || []) r.getRenderTarget().setSize(W, H);
  }
}

function cameraOf(view) {
  const c = view.camera;
  const camera = new THREE.PerspectiveCamera(c.fov_y_deg, c.aspect, c.near, c.far);
  camera.position.fromArray(c.position);
  camera.up.fromArray(c.up);
  camera.lookAt(new THREE.Vector3().fromArray(c.look_at));
  camera.updateMatrixWorld(true);
  camera.updateProjectionMatrix();
  // How far three's matrices are from views.json's (column-major, the same conventions).
  let diff = 0;
  view.view_matrix.forEach((x, i) => { diff = Math.max(diff, Math.abs(x - camera.matrixWorldInverse.elements[i])); });
  view.projection_gl.forEach((x, i) => {
    diff = Math.max(diff, Math.abs(x - camera.projectionMatrix.elements[i]) / Math.max(1, Math.abs(x)));
  });
  return { camera, diff };
}

// One frame of a variant: its reflection passes (Reflector: inside render, in onBeforeRender;
// CubeCamera: six faces per mirror, each with that mirror hidden) and the main pass.
function draw(v, camera) {
  renderer.setRenderTarget(target);
  for (const c of v.cubes || []) {
    c.front.visible = false;
    c.back.visible = false;
    c.camera.update(renderer, v.scene);
    c.front.visible = true;
    c.back.visible = true;
  }
  renderer.render(v.scene, camera);
}

// Mean of each pixel's s × s block, rows flipped (GL reads bottom-up; EXR line 0 is the top).
function readBack(view) {
  const { width: W, height: H } = size;
  const rgba = new Float32Array(W * H * 4);
  renderer.readRenderTargetPixels(target, 0, 0, W, H, rgba);
  return boxFilter(rgba, W, H, view);
}

// Wait for the GPU. Chromium's gl.finish() is only a flush (it returns before the GPU is
// done); a 1×1 readback of the target blocks until every command before it has run.
const pixel = new Float32Array(4);
function finish() {
  gl.finish();
  renderer.readRenderTargetPixels(target, 0, 0, 1, 1, pixel);
}

let shuffled;

async function init(options) {
  settings = options;
  shuffled = seededShuffle(options.seed);
  renderer = new THREE.WebGLRenderer({ canvas: document.getElementById('canvas'), antialias: false, alpha: false });
  renderer.setPixelRatio(1);
  renderer.toneMapping = THREE.NoToneMapping;
  renderer.outputColorSpace = THREE.LinearSRGBColorSpace; // only the canvas uses it; targets stay linear
  gl = renderer.getContext();
  if (!renderer.extensions.has('EXT_color_buffer_float')) throw new Error('no EXT_color_buffer_float: cannot render to a float target');
  const gltf = await new GLTFLoader().loadAsync(options.gltfUrl);
  const first = options.views[0];
  resize(first);
  for (const name of options.variants) built[name] = buildVariant(name, gltf.scene, options.contract, first);
  const info = renderer.extensions.get('WEBGL_debug_renderer_info');
  return {
    revision: THREE.REVISION,
    device: info ? gl.getParameter(info.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER),
    driver: `${info ? gl.getParameter(info.UNMASKED_VENDOR_WEBGL) : gl.getParameter(gl.VENDOR)}; ${gl.getParameter(gl.VERSION)}; ${navigator.userAgent}`,
    subpixelBits: gl.getParameter(gl.SUBPIXEL_BITS),
    isolated: self.crossOriginIsolated === true,
    mirrors: Object.fromEntries(Object.entries(built).map(([k, v]) => [k, v.mirrors])),
    gltfExtras: gltf.scene.userData.mirrorbox || null,
  };
}

async function runView(view, frames, warmup) {
  resize(view);
  const { camera, diff } = cameraOf(view);
  const names = Object.keys(built);
  const times = Object.fromEntries(names.map((n) => [n, []]));
  const overhead = [];
  for (let round = 0; round < warmup + frames; round++) {
    for (const name of shuffled(names)) {
      const t0 = performance.now();
      draw(built[name], camera);
      finish();
      const ms = performance.now() - t0;
      if (round >= warmup) times[name].push(ms);
    }
    const t0 = performance.now();
    finish();
    overhead.push(performance.now() - t0);
    await new Promise((r) => setTimeout(r, 0)); // let the page breathe between rounds
  }
  const images = {};
  for (const name of names) {
    draw(built[name], camera);
    images[name] = base64(readBack(view));
  }
  return { times, images, cameraDiff: diff, syncMs: overhead.sort((a, b) => a - b)[overhead.length >> 1] };
}

window.mirrorbox = { init, runView };
window.mirrorboxReady = true;
