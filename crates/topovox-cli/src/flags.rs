//! A table of options (`topovox_job::table`) as clap flags: one flag per
//! row, named, described and read as the row says, so the CLI never
//! repeats an option the job declares. `#[command(flatten)]` a
//! `Flags<GridOptions>`, `Flags<JobOptions>`, … into a command's arguments.

use std::ffi::OsStr;

use clap::builder::{PossibleValue, TypedValueParser, ValueParser};
use clap::error::{ContextKind, ContextValue, ErrorKind};
use clap::{Arg, ArgAction, ArgMatches, Args, Command, FromArgMatches};
use topovox_job::table::{Example, Keyword, Shape, ALIASES};
use topovox_job::{OptionValue, Table};

/// The options of table `T`, read from its flags, and which were given.
#[derive(Clone, Debug, Default)]
pub struct Flags<T: Table> {
    /// The options.
    pub options: T,
    /// The names of the options given on the command line.
    pub given: Vec<&'static str>,
}

impl<T: Table> std::ops::Deref for Flags<T> {
    type Target = T;
    fn deref(&self) -> &T {
        &self.options
    }
}

/// A choice's names as clap's possible values (listed in `--help`,
/// checked in any case, a bad one refused with the list).
#[derive(Clone)]
struct Names(Vec<(&'static str, &'static str)>);

impl TypedValueParser for Names {
    type Value = String;

    fn parse_ref(&self, cmd: &Command, arg: Option<&Arg>, value: &OsStr) -> Result<String, clap::Error> {
        let given = value.to_string_lossy();
        let names = &self.0;
        if names.iter().any(|(n, _)| n.eq_ignore_ascii_case(given.trim())) {
            return Ok(given.into_owned());
        }
        let mut e = clap::Error::new(ErrorKind::InvalidValue).with_cmd(cmd);
        e.insert(ContextKind::InvalidArg, ContextValue::String(arg.map_or_else(String::new, ToString::to_string)));
        e.insert(ContextKind::InvalidValue, ContextValue::String(given.into_owned()));
        e.insert(ContextKind::ValidValue, ContextValue::Strings(names.iter().map(|n| n.0.to_string()).collect()));
        Err(e)
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(self.0.iter().map(|&(n, h)| PossibleValue::new(n).help(h))))
    }
}

/// The clap argument of one row.
fn arg(k: &'static Keyword) -> Arg {
    let mut a = Arg::new(k.name).long(k.long()).help(k.help);
    for (alias, name) in ALIASES {
        if *name == k.name {
            a = a.visible_alias(alias.replace('_', "-"));
        }
    }
    match k.shape {
        Shape::Flag => a.action(ArgAction::SetTrue),
        Shape::Choice(name, names) => a.value_name(name).action(ArgAction::Set).value_parser(Names(names())),
        Shape::Value(name) => {
            // Numbers may be negative (`--origin -1,-1,-1`).
            let numeric = matches!(k.example, Example::Float(_) | Example::Numbers(_));
            a.value_name(name).action(ArgAction::Set).value_parser(ValueParser::string()).allow_hyphen_values(numeric)
        }
    }
}

impl<T: Table> Args for Flags<T> {
    fn augment_args(cmd: Command) -> Command {
        T::keywords().fold(cmd, |c, k| c.arg(arg(k)))
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

impl<T: Table> FromArgMatches for Flags<T> {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        let mut flags = Flags { options: T::default(), given: Vec::new() };
        flags.update_from_arg_matches(m)?;
        Ok(flags)
    }

    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        for k in T::keywords() {
            let (value, raw) = if k.shape.value_name().is_none() {
                (m.get_flag(k.name).then_some(OptionValue::Bool(true)), "")
            } else {
                match m.get_one::<String>(k.name) {
                    Some(raw) => (Some(k.parse_text(raw).map_err(|e| refused(k, raw, e))?), raw.as_str()),
                    None => (None, ""),
                }
            };
            if let Some(v) = value {
                self.options.set_named(k.name, &v).map_err(|e| refused(k, raw, e))?;
                self.given.push(k.name);
            }
        }
        Ok(())
    }
}

/// clap's one-line error for a bad value (exit status 2, as clap's own).
fn refused(k: &Keyword, raw: &str, e: topovox_job::JobError) -> clap::Error {
    clap::Error::raw(ErrorKind::ValueValidation, format!("{}\n", refusal(k, raw, e)))
}

/// The line refusing a bad value.
fn refusal(k: &Keyword, raw: &str, e: topovox_job::JobError) -> String {
    let shown: String = raw.chars().take(40).collect();
    format!("invalid value '{shown}' for '{}': {e}", k.flag())
}

/// The tables of the works one command chooses between (`batch --run`).
pub trait Runs {
    /// One per run, in the order `--help` lists them.
    fn tables() -> Vec<RunTable>;
}

