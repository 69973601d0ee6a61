//! The registry: the table of methods ([`METHODS`], in [`crate::methods`]) looked up by
//! name, and configured methods ([`Method`]) with their stable keys.

use crate::method::{MethodEntry, OptionSpec, ParamError, ParamValue, Params, RasterMethod};
pub use crate::methods::METHODS;
use std::fmt;

impl crate::gpu::Gpu {
    /// Opens the adapter of [`crate::adapter::select_adapter`] with timestamp queries, and
    /// every feature a registered method needs or can use, where the adapter has them.
    pub fn new() -> Result<crate::gpu::Gpu, crate::gpu::RasterError> {
        Self::with_options(Default::default())
    }

    /// As [`Gpu::new`](crate::gpu::Gpu::new), with the backends and colour format `options`
    /// names instead of the environment's.
    pub fn with_options(
        options: crate::gpu::GpuOptions,
    ) -> Result<crate::gpu::Gpu, crate::gpu::RasterError> {
        crate::gpu::Gpu::open(crate::methods::wanted_features(), options)
    }
}

/// The registry entry of `name`.
pub fn find(name: &str) -> Option<&'static MethodEntry> {
    METHODS.iter().copied().find(|e| e.name == name)
}

/// The registered method names, comma separated (for messages).
pub fn names() -> String {
    METHODS
        .iter()
        .map(|e| e.name)
        .collect::<Vec<_>>()
        .join(", ")
}

/// A configured raster method: an entry of [`METHODS`] with a value for each of its options.
#[derive(Clone, Debug, PartialEq)]
pub struct Method {
    params: Params,
}

impl Method {
    /// `entry` with every option at its default.
    pub fn defaults(entry: &'static MethodEntry) -> Method {
        Method {
            params: Params::defaults(entry),
        }
    }

    /// The registered method `name` with every option at its default.
    pub fn named(name: &str) -> Result<Method, ParamError> {
        find(name)
            .map(Method::defaults)
            .ok_or_else(|| ParamError::UnknownMethod {
                name: name.into(),
                known: names(),
            })
    }

    /// Sets `option` (checked against its bounds and against the method's options).
    pub fn with(mut self, option: &OptionSpec, value: ParamValue) -> Result<Method, ParamError> {
        let entry = self.params.entry();
        let Some(i) = entry.options.iter().position(|o| o.name == option.name) else {
            return Err(ParamError::NotAccepted {
                option: option.name.into(),
                methods: methods_accepting(option),
            });
        };
        self.params.set(i, entry.options[i].check(value)?);
        Ok(self)
    }

    /// Sets `option` from its command-line text: refused first if the method does not have
    /// it, then parsed and checked against its bounds.
    pub fn with_text(self, option: &OptionSpec, text: &str) -> Result<Method, ParamError> {
        if !self.entry().accepts(option) {
            return Err(ParamError::NotAccepted {
                option: option.name.into(),
                methods: methods_accepting(option),
            });
        }
        let value = option.parse(text)?;
        self.with(option, value)
    }

    /// Parses a key (`"auxiliary n=2"`, `"portal depth=64"`, `"unrolled depth=8
    /// fragment-clipping=true"`): the inverse of [`Method::key`].
    pub fn parse(key: &str) -> Result<Method, ParamError> {
        let mut words = key.split_whitespace();
        let mut m = Method::named(words.next().unwrap_or(""))?;
        for w in words {
            let (name, value) = w.split_once('=').unwrap_or((w, "true"));
            let option = all_options()
                .into_iter()
                .find(|o| o.name == name)
                .ok_or_else(|| ParamError::NotAccepted {
                    option: name.into(),
                    methods: "(no method has it)".into(),
                })?;
            m = m.with_text(option, value)?;
        }
        Ok(m)
    }

