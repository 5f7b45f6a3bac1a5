//! The keyword form of a config, `Bitmask(samples=64, gaps="open")`: the
//! values a user gives by name, and the trait (`KeywordForm`) a config
//! implements in its own module to be built from them and to read its
//! options back. The bindings make every such config's Python class from
//! this trait and the option table (`MethodSpec::info`): constructor,
//! getters, `repr`, equality, pickling and `to_dict`, with no code of the
//! method's own. (ShadowMapping's options are configs themselves, and
//! `Auto` holds a target, not options: their classes are the bindings'.)

use super::config::MethodSpec;
use super::info::{MethodInfo, Value};
use crate::error::{Error, Result};

/// One value given by keyword, converted by the bindings according to the
/// option's `Kind` (an `Int` or `OneOf` option as `Int`, a `Resolution` as
/// `Resolution`, ...).
#[derive(Debug, Clone, PartialEq)]
pub enum Given {
    Int(i64),
    Bool(bool),
    Str(String),
    Float(f64),
    Resolution((i64, i64)),
}

/// The options given by keyword, in the order given; one given as `None`
/// is left out (it keeps its default).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Keywords(pub Vec<(String, Given)>);

impl Keywords {
    fn get(&self, name: &str) -> Option<&Given> {
        self.0.iter().find(|(n, _)| n == name).map(|(_, g)| g)
    }

    fn wrong(name: &str, what: &str, g: &Given) -> Error {
        Error::invalid(name, format!("must be {what}, got {g:?}"))
    }

    pub fn int(&self, name: &str) -> Result<Option<i64>> {
        match self.get(name) {
            None => Ok(None),
            Some(Given::Int(n)) => Ok(Some(*n)),
            Some(g) => Err(Self::wrong(name, "an integer", g)),
        }
    }

    pub fn bool(&self, name: &str) -> Result<Option<bool>> {
        match self.get(name) {
            None => Ok(None),
            Some(Given::Bool(b)) => Ok(Some(*b)),
            Some(g) => Err(Self::wrong(name, "True or False", g)),
        }
    }

    pub fn str(&self, name: &str) -> Result<Option<&str>> {
        match self.get(name) {
            None => Ok(None),
            Some(Given::Str(s)) => Ok(Some(s)),
            Some(g) => Err(Self::wrong(name, "a name", g)),
        }
    }

    pub fn float(&self, name: &str) -> Result<Option<f64>> {
        match self.get(name) {
            None => Ok(None),
            Some(Given::Float(x)) => Ok(Some(*x)),
            Some(Given::Int(n)) => Ok(Some(*n as f64)),
            Some(g) => Err(Self::wrong(name, "a number", g)),
        }
    }

    pub fn resolution(&self, name: &str) -> Result<Option<(i64, i64)>> {
        match self.get(name) {
            None => Ok(None),
            Some(Given::Resolution(r)) => Ok(Some(*r)),
            Some(g) => Err(Self::wrong(name, "a resolution", g)),
        }
    }

    /// The keywords that give back a config's values (`KeywordForm::keywords`):
    /// `C::from_keywords(&Keywords::of(&c.keywords())) == c`.
    pub fn of(values: &[(&'static str, Value)]) -> Keywords {
        Keywords(
            values
                .iter()
                .filter_map(|(n, v)| {
                    let g = match *v {
                        Value::Resolved => return None,
                        Value::Int(i) => Given::Int(i),
                        Value::Bool(b) => Given::Bool(b),
                        Value::Str(s) => Given::Str(s.to_string()),
                        Value::Float(x) => Given::Float(x),
                        Value::Pair(w, h) => Given::Resolution((w, h)),
                    };
                    Some((n.to_string(), g))
                })
                .collect(),
        )
    }

    /// Each option given must be one of the method's (`info`'s).
    pub fn check_names(&self, info: &MethodInfo) -> Result<()> {
        for (given, _) in &self.0 {
            if !info.options.iter().any(|o| o.name == given) {
                let names: Vec<&str> = info.options.iter().map(|o| o.name).collect();
                return Err(Error::invalid(
                    given,
                    format!(
                        "is not an option of {:?}; its options are {names:?}",
                        info.name
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// A config built from keywords and read back as them; implemented in the
/// method's own module, beside its `MethodSpec`.
pub trait KeywordForm: MethodSpec {
    /// The config of `Class(option=value, ...)`: every value checked by the
    /// config's constructor; an option not given keeps its default.
    fn from_keywords(k: &Keywords) -> Result<Self>;
    /// The config's options, named and in `info()`'s order, as the keyword
    /// form takes them back (`Value::Resolved`: `None`, resolved when the
    /// config runs).
    fn keywords(&self) -> Vec<(&'static str, Value)>;
}

/// An optional count as an option's value.
pub fn count(v: Option<u32>) -> Value {
    v.map_or(Value::Resolved, |n| Value::Int(n.into()))
}

/// An optional flag as an option's value.
pub fn flag(v: Option<bool>) -> Value {
    v.map_or(Value::Resolved, Value::Bool)
}

/// An optional map resolution as an option's value.
pub fn resolution(v: Option<(usize, usize)>) -> Value {
    v.map_or(Value::Resolved, |(w, h)| Value::Pair(w as i64, h as i64))
}
