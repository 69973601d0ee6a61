//! A structure-aware fuzzer over the bundled scenes (issue #12): each mutant replaces one node
//! of a scene's JSON tree with an extreme or ill-typed value, deletes it, or repeats it. A
//! mutant that `load` refuses must be refused with an error (never a panic); a mutant that
//! `load` accepts must trace and render with every registered method without a panic and
//! without a wgpu validation error — a refusal (too many passes, paths, …) is a fine outcome.
//!
//! Deterministic (a fixed seed). `MIRRORBOX_FUZZ_MUTANTS=N` runs N mutants instead of the CI
//! default; `MIRRORBOX_FUZZ_SEED=S` another sequence. The fixed reproducers of the issue run
//! first. The children compile shaders with `GALLIVM_PERF=nopt` unless it is set
//! ([`CHILD_GALLIVM_PERF`]; set it empty to compile them optimised).

use mirrorbox_raster::{Gpu, METHODS, Method, RenderSettings};
use mirrorbox_scene::Scene;
use mirrorbox_scene::load::parse_scene;
use mirrorbox_trace::{IntegratorSettings, PathSettings, SceneBvh, TraceSettings, WhittedSettings};
use serde_json::{Value, json};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

/// SplitMix64: small, fast and good enough to pick mutations.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// Numbers that have broken renderers before: float and integer limits, zero, tiny and huge
/// magnitudes, the scene extent's edge.
fn extreme_numbers() -> Vec<Value> {
    vec![
        json!(0),
        json!(-0.0),
        json!(1e-38),
        json!(-1e-38),
        json!(1e-7),
        json!(3.4e38),
        json!(-3.4e38),
        json!(1e30),
        json!(999999.0),
        json!(1e6),
        json!(1.0000001e6),
        json!(-1),
        json!(7),
        json!(8),
        json!(64),
        json!(4294967295u64),
        json!(4294967296u64),
        json!(16384),
        json!(0.5),
        json!(1),
        json!(179.99),
        json!(1e-30),
        json!(2),
        json!(-5.5),
        json!(0.001),
    ]
}

/// Values of the wrong shape or type.
fn odd_values() -> Vec<Value> {
    vec![
        json!("text"),
        json!(null),
        json!(true),
        json!([]),
        json!([0, 0, 0]),
        json!([1e30, -1e30, 0]),
        json!({}),
    ]
}

