// The Babylon.js client of mirrorbox's exchange (docs/exchange.md), run in a page by ../run.mjs.
// It loads the export's scene.gltf with Babylon's own glTF loader (@babylonjs/loaders), shades it
// by the contract (docs/shading.md; ../README.md gives every conversion) and, per view and
// variant, renders linear radiance into a float render target, reads it back and box-filters it.
import { Engine } from '@babylonjs/core/Engines/engine.js';
import { Constants } from '@babylonjs/core/Engines/constants.js';
import { Scene } from '@babylonjs/core/scene.js';
import { TargetCamera } from '@babylonjs/core/Cameras/targetCamera.js';
import { Vector3 } from '@babylonjs/core/Maths/math.vector.js';
import { Color3, Color4 } from '@babylonjs/core/Maths/math.color.js';
import { Plane } from '@babylonjs/core/Maths/math.plane.js';
import { VertexBuffer } from '@babylonjs/core/Buffers/buffer.js';
import { Light } from '@babylonjs/core/Lights/light.js';
import '@babylonjs/core/Lights/pointLight.js';
import { Mesh } from '@babylonjs/core/Meshes/mesh.js';
import { VertexData } from '@babylonjs/core/Meshes/mesh.vertexData.js';
import { StandardMaterial } from '@babylonjs/core/Materials/standardMaterial.js';
import { PBRMaterial } from '@babylonjs/core/Materials/PBR/pbrMaterial.js';
import { MaterialPluginBase } from '@babylonjs/core/Materials/materialPluginBase.js';
import { ImageProcessingConfiguration } from '@babylonjs/core/Materials/imageProcessingConfiguration.js';
import { FresnelParameters } from '@babylonjs/core/Materials/fresnelParameters.js';
import { RenderTargetTexture } from '@babylonjs/core/Materials/Textures/renderTargetTexture.js';
import { MirrorTexture } from '@babylonjs/core/Materials/Textures/mirrorTexture.js';
import { ReflectionProbe } from '@babylonjs/core/Probes/reflectionProbe.js';
import '@babylonjs/core/Engines/Extensions/engine.renderTarget.js';
import '@babylonjs/core/Engines/Extensions/engine.renderTargetCube.js';
import { ImportMeshAsync } from '@babylonjs/core/Loading/sceneLoader.js';
import '@babylonjs/loaders/glTF/2.0/index.js';
import { boxFilter, base64, seededShuffle } from '../pixels.mjs';

const linear = (rgb) => new Color3(rgb[0], rgb[1], rgb[2]);

let engine;
let gl;
let size = { width: 0, height: 0 };
const built = {}; // variant name -> { scene, camera, output, mirrors, mirrorTextures?, probes? }

// Front-only emission. PBRMaterial emits from both sides; this plugin zeroes finalEmissive where
// the fragment is a back face. In a MirrorTexture pass Babylon flips the culled face instead of the
// winding (define MIRRORED), so gl_FrontFacing is inverted there, as PBR's own two-sided normal
// flip (pbrBlockNormalFinal) assumes.
class FrontEmission extends MaterialPluginBase {
  constructor(material) {
    super(material, 'MirrorboxFrontEmission', 200, { MIRRORBOX_FRONT_EMISSION: false }, true, true);
  }

  prepareDefines(defines) { defines.MIRRORBOX_FRONT_EMISSION = true; }

  getClassName() { return 'MirrorboxFrontEmission'; }

  isCompatible(shaderLanguage) { return shaderLanguage === 0; } // GLSL (WebGL)

  getCustomCode(shaderType) {
    if (shaderType !== 'fragment') return null;
    return {
      CUSTOM_FRAGMENT_BEFORE_FINALCOLORCOMPOSITION: `
#ifdef MIRRORED
        bool mirrorboxFront = !gl_FrontFacing;
#else
        bool mirrorboxFront = gl_FrontFacing;
#endif
        if (!mirrorboxFront) finalEmissive = vec3(0.0);`,
    };
  }
}

// PBRMaterial's output is linear and unclamped only when image processing is "applied by a post
// process" (IMAGEPROCESSINGPOSTPROCESS): with the scene's configuration disabled, PBR still runs
// applyImageProcessing, which gamma-encodes (toGammaSpace) and saturates. So every PBR material
// gets this configuration (and no post process is ever added); StandardMaterial (the mirrors)
// follows the scene's, disabled: its colour is written as computed.
let linearConfig;

