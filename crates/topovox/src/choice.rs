//! Named choices: every user-facing option with a fixed set of values (a
//! mode, a method, an up axis, a culling setting, on/off) is one enum that
//! implements [`Choice`] — its names, one line of help per value, the list
//! of all values and the parse, defined once with [`choice!`](crate::choice!)
//! where the enum lives. The CLI's flags, the Python package and the job's
//! fingerprints all read those; none keeps a list of its own.
//!
//! Names are matched in any case (`Cover`, `COVER` and `cover` are one
//! mode); the canonical spelling is the one [`Choice::name`] gives.

/// A value chosen by name from a fixed list.
pub trait Choice: Copy + Eq + std::fmt::Debug + Send + Sync + 'static {
    /// What is chosen, for messages (`"mode"`, `"up axis"`).
    const WHAT: &'static str;
    /// Every value, in documentation order.
    const ALL: &'static [Self];

    /// The name users write.
    fn name(self) -> &'static str;

    /// One line of help: what this value does.
    fn help(self) -> &'static str;

    /// The value called `name`, in any case.
    fn parse(name: &str) -> Result<Self, UnknownChoice> {
        Self::ALL.iter().copied().find(|v| v.name().eq_ignore_ascii_case(name.trim())).ok_or_else(|| UnknownChoice {
            what: Self::WHAT,
            given: name.to_string(),
            expected: Self::names().join(", "),
        })
    }

    /// Every name, in documentation order.
    fn names() -> Vec<&'static str> {
        Self::ALL.iter().map(|v| v.name()).collect()
    }
}

/// A name that is none of a choice's values.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown {what} {given:?} (expected one of: {expected})")]
pub struct UnknownChoice {
    /// What was being chosen.
    pub what: &'static str,
    /// The name given.
    pub given: String,
    /// The names allowed, comma-separated.
    pub expected: String,
}

/// Defines a [`Choice`] enum: each variant's doc comment is its help, the
/// string after `=` its name; `default V` makes `V` the `Default`.
///
/// ```
/// topovox::choice! {
///     /// Which way is up.
///     pub enum Side: "side" default Top {
///         /// The top.
///         Top = "top",
///         /// The bottom.
///         Bottom = "bottom",
///     }
/// }
/// use topovox::choice::Choice;
/// assert_eq!(Side::parse("BOTTOM").unwrap(), Side::Bottom);
/// assert_eq!(Side::Top.help(), "The top.");
/// ```
#[macro_export]
macro_rules! choice {
    ($(#[$meta:meta])* $vis:vis enum $name:ident : $what:literal $(default $default:ident)? {
        $($(#[doc = $doc:literal])* $var:ident = $label:literal),+ $(,)?
    }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        $vis enum $name {
            $($(#[doc = $doc])* $var),+
        }

        impl $crate::choice::Choice for $name {
            const WHAT: &'static str = $what;
            const ALL: &'static [Self] = &[$($name::$var),+];

            fn name(self) -> &'static str {
                match self {
                    $($name::$var => $label),+
                }
            }

            fn help(self) -> &'static str {
                match self {
                    $($name::$var => concat!($($doc),*).trim_ascii()),+
                }
            }
        }

        impl ::std::fmt::Display for $name {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str($crate::choice::Choice::name(*self))
            }
        }

        impl ::std::str::FromStr for $name {
            type Err = $crate::choice::UnknownChoice;
            fn from_str(s: &str) -> ::std::result::Result<Self, Self::Err> {
                <$name as $crate::choice::Choice>::parse(s)
            }
        }

        $(impl Default for $name {
            fn default() -> Self {
                $name::$default
            }
        })?
    };
}

choice! {
    /// A feature switched on or off (`--gamma on`).
    pub enum Switch: "switch" {
        /// Switched on.
        On = "on",
        /// Switched off.
        Off = "off",
    }
}

impl Switch {
    /// `true` for `on`.
    pub fn on(self) -> bool {
        self == Switch::On
    }
}

impl From<bool> for Switch {
    fn from(on: bool) -> Switch {
        if on {
            Switch::On
        } else {
            Switch::Off
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_in_any_case_and_unknown_names_list_the_choices() {
        assert_eq!(Switch::parse(" ON ").unwrap(), Switch::On);
        assert_eq!("off".parse::<Switch>().unwrap(), Switch::Off);
        let e = Switch::parse("maybe").unwrap_err();
        assert_eq!(e.to_string(), r#"unknown switch "maybe" (expected one of: on, off)"#);
        assert_eq!(Switch::On.help(), "Switched on.");
        assert_eq!(Switch::On.to_string(), "on");
        assert!(Switch::from(true).on() && !Switch::from(false).on());
    }
}
