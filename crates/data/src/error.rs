//! The one error type of this crate.

use thiserror::Error;
use volray_core::VolumeError;

/// Why a source spec could not be parsed or its volume generated.
///
/// Every message is one line that starts with the spec it is about, e.g.
/// `marschner-lobb:1: grid must have at least 2 points per side, got 1`.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum DataError {
    /// The spec is empty or only whitespace.
    #[error("empty source spec")]
    EmptySpec,
    /// Nothing before the `:`.
    #[error("{spec}: empty source name before `:`")]
    EmptyName { spec: String },
    /// An argument between commas is empty (`a:1,,2`, `a:1,`, `a:`).
    #[error("{spec}: argument {position} is empty")]
    EmptyArg {
        spec: String,
        /// 1-based position among the arguments.
        position: usize,
    },
    /// `=value` without a key.
    #[error("{spec}: argument `{arg}` has an empty key")]
    EmptyKey { spec: String, arg: String },
    /// `key=` without a value.
    #[error("{spec}: argument `{arg}` has an empty value")]
    EmptyValue { spec: String, arg: String },
    /// A bare value after a `key=value` argument.
    #[error(
        "{spec}: positional argument `{arg}` comes after a named one; put positional arguments first"
    )]
    PositionalAfterNamed { spec: String, arg: String },
    /// The same `key=` twice.
    #[error("{spec}: `{key}` is given more than once")]
    DuplicateKey { spec: String, key: String },
    /// A parameter given both by position and as `key=value`.
    #[error("{spec}: `{key}` is given both by position and by name")]
    GivenTwice { spec: String, key: String },
    /// The name is not a registered source.
    #[error("{spec}: unknown source `{name}`; known sources: {known}")]
    UnknownSource {
        spec: String,
        name: String,
        /// The registered names, comma separated.
        known: String,
    },
    /// A `key=value` whose key the source does not take.
    #[error("{spec}: unknown parameter `{key}`; {source_name} takes {allowed}")]
    UnknownKey {
        spec: String,
        source_name: String,
        key: String,
        /// The keys the source takes, comma separated.
        allowed: String,
    },
    /// More positional arguments than the source takes.
    #[error(
        "{spec}: surplus positional argument `{value}`; {source_name} takes at most {max} ({keys})"
    )]
    SurplusPositional {
        spec: String,
        source_name: String,
        value: String,
        max: usize,
        /// The positional parameters, comma separated.
        keys: String,
    },
    /// A value that does not parse as the parameter's type.
    #[error("{spec}: {key} must be {expected}, got `{value}`")]
    BadValue {
        spec: String,
        key: String,
        value: String,
        /// What was expected, e.g. "a non-negative integer".
        expected: &'static str,
    },
    /// A parameter out of its range, or an inconsistent combination.
    #[error("{spec}: {message}")]
    Invalid { spec: String, message: String },
    /// The grid could not be made into a volume (should not happen for
    /// validated parameters).
    #[error("{spec}: {error}")]
    Volume { spec: String, error: VolumeError },
}

impl DataError {
    /// Turns a source's parameter check message into an [`DataError::Invalid`]
    /// naming `spec`: `check().map_err(DataError::invalid(spec))?`.
    pub fn invalid(spec: impl std::fmt::Display) -> impl FnOnce(String) -> DataError {
        move |message| DataError::Invalid {
            spec: spec.to_string(),
            message,
        }
    }
}
