//! The options table: each option of a job is one row of an [`crate::option_table!`]
//! declaration — its name, type, default, how a value given by name is
//! checked, an example, what the batch fingerprint records, the CLI's
//! value name and the help — and the declaration generates the struct, its
//! `Default`, its [`Keyword`] list and [`Table::set`] and
//! [`Table::fingerprint`]. The CLI builds its flags from the same rows
//! (`topovox-cli/src/flags.rs`), the Python package checks its signatures
//! against them; so an option is written in its row, the code that uses
//! it and the docs.

pub use serde_json::{Map, Value};
use topovox::choice::{Choice, Switch};
use topovox_io::error::quoted;

use crate::error::{JobError, Result};
use crate::invalid;

/// A value given to an option by name (a Python keyword's value, or a CLI
/// flag's text read by [`Keyword::parse_text`]).
#[derive(Clone, Debug, PartialEq)]
pub enum OptionValue {
    /// `True` / `False`.
    Bool(bool),
    /// An integer.
    Int(i64),
    /// A number.
    Float(f64),
    /// A name, a size (`"8G"`) or a path.
    Text(String),
    /// A sequence of numbers (`origin`, `dims`).
    Numbers(Vec<f64>),
}

/// One option by name: what front ends show and take.
#[derive(Clone, Copy, Debug)]
pub struct Keyword {
    /// The name (Python's keyword; the CLI's flag with `-` for `_`).
    pub name: &'static str,
    /// What it does.
    pub help: &'static str,
    /// A valid value other than the default (the tests set every option
    /// from every front end with it); its kind is how the CLI reads text.
    pub example: Example,
    /// How the CLI takes it.
    pub shape: Shape,
}

/// How the CLI takes an option.
#[derive(Clone, Copy, Debug)]
pub enum Shape {
    /// A flag without a value: on when given.
    Flag,
    /// A value, shown as this name (`N`, `SIZE`, `X,Y,Z`).
    Value(&'static str),
    /// One of a choice's names (shown as this), each with its help.
    Choice(&'static str, fn() -> Vec<(&'static str, &'static str)>),
}

/// [`Shape::Value`].
pub const fn value(name: &'static str) -> Shape {
    Shape::Value(name)
}

/// [`Shape::Choice`] of `T`'s names.
pub const fn choice<T: Choice>(name: &'static str) -> Shape {
    Shape::Choice(name, names_of::<T>)
}

fn names_of<T: Choice>() -> Vec<(&'static str, &'static str)> {
    T::ALL.iter().map(|v| (v.name(), v.help())).collect()
}

impl Shape {
    /// The value's name; `None` for a flag.
    pub fn value_name(self) -> Option<&'static str> {
        match self {
            Shape::Flag => None,
            Shape::Value(n) | Shape::Choice(n, _) => Some(n),
        }
    }
}

/// A [`Keyword`]'s example value.
#[derive(Clone, Copy, Debug)]
pub enum Example {
    /// A boolean.
    Bool(bool),
    /// An integer.
    Int(i64),
    /// A number (or, written `A,B,C`, three).
    Float(f64),
    /// A name or size.
    Text(&'static str),
    /// Numbers.
    Numbers(&'static [f64]),
}

impl Example {
    /// As an [`OptionValue`].
    pub fn value(self) -> OptionValue {
        match self {
            Example::Bool(b) => OptionValue::Bool(b),
            Example::Int(i) => OptionValue::Int(i),
            Example::Float(f) => OptionValue::Float(f),
            Example::Text(t) => OptionValue::Text(t.into()),
            Example::Numbers(n) => OptionValue::Numbers(n.to_vec()),
        }
    }
}

impl Keyword {
    /// The CLI's long name: the name with `-` for `_`.
    pub fn long(&self) -> String {
        self.name.replace('_', "-")
    }

    /// The CLI flag: `--` and [`Keyword::long`].
    pub fn flag(&self) -> String {
        format!("--{}", self.long())
    }

    /// A CLI flag's text as the value its kind takes: integers and numbers
    /// parsed (`A,B,C` is three), `on`/`off` for a switch, text as it is.
    pub fn parse_text(&self, raw: &str) -> Result<OptionValue> {
        let numbers = |raw: &str| -> Result<Vec<f64>> {
            raw.split(',')
                .map(|x| {
                    x.trim().parse::<f64>().map_err(|_| JobError::invalid(format!("{} takes numbers; got {}", self.name, quoted(raw))))
                })
                .collect()
        };
        Ok(match self.example {
            Example::Bool(_) => OptionValue::Bool(Switch::parse(raw).map_err(|e| JobError::invalid(format!("{}: {e}", self.name)))?.on()),
            Example::Int(_) => match raw.trim().parse::<i64>() {
                Ok(i) => OptionValue::Int(i),
                Err(_) => invalid!("{} must be an integer; got {}", self.name, quoted(raw)),
            },
            Example::Float(_) if raw.contains(',') => OptionValue::Numbers(numbers(raw)?),
            Example::Float(_) => match raw.trim().parse::<f64>() {
                Ok(f) => OptionValue::Float(f),
                // Text the option reads itself (`band all`).
                Err(_) => OptionValue::Text(raw.into()),
            },
            Example::Numbers(ex) => match numbers(raw)? {
                n if n.len() == ex.len() => OptionValue::Numbers(n),
                n => invalid!(
                    "{} takes {} comma-separated values ({}); got {}",
                    self.name,
                    ["no", "one", "two", "three", "four", "five", "six"].get(ex.len()).copied().unwrap_or("more"),
                    self.shape.value_name().unwrap_or_default(),
                    n.len()
                ),
            },
            Example::Text(_) => OptionValue::Text(raw.into()),
        })
    }
}

/// A group of options declared by [`crate::option_table!`].
pub trait Table: Default + Clone + std::fmt::Debug + PartialEq + Send + Sync + 'static {
    /// Every option, in documentation order: the table's own rows, then
    /// each group's.
    const KEYWORDS: &'static [&'static [Keyword]];