// Diffuse, the contract's Lambert: the loader's PBRMaterial (metallic 0, roughness 1) with
// Lambert's 1/π diffuse BRDF, no dielectric specular (F0 factor 0: no specular lobe, no (1 − F)
// energy conservation on the diffuse), ambient colour white (PBR adds scene.ambientColor ×
// ambientColor × albedo: ρ·A), two-sided lighting without culling, front-only emission.
const configured = new Set();
function configureDiffuse(m, lights) {
  if (configured.has(m)) return m;
  if (!(m instanceof PBRMaterial)) throw new Error(`material "${m.name}" is a ${m.getClassName()}, not the glTF loader's PBRMaterial`);
  m.metallic = 0;
  m.roughness = 1;
  m.metallicF0Factor = 0;
  m.brdf.useLegacySpecularEnergyConservation = false;
  m.brdf.baseDiffuseModel = Constants.MATERIAL_DIFFUSE_MODEL_LAMBERT;
  m.ambientColor = Color3.White();
  m.backFaceCulling = false;
  m.twoSidedLighting = true;
  m.maxSimultaneousLights = Math.max(4, lights);
  m.imageProcessingConfiguration = linearConfig;
  m.environmentIntensity = 0;
  // Textures: the loader's sRGB buffers (SRGB8_ALPHA8: decoded before filtering) and the
  // sampler's LINEAR/LINEAR (bilinear, no mip-maps); Babylon's default anisotropic filtering
  // (level 4) is turned off: it blends more than the four texels around the sample on a
  // surface seen at a slant, which the contract's lookup does not.
  for (const t of m.getActiveTextures()) t.anisotropicFilteringLevel = 1;
  new FrontEmission(m); // eslint-disable-line no-new
  configured.add(m);
  return m;
}

// The mirror's back: diffuse with back_albedo, on a copy of the mirror's triangles with their
// winding reversed and their normals negated, culled on its back (the mirror's front). (Babylon's
// flipFaces only reverses indices, and the loader leaves these unindexed triangles without.)
function backOfMirror(mesh, info, scene, lights) {
  const pos = mesh.getVerticesData(VertexBuffer.PositionKind);
  const nrm = mesh.getVerticesData(VertexBuffer.NormalKind);
  const idx = mesh.getIndices();
  const order = idx && idx.length ? Array.from(idx) : [...Array(pos.length / 3).keys()];
  const positions = [];
  const normals = [];
  for (let t = 0; t < order.length; t += 3) {
    for (const k of [0, 2, 1]) {
      const i = order[t + k];
      positions.push(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]);
      normals.push(-nrm[3 * i], -nrm[3 * i + 1], -nrm[3 * i + 2]);
    }
  }
  const data = new VertexData();
  data.positions = positions;
  data.normals = normals;
  data.indices = [...Array(positions.length / 3).keys()];
  const back = new Mesh(`back of ${info.name}`, scene);
  // The loader's winding convention (a new Mesh in a right-handed scene starts clockwise).
  back.sideOrientation = mesh.sideOrientation;
  data.applyToMesh(back);
  back.parent = mesh.parent;
  back.position.copyFrom(mesh.position);
  back.rotationQuaternion = mesh.rotationQuaternion?.clone() ?? null;
  back.rotation.copyFrom(mesh.rotation);
  back.scaling.copyFrom(mesh.scaling);
  const m = new PBRMaterial(`back ${info.name}`, scene);
  m.albedoColor = linear(info.back_albedo);
  configureDiffuse(m, lights);
  m.backFaceCulling = true;
  m.twoSidedLighting = false;
  back.material = m;
  return back;
}

// A mirror's rectangle from its triangles: centre, axes (right × up = the front normal n_f of its
// first triangle), width and height (as the three client's mirrorFrame).
function mirrorFrame(mesh) {
  const world = mesh.computeWorldMatrix(true);
  const p = mesh.getVerticesData(VertexBuffer.PositionKind);
  const idx = mesh.getIndices();
  const order = idx && idx.length ? Array.from(idx) : [...Array(p.length / 3).keys()];
  const pts = order.map((i) => Vector3.TransformCoordinates(new Vector3(p[3 * i], p[3 * i + 1], p[3 * i + 2]), world));
  const [a, b, c] = pts;
  const normal = Vector3.Cross(b.subtract(a), c.subtract(a)).normalize();
  let best = null;
  for (const [u, v] of [[a, b], [b, c], [c, a]]) {
    const right = v.subtract(u).normalize();
    const up = Vector3.Cross(normal, right);
    const us = pts.map((x) => Vector3.Dot(x, right));
    const vs = pts.map((x) => Vector3.Dot(x, up));
    const [u0, u1, v0, v1] = [Math.min(...us), Math.max(...us), Math.min(...vs), Math.max(...vs)];
    const area = (u1 - u0) * (v1 - v0);
    if (!best || area < best.area) {
      const centre = right.scale((u0 + u1) / 2).add(up.scale((v0 + v1) / 2)).add(normal.scale(Vector3.Dot(a, normal)));
      best = { area, right, up, normal, centre, width: u1 - u0, height: v1 - v0 };
    }
  }
  return best;
}