    pub fn entry(&self) -> &'static MethodEntry {
        self.params.entry()
    }

    pub fn name(&self) -> &'static str {
        self.params.entry().name
    }

    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The value of the count option named `name` (`"n"`, `"depth"`), if the method has one.
    pub fn count_of(&self, name: &str) -> Option<u32> {
        let o = self.entry().options.iter().find(|o| o.name == name)?;
        match self.params.get(o) {
            Some(ParamValue::Count(v)) => Some(v),
            _ => None,
        }
    }

    /// The stable identity of the method and its parameters, the part of a sweep's resume
    /// key that names the method: the name, then ` option=value` for the swept option and
    /// for every other option not at its default that changes the point (`in_key`), in the
    /// entry's option order. This format
    /// is frozen — `results.jsonl` files resume by it (test `keys_of_earlier_sweeps`).
    pub fn key(&self) -> String {
        let entry = self.entry();
        let mut key = entry.name.to_string();
        for (o, v) in entry.options.iter().zip(self.params.values()) {
            let swept = entry.swept.is_some_and(|s| s.name == o.name);
            if swept || (o.in_key && *v != o.default) {
                key.push_str(&format!(" {}={v}", o.name));
            }
        }
        key
    }

    /// The options of the key other than the swept one, `name=value` separated by spaces
    /// (empty at the defaults): what makes this a variant of its method in a report, e.g.
    /// `symmetry-draws=per-copy`.
    pub fn variant_options(&self) -> String {
        let entry = self.entry();
        let mut words = Vec::new();
        for (o, v) in entry.options.iter().zip(self.params.values()) {
            let swept = entry.swept.is_some_and(|s| s.name == o.name);
            if !swept && o.in_key && *v != o.default {
                words.push(format!("{}={v}", o.name));
            }
        }
        words.join(" ")
    }

    /// A file-name-safe form of the key: `auxiliary_n2`, `portal_d64` (sweep image names).
    pub fn slug(&self) -> String {
        self.key()
            .replace(" n=", "_n")
            .replace(" depth=", "_d")
            .replace([' ', '='], "_")
    }

    /// The method's typed settings.
    pub fn configure(&self) -> Box<dyn RasterMethod> {
        (self.entry().configure)(&self.params)
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.key())
    }
}

/// Every distinct option of every registered method, in table order.
pub fn all_options() -> Vec<&'static OptionSpec> {
    let mut out: Vec<&'static OptionSpec> = Vec::new();
    for e in METHODS {
        for &o in e.options {
            if !out.iter().any(|p| p.name == o.name) {
                out.push(o);
            }
        }
    }
    out
}

/// The methods that accept `option`, as `a`, `a or b`, `a, b or c`.
pub fn methods_accepting(option: &OptionSpec) -> String {
    let m: Vec<&str> = METHODS
        .iter()
        .filter(|e| e.accepts(option))
        .map(|e| e.name)
        .collect();
    or_list(&m)
}