    /// Sets the option called `key` from a value given by name, checking
    /// its type and range; `Ok(false)`: the table has no such option.
    fn set(&mut self, key: &str, v: &OptionValue) -> Result<bool>;

    /// Adds what a batch's manifest records of these options to `out`.
    fn fingerprint(&self, out: &mut Map<String, Value>);

    /// Every option, one by one.
    fn keywords() -> impl Iterator<Item = &'static Keyword> {
        Self::KEYWORDS.iter().flat_map(|rows| rows.iter())
    }

    /// [`Table::set`], taking other spellings ([`ALIASES`]) and refusing
    /// an unknown name with the list of known ones.
    fn set_named(&mut self, key: &str, v: &OptionValue) -> Result<()> {
        let key = ALIASES.iter().find(|a| a.0 == key).map_or(key, |a| a.1);
        if !self.set(key, v)? {
            invalid!("unknown option {key:?} (expected one of: {})", Self::keywords().map(|k| k.name).collect::<Vec<_>>().join(", "));
        }
        Ok(())
    }
}

/// Other spellings of option names (the ecosystem's American ones).
pub const ALIASES: &[(&str, &str)] = &[("color_rule", "colour_rule")];

/// Declares a table of options: a struct whose groups (other tables,
/// `[group name: Type, "doc"]`) come first, then one row per option:
///
/// ```text
/// name: Type = default, parse FN, example EXAMPLE, print FN, cli SHAPE, "help";
/// ```
///
/// `parse` is a `fn(&str, &OptionValue) -> Result<Type>` (the name for
/// messages, the value); `print` a `fn(&Self) -> Option<Value>`, what the
/// fingerprint records under the option's name (`None`: nothing).
#[macro_export]
macro_rules! option_table {
    (
        $(#[$meta:meta])*
        pub struct $name:ident {
            $([group $gfield:ident: $gty:ty, $gdoc:literal])*
            $(
                $field:ident: $ty:ty = $default:expr,
                parse $parse:expr,
                example $example:expr,
                print $print:expr,
                cli $shape:expr,
                $help:literal;
            )*
        }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Debug, PartialEq)]
        pub struct $name {
            $(#[doc = $gdoc] pub $gfield: $gty,)*
            $(#[doc = $help] pub $field: $ty,)*
        }

        impl Default for $name {
            fn default() -> $name {
                $name { $($gfield: <$gty>::default(),)* $($field: $default,)* }
            }
        }

        impl $name {
            /// This table's own rows.
            pub const OWN: &'static [$crate::table::Keyword] = &[$(
                $crate::table::Keyword { name: stringify!($field), help: $help, example: $example, shape: $shape },
            )*];
        }

        impl $crate::table::Table for $name {
            const KEYWORDS: &'static [&'static [$crate::table::Keyword]] = &[$name::OWN $(, <$gty>::OWN)*];

            fn set(&mut self, key: &str, v: &$crate::table::OptionValue) -> $crate::Result<bool> {
                $(if $crate::table::Table::set(&mut self.$gfield, key, v)? {
                    return Ok(true);
                })*
                Ok(match key {
                    $(stringify!($field) => {
                        let parse: fn(&str, &$crate::table::OptionValue) -> $crate::Result<$ty> = $parse;
                        self.$field = parse(key, v)?;
                        true
                    })*
                    _ => false,
                })
            }

            fn fingerprint(&self, out: &mut $crate::table::Map<String, $crate::table::Value>) {
                $($crate::table::Table::fingerprint(&self.$gfield, out);)*
                $(
                    let print: fn(&$name) -> Option<$crate::table::Value> = $print;
                    if let Some(v) = print(self) {
                        out.insert(stringify!($field).into(), v);
                    }
                )*
            }
        }
    };
}