// What a mirror shows: StandardMaterial with nothing but its reflection texture (no diffuse,
// specular, emissive, ambient or lighting), level 1, times the reflectance: a Fresnel term whose
// left and right colours are both the reflectance, R·(1 − f) + f·R = R at every angle. Its colour
// is added outside StandardMaterial's [0, 1] clamp of the diffuse part, so it stays HDR.
function reflectingMaterial(name, info, texture, scene) {
  const m = new StandardMaterial(name, scene);
  m.diffuseColor = Color3.Black();
  m.specularColor = Color3.Black();
  m.emissiveColor = Color3.Black();
  m.ambientColor = Color3.Black();
  m.disableLighting = true;
  m.backFaceCulling = true;
  m.sideOrientation = null; // the mesh's (the loader's counter-clockwise): front faces only
  texture.level = 1;
  m.reflectionTexture = texture;
  const r = linear(info.reflectance);
  m.reflectionFresnelParameters = new FresnelParameters({ leftColor: r, rightColor: r.clone(), bias: 0, power: 1 });
  return m;
}

const TEXTURE_TYPES = {
  byte: Constants.TEXTURETYPE_UNSIGNED_BYTE,
  half: Constants.TEXTURETYPE_HALF_FLOAT,
  float: Constants.TEXTURETYPE_FLOAT,
};

function outputTarget(scene, W, H) {
  return new RenderTargetTexture('mirrorbox output', { width: W, height: H }, scene, {
    generateMipMaps: false,
    type: Constants.TEXTURETYPE_FLOAT,
    format: Constants.TEXTUREFORMAT_RGBA,
    samplingMode: Constants.TEXTURE_NEAREST_SAMPLINGMODE,
    generateDepthBuffer: true,
    generateStencilBuffer: false,
  });
}

async function buildVariant(name, options, view) {
  const { contract } = options;
  const scene = new Scene(engine);
  scene.useRightHandedSystem = true; // glTF's: the loader adds no handedness flip
  scene.clearColor = new Color4(...contract.background, 1);
  scene.ambientColor = linear(contract.ambient);
  scene.imageProcessingConfiguration.isEnabled = false;
  scene.skipPointerMovePicking = true;
  const c = view.camera;
  const camera = new TargetCamera('view', new Vector3(...c.position), scene, true);
  scene.activeCamera = camera;
  let gltfExtras = null;
  const result = await ImportMeshAsync(options.gltfUrl, scene, {
    pluginOptions: {
      gltf: {
        onParsed: (data) => { gltfExtras = data.json.scenes?.[0]?.extras?.mirrorbox ?? null; },
      },
    },
  });
  for (const cam of scene.cameras.slice()) if (cam !== camera) cam.dispose(); // the glTF's camera: views.json's is used
  scene.activeCamera = camera;
  const lights = scene.lights;
  for (const light of lights) {
    if (light.getClassName() !== 'PointLight') throw new Error(`light "${light.name}" is a ${light.getClassName()}: only point lights are in the contract`);
    light.falloffType = Light.FALLOFF_PHYSICAL; // 1/r² (the loader's glTF falloff with an infinite range is the same)
    light.intensityMode = Light.INTENSITYMODE_LUMINOUSINTENSITY; // candela = W/sr, photometric scale 1
    light.specular = Color3.Black(); // no specular lobe (and no SPECULARTERM)
  }
  const mirrors = [];
  const meshes = result.meshes.filter((m) => m.getTotalVertices() > 0);
  for (const mesh of meshes) {
    const info = mesh.material?.metadata?.gltf?.extras?.mirrorbox_mirror;
    if (info) mirrors.push({ mesh, info });
    else configureDiffuse(mesh.material, lights.length);
  }
  const W = view.width * view.ssaa;
  const H = view.height * view.ssaa;
  const output = outputTarget(scene, W, H);
  camera.outputRenderTarget = output;
  const v = { scene, camera, output, mirrors: mirrors.length, gltfExtras, targets: [] };
  const diffuseMeshes = meshes.filter((m) => !mirrors.some((x) => x.mesh === m));
  if (name === 'floor') {
    for (const { mesh } of mirrors) mesh.dispose();
  } else if (name === 'mirrortexture' || name === 'probe') {
    const parts = mirrors.map(({ mesh, info }) => ({ mesh, info, frame: mirrorFrame(mesh), back: backOfMirror(mesh, info, scene, lights.length) }));
    for (const part of parts) {
      const others = [...diffuseMeshes, ...parts.filter((p) => p !== part).flatMap((p) => [p.mesh, p.back])];
      if (name === 'mirrortexture') {
        const tex = new MirrorTexture(`mirror ${part.info.name}`, { width: W, height: H }, scene, false,
          TEXTURE_TYPES[options.mirrorType], Constants.TEXTURE_BILINEAR_SAMPLINGMODE, true);
        // Babylon discards where plane·x > 0 (clipPlaneFragment): the plane's normal points into
        // the mirror, so what lies in front of it is kept. Its reflection is the same either way.
        tex.mirrorPlane = Plane.FromPositionAndNormal(part.frame.centre, part.frame.normal.negate());
        tex.blurKernel = 0;
        tex.adaptiveBlurKernel = 0;
        tex.renderList = others;
        tex.refreshRate = RenderTargetTexture.REFRESHRATE_RENDER_ONEVERYFRAME;
        part.mesh.material = reflectingMaterial(`mirrortexture ${part.info.name}`, part.info, tex, scene);
        v.targets.push(tex);
      } else {
        const probe = new ReflectionProbe(`probe ${part.info.name}`, options.cubeSize, scene, false, true, false);
        probe.position.copyFrom(part.frame.centre);
        probe.renderList.push(...others);
        probe.refreshRate = RenderTargetTexture.REFRESHRATE_RENDER_ONEVERYFRAME;
        // Right-handed scenes: ReflectionProbe renders cube face 4 (GL's +Z) looking down −Z and
        // marks its cube invertZ, and the material helper then turns REFLECTIONMAP_OPPOSITEZ *off*
        // for a cube in a right-handed scene (!invertZ): the lookup of a direction +z reads the
        // face drawn towards −z, so every mirror showed what lies behind it (measured: the box's
        // mirrors all background). invertZ = false gives OPPOSITEZ and the lookup matches
        // three's CubeCamera to 1e-4 FLIP on mirror_box (README.md).
        probe.cubeTexture.invertZ = false;
        part.mesh.material = reflectingMaterial(`probe ${part.info.name}`, part.info, probe.cubeTexture, scene);
        v.targets.push(probe.cubeTexture);
        v.probes = v.probes || [];
        v.probes.push(probe);
      }
    }
  } else {
    throw new Error(`unknown variant ${name}`);
  }
  return v;
}