/// A run's name as the choice names it, and its table.
pub struct RunTable {
    /// The run.
    pub run: &'static str,
    /// Its table's options.
    pub keywords: Vec<&'static Keyword>,
    /// Sets one option on the table's defaults, as [`Table::set_named`]
    /// does (so a bad value is refused while the flags are read).
    pub try_set: fn(&str, &OptionValue) -> topovox_job::Result<()>,
}

impl RunTable {
    /// Run `run`, reading table `T`.
    pub fn of<T: Table>(run: &'static str) -> RunTable {
        RunTable { run, keywords: T::keywords().collect(), try_set: |name, v| T::default().set_named(name, v) }
    }
}

/// One row of a merged flag: a run that takes the option, and how.
struct Row {
    run: &'static str,
    keyword: &'static Keyword,
    try_set: fn(&str, &OptionValue) -> topovox_job::Result<()>,
}

/// The options of several tables under one set of flags, read later by the
/// table of the work chosen: a name two tables share is one flag (with
/// both meanings in its help, and both choices' names where they differ),
/// and each table reads its text its own way.
#[derive(Clone, Debug)]
pub struct RunFlags<R: Runs> {
    /// The options given, by name, as text (`on` for a flag).
    pub given: Vec<(&'static str, String)>,
    runs: std::marker::PhantomData<R>,
}

/// Each option name once, in order, with a row for every run having it.
fn merged<R: Runs>() -> Vec<(&'static str, Vec<Row>)> {
    let mut out: Vec<(&'static str, Vec<Row>)> = Vec::new();
    for t in R::tables() {
        for keyword in t.keywords {
            let row = Row { run: t.run, keyword, try_set: t.try_set };
            match out.iter_mut().find(|(n, _)| *n == keyword.name) {
                Some((_, rows)) => rows.push(row),
                None => out.push((keyword.name, vec![row])),
            }
        }
    }
    out
}

/// One flag for rows of one name: the row's own where all agree.
fn merged_arg(rows: &[Row]) -> Arg {
    let first = rows[0].keyword;
    if rows.iter().all(|r| r.keyword.help == first.help) {
        return arg(first);
    }
    let help: Vec<String> = rows.iter().map(|r| format!("--run {}: {}", r.run, r.keyword.help)).collect();
    let mut a = Arg::new(first.name).long(first.long()).help(help.join("; "));
    let mut names = Vec::new();
    for r in rows {
        match r.keyword.shape {
            Shape::Choice(_, of) => names.extend(of().into_iter().filter(|n| !names.contains(n)).collect::<Vec<_>>()),
            _ => return a.value_name("VALUE").action(ArgAction::Set).value_parser(ValueParser::string()),
        }
    }
    a = a.value_name(first.shape.value_name().unwrap_or("VALUE")).action(ArgAction::Set);
    a.value_parser(Names(names))
}

impl<R: Runs> Args for RunFlags<R> {
    fn augment_args(cmd: Command) -> Command {
        merged::<R>().iter().fold(cmd, |c, (_, rows)| c.arg(merged_arg(rows)))
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

impl<R: Runs> FromArgMatches for RunFlags<R> {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        let mut flags = RunFlags { given: Vec::new(), runs: std::marker::PhantomData };
        flags.update_from_arg_matches(m)?;
        Ok(flags)
    }

    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        for (name, rows) in merged::<R>() {
            let raw = if rows[0].keyword.shape.value_name().is_none() {
                m.get_flag(name).then(|| "on".to_string())
            } else {
                m.get_one::<String>(name).cloned()
            };
            let Some(raw) = raw else { continue };
            // A value no run takes is refused now (the first run's
            // refusal), as Flags refuses it.
            let mut tries = rows
                .iter()
                .map(|r| r.keyword.parse_text(&raw).and_then(|v| (r.try_set)(name, &v)).map_err(|e| refused(r.keyword, &raw, e)));
            if let Some(Err(e)) = tries.next() {
                if !tries.any(|t| t.is_ok()) {
                    return Err(e);
                }
            }
            self.given.push((name, raw));
        }
        Ok(())
    }
}

impl<R: Runs> RunFlags<R> {
    /// The options of `run`'s table `T`; an option of another run's only
    /// is refused, naming the runs that take it.
    pub fn table<T: Table>(&self, run: &str) -> anyhow::Result<T> {
        let mut out = T::default();
        for (name, raw) in &self.given {
            let Some(k) = T::keywords().find(|k| k.name == *name) else {
                let runs: Vec<String> = R::tables()
                    .into_iter()
                    .filter(|t| t.keywords.iter().any(|k| k.name == *name))
                    .map(|t| format!("--run {}", t.run))
                    .collect();
                anyhow::bail!("--{} applies to {}, not --run {run}", name.replace('_', "-"), runs.join(" or "));
            };
            let value = k.parse_text(raw).map_err(|e| anyhow::anyhow!(refusal(k, raw, e)))?;
            out.set_named(k.name, &value).map_err(|e| anyhow::anyhow!(refusal(k, raw, e)))?;
        }
        Ok(out)
    }
}
