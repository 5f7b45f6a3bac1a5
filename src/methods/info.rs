//! What the table of methods says of one method and its options (the
//! types `capabilities()` returns): each method's config describes itself
//! with them (`MethodSpec::info`, in the method's own module).

use super::Input;
use crate::backend::Backend;

/// An option's value, for defaults and allowed values.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// Resolved when the config runs (see the option's `default_doc`).
    Resolved,
    Int(i64),
    Bool(bool),
    Str(&'static str),
    Float(f64),
    /// A (W, H) resolution.
    Pair(i64, i64),
}

/// What values an option takes.
#[derive(Debug, Clone, PartialEq)]
pub enum Kind {
    /// An integer in [min, max].
    Int {
        min: i64,
        max: i64,
    },
    /// One of these integers.
    OneOf(Vec<i64>),
    Bool,
    /// One of these names.
    Choice(Vec<&'static str>),
    /// A map resolution: an int (square) or (W, H), each at least 1, at most
    /// `max_texels` texels.
    Resolution {
        max_texels: i64,
    },
    /// An instance of one of these config classes (their own options are
    /// checked by their constructors).
    Config(Vec<&'static str>),
    /// A real number (its limits in the option's doc).
    Float,
}

/// One option of a method's config.
#[derive(Debug, Clone, PartialEq)]
pub struct OptionInfo {
    pub name: &'static str,
    pub kind: Kind,
    pub default: Value,
    /// The default in words (how a `Resolved` default is chosen).
    pub default_doc: &'static str,
    pub doc: &'static str,
    /// Backends that accept only some values of it: (backend, the values).
    pub restricted_on: Vec<(Backend, Vec<Value>)>,
}

/// One method.
#[derive(Debug, Clone, PartialEq)]
pub struct MethodInfo {
    /// The name given as `method=`.
    pub name: &'static str,
    /// The config class (`softshadow.Ssm`, ...).
    pub config: &'static str,
    pub summary: &'static str,
    /// What it reads of the occluders (the receivers are always read).
    pub reads: Vec<Input>,
    /// The backends of this build that run it.
    pub backends: Vec<Backend>,
    pub options: Vec<OptionInfo>,
}