// Before its first update a probe's cube shows the terminal radiance (the depth cap), as
// mirrorbox's cubemap's first frame (and the three client's CubeCamera).
function clearProbes(v, terminal) {
  for (const probe of v.probes || []) {
    const rt = probe.cubeTexture.renderTarget;
    for (let face = 0; face < 6; face++) {
      engine.bindFramebuffer(rt, face);
      engine.clear(new Color4(...terminal, 1), true, true, false);
      engine.unBindFramebuffer(rt, true);
    }
  }
}

function resize(view) {
  const W = view.width * view.ssaa;
  const H = view.height * view.ssaa;
  if (size.width === W && size.height === H) return;
  size = { width: W, height: H };
  engine.setSize(W, H, true);
  for (const v of Object.values(built)) {
    v.output.resize({ width: W, height: H });
    for (const t of v.targets) if (t instanceof MirrorTexture) t.resize({ width: W, height: H });
  }
}

function placeCamera(v, view) {
  const c = view.camera;
  const camera = v.camera;
  camera.position.set(...c.position);
  camera.upVector = new Vector3(...c.up);
  camera.setTarget(new Vector3(...c.look_at));
  camera.fovMode = TargetCamera.FOVMODE_VERTICAL_FIXED;
  camera.fov = (c.fov_y_deg * Math.PI) / 180;
  camera.minZ = c.near;
  camera.maxZ = c.far;
  camera.computeWorldMatrix(true);
  // How far Babylon's matrices are from views.json's (both column-major: Babylon's m[12..14]
  // is the translation).
  const viewMatrix = camera.getViewMatrix(true).m;
  const projection = camera.getProjectionMatrix(true).m;
  let diff = 0;
  view.view_matrix.forEach((x, i) => { diff = Math.max(diff, Math.abs(x - viewMatrix[i])); });
  view.projection_gl.forEach((x, i) => { diff = Math.max(diff, Math.abs(x - projection[i]) / Math.max(1, Math.abs(x))); });
  return diff;
}

// One frame of a variant: Scene.render draws the scene's render targets (each MirrorTexture, each
// probe's six faces) and then the camera's pass into its output target.
function draw(v) {
  v.scene.render(true, true);
}

