//! The method configs as Python classes: `Auto` here, `ShadowMapping` in
//! `shadow_configs.rs` (their options are a target and configs), every
//! other method's class made from its keyword form (`keyword_class.rs`);
//! the conversions between them and `MethodConfig`, and the string form.
//! Frozen, keyword-only, compared and hashed by value, picklable (pickle
//! calls the keyword-only constructor again through `__getnewargs_ex__`).
//! The values are checked by the core's constructors (each in its method's module);
//! `None` means "resolved when the config runs".

use super::config_class::newargs;
use super::convert::{opt_bool, opt_float, opt_int, opt_resolution, opt_string, string};
use super::keyword_class::{self, PyKeywordConfig};
use super::shadow_configs::PyShadowMapping;
use crate::methods::config::{check_resolution, LooseOptions};
use crate::methods::target::Target;
use crate::methods::{auto_rule, AutoConfig};
use crate::methods::{MethodConfig, SsmConfig};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

impl From<AutoConfig> for PyAuto {
    // The options given beside `method="auto"` are the string form's; the
    // class holds the target.
    fn from(a: AutoConfig) -> Self {
        PyAuto(a.target)
    }
}

impl From<&PyAuto> for AutoConfig {
    fn from(a: &PyAuto) -> Self {
        AutoConfig {
            given: SsmConfig::default(),
            target: a.0,
        }
    }
}

/// The rule ``method="auto"`` names; it resolves to an ``Ssm`` when run
/// (the result's ``method`` says which). See `capabilities()["auto"]`.
#[pyclass(frozen, eq, hash, module = "softshadow._core", name = "Auto")]
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct PyAuto(pub Target);

#[pymethods]
impl PyAuto {
    #[new]
    #[pyo3(signature = (*, error=None, time=None))]
    fn new(error: Option<&Bound<'_, PyAny>>, time: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        Ok(PyAuto(Target::new(
            opt_float("error", error)?,
            opt_float("time", time)?,
        )?))
    }
    /// The error target (the paper's §4.2.1 metric), or None.
    #[getter]
    fn error(&self) -> Option<f64> {
        self.0.error.map(|r| r.0)
    }
    /// The time budget in seconds, or None.
    #[getter]
    fn time(&self) -> Option<f64> {
        self.0.time.map(|r| r.0)
    }
    /// "auto", the name given as ``method=``.
    #[getter]
    fn name(&self) -> &'static str {
        "auto"
    }
    /// The options as keyword arguments: ``Auto(**a.to_dict()) == a``.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("error", self.error())?;
        d.set_item("time", self.time())?;
        Ok(d)
    }
    /// The ``Ssm`` the rule picks for an output ``resolution`` (an int or
    /// (W, H)) from meshes.
    fn rule(&self, py: Python<'_>, resolution: &Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
        let r = check_resolution(
            "resolution",
            super::convert::resolution("resolution", resolution)?,
        )?;
        to_py(py, &MethodConfig::Ssm(auto_rule(r)))
    }
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        Ok(newargs(py, self.to_dict(py)?))
    }
    // Only the target given (an `Auto` holds one at most).
    fn __repr__(&self) -> String {
        match (self.error(), self.time()) {
            (Some(e), _) => format!("Auto(error={e})"),
            (_, Some(t)) => format!("Auto(time={t})"),
            _ => "Auto()".into(),
        }
    }
}

/// The loose options beside `method=` (the string shorthand).
pub struct Loose<'py> {
    pub passes: Option<Bound<'py, PyAny>>,
    pub samples: Option<Bound<'py, PyAny>>,
    pub occluder_resolution: Option<Bound<'py, PyAny>>,
    pub hierarchy: Option<Bound<'py, PyAny>>,
    pub precision: Option<Bound<'py, PyAny>>,
}

impl Loose<'_> {
    /// No loose options.
    pub fn none() -> Self {
        Loose {
            passes: None,
            samples: None,
            occluder_resolution: None,
            hierarchy: None,
            precision: None,
        }
    }
}

/// `method=` (a config object, or a name with loose options) as a core
/// config. A config object with loose options beside it is refused.
pub fn method_arg(method: &Bound<'_, PyAny>, loose: &Loose<'_>) -> PyResult<MethodConfig> {
    let precision = opt_string("precision", loose.precision.as_ref())?;
    let o = LooseOptions {
        passes: opt_int("passes", loose.passes.as_ref())?,
        samples: opt_int("samples", loose.samples.as_ref())?,
        occluder_resolution: opt_resolution(
            "occluder_resolution",
            loose.occluder_resolution.as_ref(),
        )?,
        hierarchy: opt_bool("hierarchy", loose.hierarchy.as_ref())?,
        precision: precision.as_deref(),
    };
    if let Some(c) = config_of(method) {
        MethodConfig::refuse_loose(&o)?;
        return Ok(c);
    }
    if method.extract::<String>().is_err() {
        return Err(PyTypeError::new_err(format!(
            "method: must be a method name or a config ({}), got {}",
            class_names(),
            method.get_type().name()?
        )));
    }
    Ok(MethodConfig::from_name(&string("method", method)?, &o)?)
}

/// The classes written here, each with the `MethodConfig` variant it
/// holds: one line a class makes its conversion both ways (`config_of`,
/// `to_py`) and its registration in `_core`; the keyword-form classes
/// (`keyword_class.rs`) are converted and registered from the core's table.
macro_rules! hand_written_classes {
    ($($class:ty => $variant:ident,)*) => {
        /// The core config of a config object, if it is one.
        fn config_of(v: &Bound<'_, PyAny>) -> Option<MethodConfig> {
            if let Ok(c) = v.cast::<PyKeywordConfig>() {
                return Some(c.get().0);
            }
            $(if let Ok(c) = v.cast::<$class>() {
                return Some(MethodConfig::$variant(c.get().into()));
            })*
            None
        }

        /// A method config as its Python object.
        pub fn to_py(py: Python<'_>, c: &MethodConfig) -> PyResult<Py<PyAny>> {
            if let Some(o) = keyword_class::to_py(py, c)? {
                return Ok(o);
            }
            Ok(match *c {
                $(MethodConfig::$variant(c) => Py::new(py, <$class>::from(c))?.into_any(),)*
                _ => unreachable!("every config has a keyword form or a class written here"),
            })
        }

        /// Registers every method's config class; their names, in the
        /// table's order.
        pub fn register(m: &Bound<'_, PyModule>) -> PyResult<Vec<String>> {
            keyword_class::register(m)?;
            $(m.add_class::<$class>()?;)*
            Ok(MethodConfig::infos().iter().map(|i| i.config.to_string()).collect())
        }
    };
}

hand_written_classes! {
    PyAuto => Auto,
    PyShadowMapping => ShadowMapping,
}

/// The config classes' Python names, in the table's order.
fn class_names() -> String {
    let names: Vec<&str> = MethodConfig::infos().iter().map(|i| i.config).collect();
    names.join(", ")
}