/// Every path (object keys and array indices) of the JSON tree, root excluded.
fn node_paths(v: &Value, prefix: &mut Vec<Value>, out: &mut Vec<Vec<Value>>) {
    match v {
        Value::Object(map) => {
            for (k, child) in map {
                prefix.push(json!(k));
                out.push(prefix.clone());
                node_paths(child, prefix, out);
                prefix.pop();
            }
        }
        Value::Array(items) => {
            for (i, child) in items.iter().enumerate() {
                prefix.push(json!(i));
                out.push(prefix.clone());
                node_paths(child, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

fn parent_and_key<'a>(root: &'a mut Value, path: &[Value]) -> (&'a mut Value, Value) {
    let (last, init) = path.split_last().expect("non-empty path");
    let mut node = root;
    for step in init {
        node = match step {
            Value::String(k) => &mut node[k.as_str()],
            _ => &mut node[step.as_u64().unwrap() as usize],
        };
    }
    (node, last.clone())
}

/// One mutation of `scene`: replace a node, delete it, or repeat an array element.
pub(crate) fn mutate(scene: &Value, rng: &mut Rng) -> Value {
    let mut mutant = scene.clone();
    let mut paths = Vec::new();
    node_paths(&mutant, &mut Vec::new(), &mut paths);
    let mutations = 1 + rng.below(3);
    for _ in 0..mutations {
        // Leaves (numbers) most of the time: they reach the renderers.
        let leaves: Vec<&Vec<Value>> = paths
            .iter()
            .filter(|p| {
                let mut node = &mutant;
                for step in p.iter() {
                    node = match step {
                        Value::String(k) => &node[k.as_str()],
                        _ => &node[step.as_u64().unwrap() as usize],
                    };
                }
                node.is_number()
            })
            .collect();
        let path = if !leaves.is_empty() && rng.below(4) != 0 {
            (*rng.pick(&leaves)).clone()
        } else {
            rng.pick(&paths).clone()
        };
        let (parent, key) = parent_and_key(&mut mutant, &path);
        match (rng.below(10), parent, key) {
            (0, Value::Object(map), Value::String(k)) => {
                map.remove(&k);
            }
            (1, Value::Array(items), Value::Number(i)) => {
                let i = i.as_u64().unwrap() as usize;
                if i < items.len() {
                    let copy = items[i].clone();
                    let times = 1 + rng.below(4);
                    for _ in 0..times {
                        items.push(copy.clone());
                    }
                }
            }
            (_, parent, key) => {
                let current = match (&*parent, &key) {
                    (Value::Object(map), Value::String(k)) => map.get(k).cloned(),
                    (Value::Array(items), Value::Number(i)) => {
                        items.get(i.as_u64().unwrap() as usize).cloned()
                    }
                    _ => None,
                };
                // Mostly a number for a number (deep into the renderers), sometimes any value.
                let numeric = current.is_some_and(|c| c.is_number()) && rng.below(8) != 0;
                let value = if numeric || rng.below(2) == 0 {
                    rng.pick(&extreme_numbers()).clone()
                } else {
                    rng.pick(&odd_values()).clone()
                };
                match (parent, key) {
                    (Value::Object(map), Value::String(k)) => {
                        map.insert(k, value);
                    }
                    (Value::Array(items), Value::Number(i)) => {
                        let i = i.as_u64().unwrap() as usize;
                        if i < items.len() {
                            items[i] = value;
                        }
                    }
                    _ => {}
                }
            }
        }
        // Paths may be stale after a structural change: recompute.
        paths.clear();
        node_paths(&mutant, &mut Vec::new(), &mut paths);
        if paths.is_empty() {
            break;
        }
    }
    mutant
}

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

fn bundled() -> Vec<(PathBuf, Value)> {
    let mut out: Vec<(PathBuf, Value)> = std::fs::read_dir(scenes_dir())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .map(|p| {
            let v = serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
            (p, v)
        })
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

/// What a mutant did.
#[derive(Default, Debug)]
struct Tally {
    tried: usize,
    refused_by_load: usize,
    traced: usize,
    rendered: usize,
    refused_by_method: usize,
}

/// Traces (small, shallow) and renders with every method; returns the failures (panics and
/// wgpu validation errors), each with what failed.
fn exercise(scene: &Scene, gpu: &Gpu, render_too: bool, tally: &mut Tally) -> Vec<String> {
    let mut failures = Vec::new();
    let mut small = scene.clone();
    if small.resize(Some(12), Some(8)).is_err() {
        return vec!["resize to 12x8 refused".into()];
    }
    let traced = catch_unwind(AssertUnwindSafe(|| {
        let bvh = SceneBvh::build(&small.geometry);
        for integrator in [
            IntegratorSettings::from(WhittedSettings {
                max_depth: 64,
                min_throughput: 1e-3,
            }),
            PathSettings {
                max_segments: 8,
                rr_from: 3,
                seed: 1,
            }
            .into(),
        ] {
            let settings = TraceSettings::whitted(1).with_integrator(integrator);
            let out = mirrorbox_trace::render(&small, &bvh, &settings, &|_| {});
            assert_eq!(out.image.pixels.len(), 12 * 8);
        }
    }));
    match traced {
        Ok(()) => tally.traced += 1,
        Err(e) => failures.push(format!("trace panicked: {}", panic_text(&e))),
    }
    if !render_too {
        return failures;
    }
    // `symmetry` submits 2^p copies of the objects: on symmetry_many (10 planes, 5 708
    // triangles) 5.8 M triangles, ~3 s a frame on lavapipe even at 12×8. Nine planes keep
    // every path of the symmetry methods (more than 8 planes: discard instead of clip
    // distances) at half the cost; the bake and the trace above saw every plane.
    let planes = small.symmetry.as_ref().map_or(0, |s| s.planes.len());
    if planes > 9 {
        match small.with_symmetry_planes(9) {
            Ok(fewer) => small = fewer,
            Err(e) => return vec![format!("keeping 9 of {planes} symmetry planes: {e}")],
        }
    }
    for entry in METHODS {
        // `ssr` nests its fallback's frame: fuzzed through the cheap `planar` one. Its
        // default, the cube-map probe, is the `cubemap` method (fuzzed itself): drawing it
        // twice more per mutant cost the test 70 s. `cubemap` draws 16² faces, not its
        // default 256²: the same passes and code for any face size (its own tests hold the
        // sizes), and its 256² faces were 40 % of a child's render time for a 12×8 image.
        let method = match entry.name {
            "ssr" => Method::parse("ssr ssr-fallback=planar").expect("a registered fallback"),
            "cubemap" => Method::parse("cubemap cube-size=16").expect("a face size in range"),
            _ => Method::defaults(entry),
        };
        let settings = RenderSettings {
            warmup: 0,
            ..RenderSettings::new(method)
        };
        let rendered = catch_unwind(AssertUnwindSafe(|| {
            mirrorbox_raster::render(gpu, &small, &settings)
        }));
        match rendered {
            Ok(Ok(out)) => {
                assert_eq!(out.image.pixels.len(), 12 * 8);
                tally.rendered += 1;
            }
            Ok(Err(e)) if e.is_refusal() => tally.refused_by_method += 1,
            Ok(Err(e)) => failures.push(format!("render {}: {e}", entry.name)),
            Err(e) => failures.push(format!(
                "render {} panicked: {}",
                entry.name,
                panic_text(&e)
            )),
        }
    }
    failures
}

fn panic_text(e: &Box<dyn std::any::Any + Send>) -> String {
    e.downcast_ref::<String>()
        .cloned()
        .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
        .unwrap_or_else(|| "(no message)".into())
}

/// Loads `text` as if it were the file `path`, catching panics.
fn load(text: &str, path: &Path) -> Result<Result<Scene, String>, String> {
    catch_unwind(AssertUnwindSafe(|| {
        parse_scene(text, path).map_err(|e| e.to_string())
    }))
    .map_err(|e| panic_text(&e))
}

pub(crate) fn env_number(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Mutants per child process of this test: the mutants are split over [`CHILDREN`] children
/// that run at the same time, one per core of the 2-core machines the budgets are set for (a
/// child renders tiny images, which lavapipe draws on one thread). On Mesa 22.3's lavapipe,
/// which kept the memory of every executed pass, 1 000 mutants in one process peaked at
/// 4.8 GB, so they ran in children of 125, one after another; on Mesa 25 all 1 003 in one
/// child peak at 306 MB and take 93 s, where those nine took 108 s (docs/budgets.md).
/// Children, not threads, so that a driver abort is reported with its chunk's output instead
/// of ending the whole test binary.
const CHILDREN: usize = 2;

/// The children's `GALLIVM_PERF` where the user set none: `nopt`, lavapipe's shader compiler
/// without LLVM's optimisation passes. A child draws hundreds of 12×8 frames, so on a fresh
/// machine its time is compiling shaders, about three times as long optimised
/// (docs/budgets.md); what it looks for is decided before the driver's compiler. Mesa keys its
/// disk cache by this setting, so these shaders never stand in for optimised ones.
const CHILD_GALLIVM_PERF: &str = "nopt";

/// The reproducers, then random mutants of every bundled scene, split over
/// [`CHILDREN`] child processes of this test binary running side by side.
#[test]
fn no_scene_that_loads_crashes_the_tracer_or_a_raster_method() {
    let mutants = env_number("MIRRORBOX_FUZZ_MUTANTS", 1000) as usize;
    let total = 3 + mutants;
    let per_child = total.div_ceil(CHILDREN);
    if let Ok(chunk) = std::env::var("MIRRORBOX_FUZZ_CHUNK") {
        return fuzz_chunk(chunk.parse().expect("a chunk index"), per_child);
    }
    // libtest's name of this test: the module path without the crate, then the function.
    let module = module_path!().split_once("::").map_or("", |(_, m)| m);
    let this_test = format!("{module}::no_scene_that_loads_crashes_the_tracer_or_a_raster_method");
    let user_set_gallivm_perf = std::env::var_os("GALLIVM_PERF").is_some();
    let children: Vec<_> = (0..CHILDREN)
        .map(|chunk| {
            let mut child = std::process::Command::new(std::env::current_exe().unwrap());
            if !user_set_gallivm_perf {
                child.env("GALLIVM_PERF", CHILD_GALLIVM_PERF);
            }
            child
                .args(["--exact", &this_test, "--nocapture", "--test-threads", "1"])
                .env("MIRRORBOX_FUZZ_CHUNK", chunk.to_string())
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .expect("start a fuzz chunk")
        })
        .collect();
    let mut tally = Tally::default();
    for (chunk, child) in children.into_iter().enumerate() {
        let out = child.wait_with_output().expect("run a fuzz chunk");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            out.status.success(),
            "chunk {chunk} failed ({}):\n{stderr}\n{}",
            out.status,
            String::from_utf8_lossy(&out.stdout)
        );
        let line = stderr
            .lines()
            .find_map(|l| l.strip_prefix("scene fuzz chunk: "))
            .expect("the chunk's tally");
        let n: Vec<usize> = line.split(' ').map(|x| x.parse().unwrap()).collect();
        tally.tried += n[0];
        tally.refused_by_load += n[1];
        tally.traced += n[2];
        tally.rendered += n[3];
        tally.refused_by_method += n[4];
    }
    eprintln!("scene fuzz: {tally:?}");
    assert_eq!(tally.tried, total);
    // The fuzzer must reach the renderers, not only the validator.
    assert!(
        tally.traced * 4 >= tally.tried && tally.rendered > 0,
        "{tally:?}"
    );
}

/// Mutants `chunk·per_child ..` of the whole sequence (every chunk generates the same
/// sequence from the seed and takes its slice).
fn fuzz_chunk(chunk: usize, per_child: usize) {
    let gpu = Gpu::new().expect("a wgpu adapter (scripts/install-system-deps.sh)");
    let mutants = env_number("MIRRORBOX_FUZZ_MUTANTS", 1000) as usize;
    let mut rng = Rng(env_number("MIRRORBOX_FUZZ_SEED", 12));
    let scenes = bundled();
    let mut tally = Tally::default();
    let mut failures: Vec<String> = Vec::new();

    let mut reproducers: Vec<(PathBuf, Value)> = Vec::new();
    let (box_path, box_scene) = scenes
        .iter()
        .find(|(p, _)| p.ends_with("mirror_box.json"))
        .cloned()
        .expect("mirror_box.json");
    let mut far = box_scene.clone();
    far["objects"][0]["transform"] = json!({ "translate": [3.4e38, 0, 0] });
    reproducers.push((box_path.clone(), far));
    let mut empty = box_scene.clone();
    empty.as_object_mut().unwrap().remove("objects");
    empty.as_object_mut().unwrap().remove("mirrors");
    reproducers.push((box_path.clone(), empty));
    let mut edge = box_scene.clone();
    edge["objects"][0]["transform"] = json!({ "translate": [999999, 0, 0] });
    reproducers.push((box_path.clone(), edge));

    let random = (0..mutants).map(|_| {
        let (path, scene) = rng.pick(&scenes).clone();
        let mutant = mutate(&scene, &mut rng);
        (path, mutant)
    });
    let all: Vec<(PathBuf, Value)> = reproducers.into_iter().chain(random).collect();
    let start = chunk * per_child;
    for (i, (path, mutant)) in all.iter().enumerate().skip(start).take(per_child) {
        tally.tried += 1;
        let text = serde_json::to_string(mutant).unwrap();
        match load(&text, path) {
            Err(panic) => failures.push(format!("load panicked: {panic}\n  mutant: {text}")),
            Ok(Err(_refused)) => tally.refused_by_load += 1,
            Ok(Ok(scene)) => {
                // Every mutant is traced; every third one (and every reproducer) also
                // rendered with every method — every other one until `ssr` and `ray-query`
                // joined the table, and the test budget (≤ 10 min on 2 cores) had no room for
                // their renders on top.
                let render_too = i < 3 || i % 3 == 0;
                for f in exercise(&scene, &gpu, render_too, &mut tally) {
                    failures.push(format!("{f}\n  mutant: {text}"));
                }
            }
        }
    }
    eprintln!(
        "scene fuzz chunk: {} {} {} {} {}",
        tally.tried, tally.refused_by_load, tally.traced, tally.rendered, tally.refused_by_method
    );
    assert!(
        failures.is_empty(),
        "{} of {} mutants failed:\n{}",
        failures.len(),
        tally.tried,
        failures.join("\n")
    );
}