function readTarget(v, x, y, w, h, out) {
  const rt = v.output.renderTarget;
  engine.bindFramebuffer(rt);
  gl.readPixels(x, y, w, h, gl.RGBA, gl.FLOAT, out);
  engine.unBindFramebuffer(rt, true);
}

// Mean of each pixel's s × s block, rows flipped (GL reads bottom-up; EXR line 0 is the top).
function readBack(v, view) {
  const { width: W, height: H } = size;
  const rgba = new Float32Array(W * H * 4);
  readTarget(v, 0, 0, W, H, rgba);
  return boxFilter(rgba, W, H, view);
}

// Wait for the GPU. Chromium's gl.finish() is only a flush; a 1×1 readback of the target blocks
// until every command before it has run.
const pixel = new Float32Array(4);
function finish(v) {
  gl.finish();
  readTarget(v, 0, 0, 1, 1, pixel);
}

let shuffled;

async function init(options) {
  shuffled = seededShuffle(options.seed);
  if (!(options.mirrorType in TEXTURE_TYPES)) throw new Error(`unknown mirror texture type ${options.mirrorType}`);
  const canvas = document.getElementById('canvas');
  engine = new Engine(canvas, false, {
    antialias: false, alpha: false, premultipliedAlpha: false, preserveDrawingBuffer: false, stencil: true,
    audioEngine: false, doNotHandleContextLost: true, powerPreference: 'high-performance',
  }, false);
  if (engine.webGLVersion < 2) throw new Error('no WebGL 2');
  gl = engine._gl;
  if (!engine.getCaps().textureFloatRender) throw new Error('no float render targets (EXT_color_buffer_float)');
  // Compile shaders synchronously: with KHR_parallel_shader_compile a mesh whose effect is still
  // compiling is skipped, in the main pass and in every render target pass.
  engine.getCaps().parallelShaderCompile = undefined;
  engine.setHardwareScalingLevel(1);
  linearConfig = new ImageProcessingConfiguration();
  linearConfig.isEnabled = true;
  linearConfig.applyByPostProcess = true;
  linearConfig.skipFinalColorClamp = true;
  linearConfig.toneMappingEnabled = false;
  linearConfig.exposure = 1;
  linearConfig.contrast = 1;
  const first = options.views[0];
  resize(first);
  let gltfExtras = null;
  for (const name of options.variants) {
    built[name] = await buildVariant(name, options, first);
    gltfExtras = built[name].gltfExtras;
  }
  for (const v of Object.values(built)) {
    placeCamera(v, first);
    await v.scene.whenReadyAsync();
    clearProbes(v, options.contract.terminal);
  }
  const ext = gl.getExtension('WEBGL_debug_renderer_info');
  return {
    version: Engine.Version,
    device: ext ? gl.getParameter(ext.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER),
    driver: `${ext ? gl.getParameter(ext.UNMASKED_VENDOR_WEBGL) : gl.getParameter(gl.VENDOR)}; ${gl.getParameter(gl.VERSION)}; ${navigator.userAgent}`,
    subpixelBits: gl.getParameter(gl.SUBPIXEL_BITS),
    isolated: self.crossOriginIsolated === true,
    mirrors: Object.fromEntries(Object.entries(built).map(([k, v]) => [k, v.mirrors])),
    gltfExtras,
  };
}

async function runView(view, frames, warmup) {
  resize(view);
  const names = Object.keys(built);
  let diff = 0;
  for (const name of names) diff = Math.max(diff, placeCamera(built[name], view));
  const times = Object.fromEntries(names.map((n) => [n, []]));
  const overhead = [];
  for (let round = 0; round < warmup + frames; round++) {
    for (const name of shuffled(names)) {
      const v = built[name];
      const t0 = performance.now();
      draw(v);
      finish(v);
      const ms = performance.now() - t0;
      if (round >= warmup) times[name].push(ms);
    }
    const v = built[names[0]];
    const t0 = performance.now();
    finish(v);
    overhead.push(performance.now() - t0);
    await new Promise((r) => setTimeout(r, 0)); // let the page breathe between rounds
  }
  const images = {};
  for (const name of names) {
    const v = built[name];
    if (!v.scene.isReady()) throw new Error(`variant ${name}: the scene is still not ready after ${warmup + frames} frames`);
    draw(v);
    images[name] = base64(readBack(v, view));
  }
  return { times, images, cameraDiff: diff, syncMs: overhead.sort((a, b) => a - b)[overhead.length >> 1] };
}

window.mirrorbox = { init, runView };
window.mirrorboxReady = true;