fn or_list(items: &[&str]) -> String {
    match items {
        [] => String::new(),
        [one] => one.to_string(),
        [init @ .., last] => format!("{} or {last}", init.join(", ")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `mirrorbox advise` takes its candidates from the rows: every variant parses, every
    /// coarse value lies within the knob's bounds, ascending, and the knob is an option of
    /// the method (issue 55).
    #[test]
    fn every_advise_row_names_candidates_the_method_accepts() {
        use crate::method::Advise;
        let mut offered = 0;
        for e in METHODS {
            // Each variant as declared and with the shadow maps a shadowed scene adds.
            let parse = |words: &str| {
                for s in crate::lighting::ADVISE_SHADOW_MAP_SIZES {
                    let lit = format!("{} {words} shadows=map shadow-map-size={s}", e.name);
                    Method::parse(&lit).unwrap_or_else(|err| panic!("{lit:?}: {err}"));
                }
                Method::parse(&format!("{} {words}", e.name))
                    .unwrap_or_else(|err| panic!("{}: variant {words:?}: {err}", e.name))
            };
            match e.advise {
                Advise::Skip => {}
                Advise::Fixed(variants) => {
                    assert!(!variants.is_empty(), "{}", e.name);
                    variants.iter().for_each(|v| drop(parse(v)));
                    offered += 1;
                }
                Advise::Knob {
                    option,
                    coarse,
                    variants,
                } => {
                    assert!(e.accepts(option), "{}: {}", e.name, option.name);
                    assert!(coarse.windows(2).all(|w| w[0] < w[1]), "{}", e.name);
                    for v in variants {
                        for &c in coarse {
                            parse(v)
                                .with(option, ParamValue::Count(c))
                                .unwrap_or_else(|err| {
                                    panic!("{} {v} {}={c}: {err}", e.name, option.name)
                                });
                        }
                    }
                    offered += 1;
                }
            }
        }
        // Every mirror method: all but the three symmetry-plane ones.
        assert_eq!(offered, METHODS.len() - 3);
    }

    #[test]
    fn every_method_takes_the_shared_options() {
        // `method_options!` appends them; an entry that lists its options by hand must too.
        for e in METHODS {
            for shared in [
                &crate::lighting::LIGHTS,
                &crate::lighting::SHADOWS,
                &crate::lighting::SHADOW_MAP_SIZE,
                &crate::lighting::SHADOW_BIAS,
            ] {
                assert!(
                    e.options.iter().any(|o| o.name == shared.name),
                    "{} lacks --{}: build its options with method_options!",
                    e.name,
                    shared.name
                );
            }
        }
    }

    #[test]
    fn names_are_unique_and_options_consistent() {
        for (i, e) in METHODS.iter().enumerate() {
            assert!(
                METHODS[..i].iter().all(|o| o.name != e.name),
                "{} registered twice",
                e.name
            );
            if let Some(s) = e.swept {
                assert!(
                    e.accepts(s),
                    "{}: swept option --{} not declared",
                    e.name,
                    s.name
                );
                assert!(
                    s.sweep.is_some(),
                    "--{} is swept but has no sweep axis",
                    s.name
                );
            }
            for o in e.options {
                o.check(o.default).unwrap_or_else(|err| {
                    panic!(
                        "{}: default of --{} out of its own bounds: {err}",
                        e.name, o.name
                    )
                });
            }
        }
        // Two options with one name must be one option (one meaning, one flag).
        let all = all_options();
        for e in METHODS {
            for o in e.options {
                let first = all.iter().find(|a| a.name == o.name).unwrap();
                assert!(std::ptr::eq(*first, *o), "--{} declared twice", o.name);
            }
        }
    }

    #[test]
    fn every_method_configures_from_its_defaults() {
        // A method reading an option its entry does not declare panics here.
        let scene = mirrorbox_scene::load::bundled_scene("mirror_box.json");
        for e in METHODS {
            let m = Method::defaults(e);
            m.configure()
                .plan(&scene, 32, 18)
                .unwrap_or_else(|err| panic!("{}: {err}", e.name));
        }
    }

    /// Keys written by the sweeps before the registry existed must still name the same
    /// points, or every earlier `results.jsonl` would be re-measured.
    #[test]
    fn keys_of_earlier_sweeps() {
        for key in [
            "naive",
            "auxiliary n=0",
            "auxiliary n=4",
            "portal depth=64",
            "unrolled depth=1024",
        ] {
            let m = Method::parse(key).unwrap();
            assert_eq!(m.key(), key);
            assert_eq!(m.to_string(), key);
        }
        assert_eq!(
            Method::parse("auxiliary n=2").unwrap().slug(),
            "auxiliary_n2"
        );
        assert_eq!(
            Method::parse("portal depth=64").unwrap().slug(),
            "portal_d64"
        );
        assert_eq!(Method::parse("naive").unwrap().slug(), "naive");
        let m = Method::parse("unrolled depth=8 fragment-clipping").unwrap();
        assert_eq!(m.key(), "unrolled depth=8 fragment-clipping=true");
        // A refusal limit changes no point: old sweeps run with --max-passes resume.
        let m = Method::parse("auxiliary n=7 max-passes=20000").unwrap();
        assert_eq!(m.key(), "auxiliary n=7");
    }

    #[test]
    fn options_are_checked_and_refused_where_they_do_not_apply() {
        let aux = Method::named("auxiliary").unwrap();
        let n = aux.entry().swept.unwrap();
        assert_eq!(
            Method::named("naive")
                .unwrap()
                .with(n, ParamValue::Count(2))
                .unwrap_err()
                .to_string(),
            "--n applies to --method auxiliary only"
        );
        let depth = find("portal").unwrap().swept.unwrap();
        assert_eq!(
            aux.clone()
                .with(depth, ParamValue::Count(8))
                .unwrap_err()
                .to_string(),
            "--depth applies to --method path-textures, portal, unrolled or ray-query only"
        );
        let portal = Method::named("portal").unwrap();
        assert_eq!(
            portal
                .with(depth, ParamValue::Count(0))
                .unwrap_err()
                .to_string(),
            "--depth must be in [1, 4096], got 0"
        );
        assert!(Method::named("magic").is_err());
        assert_eq!(
            n.parse_axis("3..1").unwrap_err(),
            "--n \"3..1\": expected a range like 0..4 or a list like 0,2,4 of counts 0..=16"
        );
        assert_eq!(n.parse_axis("0..2").unwrap().len(), 3);
        assert_eq!(
            n.parse_axis("0..=2").unwrap(),
            n.parse_axis("0..2").unwrap()
        );
        assert_eq!(
            depth.parse_axis("0..4").unwrap_err(),
            "--depth \"0..4\": expected a range like 1..8 or a list like 1,4,16,64 of depths 1..=4096"
        );
    }

    #[test]
    fn every_method_takes_the_lights_option() {
        let lights = &crate::lighting::LIGHTS;
        for entry in METHODS {
            assert!(entry.accepts(lights), "{} lacks --lights", entry.name);
            let m = Method::parse(&format!("{} lights=direct", entry.name)).unwrap();
            assert!(m.key().ends_with("lights=direct"), "{}", m.key());
            assert!(!Method::named(entry.name).unwrap().key().contains("lights"));
        }
    }
}
