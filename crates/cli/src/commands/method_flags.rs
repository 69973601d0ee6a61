//! The raster methods' options as command-line flags, made from the registry
//! (`mirrorbox_raster::METHODS`): every option any method declares becomes one flag of
//! `render` (`--NAME VALUE`, a switch `--NAME`), and of `sweep`, where a method's swept option
//! (`--n`, `--depth`) takes a range or list instead. A flag given for a method that does not
//! declare it is an error naming the methods that do.

use crate::Failure;
use clap::{Arg, ArgAction, ArgMatches, Command};
use mirrorbox_raster::method::OptionKind;
use mirrorbox_raster::registry::{all_options, methods_accepting};
use mirrorbox_raster::{METHODS, Method, MethodEntry, OptionSpec, ParamValue};

/// Whether an option is a sweep axis (some method sweeps it).
fn is_axis(option: &OptionSpec) -> bool {
    METHODS
        .iter()
        .any(|e| e.swept.is_some_and(|s| s.name == option.name))
}

fn arg(option: &'static OptionSpec, sweep: bool) -> Arg {
    let methods = methods_accepting(option);
    let arg = Arg::new(option.name).long(option.name);
    if matches!(option.kind, OptionKind::Switch) {
        return arg
            .action(ArgAction::SetTrue)
            .help(format!("{} [{methods}]", option.help));
    }
    let (value_name, default) = match (&option.sweep, sweep) {
        (Some(axis), true) => ("LIST", axis.default.to_string()),
        _ => ("VALUE", option.default.to_string()),
    };
    // A sweep takes a list only for the methods that sweep the option; the others that
    // accept it take one value (`--history 0,4` is refused for cubemap).
    let methods = match (&option.sweep, sweep) {
        (Some(_), true) => {
            let by = |sweeps: bool| {
                METHODS
                    .iter()
                    .filter(|e| {
                        e.accepts(option)
                            && e.swept.is_some_and(|s| s.name == option.name) == sweeps
                    })
                    .map(|e| e.name)
                    .collect::<Vec<_>>()
            };
            match (by(true), by(false)) {
                (list, one) if one.is_empty() => list.join(" or "),
                (list, one) => format!(
                    "a list for {}, one value for {}",
                    list.join(" or "),
                    one.join(" or ")
                ),
            }
        }
        _ => methods,
    };
    arg.action(ArgAction::Set)
        .value_name(value_name)
        .help(format!(
            "{} [{methods}; {}; default {default}]",
            option.help,
            option.allowed()
        ))
}

/// The `--method` values with their one-line help.
pub fn method_value_parser() -> clap::builder::PossibleValuesParser {
    clap::builder::PossibleValuesParser::new(
        METHODS
            .iter()
            .map(|e| clap::builder::PossibleValue::new(e.name).help(e.help)),
    )
}

/// The options given on the command line, unchecked.
#[derive(Clone, Debug, Default)]
pub struct GivenOptions(Vec<(&'static OptionSpec, String)>);

impl GivenOptions {
    fn from_matches(m: &ArgMatches) -> Self {
        let mut given = Vec::new();
        for o in all_options() {
            if matches!(o.kind, OptionKind::Switch) {
                if m.get_flag(o.name) {
                    given.push((o, "true".to_string()));
                }
            } else if let Some(v) = m.get_one::<String>(o.name) {
                given.push((o, v.clone()));
            }
        }
        GivenOptions(given)
    }

    /// `entry` configured with the given options (exit 2 on one it does not accept or out
    /// of bounds).
    pub fn configure(&self, entry: &'static MethodEntry) -> Result<Method, Failure> {
        let mut m = Method::defaults(entry);
        for (o, text) in &self.0 {
            m = m.with_text(o, text)?;
        }
        Ok(m)
    }
}

/// `render`'s method flags: every option once.
#[derive(Clone, Debug, Default)]
pub struct RenderOptions(pub GivenOptions);

impl clap::FromArgMatches for RenderOptions {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        Ok(RenderOptions(GivenOptions::from_matches(m)))
    }
    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

impl clap::Args for RenderOptions {
    fn augment_args(cmd: Command) -> Command {
        all_options()
            .into_iter()
            .fold(cmd, |c, o| c.arg(arg(o, false)))
    }
    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

/// `sweep`'s method flags: swept options as axes (a range or list, with the axis default),
/// the others as one value each for every method that has them.
#[derive(Clone, Debug, Default)]
pub struct SweepOptions {
    /// Every option given on the command line, axes included, as given.
    pub given: GivenOptions,
}

impl SweepOptions {
    /// A message when an option was given that none of `entries` has.
    pub fn unused_by(&self, entries: &[&'static MethodEntry]) -> Option<String> {
        self.given.0.iter().find_map(|(o, _)| {
            (!entries.iter().any(|e| e.accepts(o))).then(|| {
                // Named as the sweep names its methods (`--methods`), not as `render` does.
                format!(
                    "--{} applies to --methods {} only (none of the methods swept)",
                    o.name,
                    methods_accepting(o)
                )
            })
        })
    }

    fn given_text(&self, option: &OptionSpec) -> Option<&str> {
        self.given
            .0
            .iter()
            .find(|(o, _)| o.name == option.name)
            .map(|(_, t)| t.as_str())
    }

    /// The points of one method: its defaults with the given options it has applied, once
    /// per value of its swept option's axis (given, or the axis default). An axis flag that
    /// the method has but does not sweep must hold one value.
    pub fn methods_of(&self, entry: &'static MethodEntry) -> Result<Vec<Method>, Failure> {
        let mut base = Method::defaults(entry);
        let swept_name = entry.swept.map(|s| s.name);
        for (o, text) in &self.given.0 {
            if !entry.accepts(o) || Some(o.name) == swept_name {
                continue;
            }
            if is_axis(o) {
                let values = o.parse_axis(text).map_err(Failure::BadInput)?;
                let [value] = values[..] else {
                    return Err(Failure::BadInput(format!(
                        "--{} {text:?}: --method {} does not sweep it; give one value",
                        o.name, entry.name
                    )));
                };
                base = base.with(o, value)?;
            } else {
                base = base.with_text(o, text)?;
            }
        }
        let Some(swept) = entry.swept else {
            return Ok(vec![base]);
        };
        let default = swept.sweep.as_ref().map_or("", |a| a.default);
        let text = self.given_text(swept).unwrap_or(default);
        swept
            .parse_axis(text)
            .map_err(Failure::BadInput)?
            .into_iter()
            .map(|v: ParamValue| Ok(base.clone().with(swept, v)?))
            .collect()
    }
}

impl clap::FromArgMatches for SweepOptions {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        Ok(SweepOptions {
            given: GivenOptions::from_matches(m),
        })
    }
    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

impl clap::Args for SweepOptions {
    fn augment_args(cmd: Command) -> Command {
        all_options()
            .into_iter()
            .fold(cmd, |c, o| c.arg(arg(o, is_axis(o))))
    }
    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}