// The row checkers: each takes the option's name (for messages) and value.

/// `True` or `False`.
pub fn flag(key: &str, v: &OptionValue) -> Result<bool> {
    match v {
        OptionValue::Bool(b) => Ok(*b),
        v => invalid!("{key} must be True or False; got {}", shown(v)),
    }
}

/// A string.
pub fn text<'a>(key: &str, v: &'a OptionValue) -> Result<&'a str> {
    match v {
        OptionValue::Text(t) => Ok(t),
        v => invalid!("{key} must be a string; got {}", shown(v)),
    }
}

/// An integer of at least `least`.
pub fn int(key: &str, v: &OptionValue, least: i64) -> Result<u64> {
    match v {
        OptionValue::Int(i) if *i >= least => Ok(*i as u64),
        OptionValue::Int(i) => invalid!("{key} must be at least {least}; got {i}"),
        v => invalid!("{key} must be an integer; got {}", shown(v)),
    }
}

/// A number.
pub fn number(key: &str, v: &OptionValue) -> Result<f64> {
    match v {
        OptionValue::Float(f) => Ok(*f),
        OptionValue::Int(i) => Ok(*i as f64),
        v => invalid!("{key} must be a number; got {}", shown(v)),
    }
}

/// Three numbers.
pub fn numbers(key: &str, v: &OptionValue) -> Result<Vec<f64>> {
    match v {
        OptionValue::Numbers(n) if n.len() == 3 => Ok(n.clone()),
        OptionValue::Numbers(n) => invalid!("{key} must have 3 values; got {}", n.len()),
        v => invalid!("{key} must be a sequence of 3 numbers; got {}", shown(v)),
    }
}

/// One number or several.
pub fn number_list(key: &str, v: &OptionValue) -> Result<Vec<f64>> {
    match v {
        OptionValue::Numbers(n) => Ok(n.clone()),
        OptionValue::Float(_) | OptionValue::Int(_) => Ok(vec![number(key, v)?]),
        v => invalid!("{key} must be a number or a sequence of numbers; got {}", shown(v)),
    }
}

/// A choice given by name (or, for `hollow`, by number).
pub fn chosen<T: Choice>(key: &str, v: &OptionValue) -> Result<T> {
    let name = match v {
        OptionValue::Int(i) => i.to_string(),
        v => text(key, v)?.to_string(),
    };
    T::parse(&name).map_err(|e| JobError::invalid(format!("{key}: {e}")))
}

/// A value as the user would have written it, for messages.
pub fn shown(v: &OptionValue) -> String {
    match v {
        OptionValue::Bool(b) => if *b { "True" } else { "False" }.into(),
        OptionValue::Int(i) => i.to_string(),
        OptionValue::Float(f) => f.to_string(),
        OptionValue::Text(t) => quoted(t),
        OptionValue::Numbers(n) => format!("{n:?}"),
    }
}
