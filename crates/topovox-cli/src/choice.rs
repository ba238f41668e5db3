//! Flags that take a named choice parse straight into the choice's own type
//! ([`topovox::choice::Choice`]): one parser for all of them, whose
//! possible values and their help come from the type's list, in any case.

use std::ffi::OsStr;
use std::marker::PhantomData;

use clap::builder::{PossibleValue, TypedValueParser};
use clap::error::{ContextKind, ContextValue, ErrorKind};
use topovox::choice::Choice;

/// The value parser of a [`Choice`] flag.
#[derive(Clone, Copy, Debug, Default)]
pub struct ChoiceParser<T>(PhantomData<T>);

/// `value_parser = choice::<T>()`.
pub fn choice<T: Choice>() -> ChoiceParser<T> {
    ChoiceParser(PhantomData)
}

impl<T: Choice + Clone> TypedValueParser for ChoiceParser<T> {
    type Value = T;

    fn parse_ref(&self, cmd: &clap::Command, arg: Option<&clap::Arg>, value: &OsStr) -> Result<T, clap::Error> {
        let given = value.to_string_lossy();
        T::parse(&given).map_err(|_| {
            let mut e = clap::Error::new(ErrorKind::InvalidValue).with_cmd(cmd);
            let name = arg.map_or_else(|| T::WHAT.to_string(), ToString::to_string);
            e.insert(ContextKind::InvalidArg, ContextValue::String(name));
            e.insert(ContextKind::InvalidValue, ContextValue::String(given.into_owned()));
            e.insert(ContextKind::ValidValue, ContextValue::Strings(T::names().into_iter().map(String::from).collect()));
            e
        })
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(T::ALL.iter().map(|v| PossibleValue::new(v.name()).help(v.help()))))
    }
}
