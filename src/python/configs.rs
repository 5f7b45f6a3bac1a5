//! The method configs as Python classes: `Ssm`, `Bitmask`, `Exact`, `Auto`
//! here, and the list of every method's class (`method_classes!`: the
//! conversions to and from `MethodConfig`, the registration), the string
//! form.
//! Frozen, keyword-only, compared and hashed by value, picklable (pickle
//! calls the keyword-only constructor again through `__getnewargs_ex__`).
//! The values are checked by the core's constructors (each in its method's module);
//! `None` means "resolved when the config runs".

use super::config_class::{config_class, newargs};
use super::convert::{opt_bool, opt_float, opt_int, opt_resolution, opt_string, string};
use super::shadow_configs::{PyPcss, PyShadowMapping, PySmoothies};
use crate::methods::config::{check_resolution, LooseOptions};
use crate::methods::target::Target;
use crate::methods::{auto_rule, AutoConfig};
use crate::methods::{BitmaskConfig, ExactConfig, MethodConfig, SsmConfig};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

config_class! {
    /// Soft shadow maps as published (Atty et al. 2005). See `capabilities()["ssm"]`.
    class PySsm(SsmConfig) as "Ssm", name "ssm";
    #[pyo3(signature = (*, passes=None, occluder_resolution=None, hierarchy=None, precision=None))]
    fn new(
        passes: Option<&Bound<'_, PyAny>>,
        occluder_resolution: Option<&Bound<'_, PyAny>>,
        hierarchy: Option<&Bound<'_, PyAny>>,
        precision: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let precision = opt_string("precision", precision)?;
        Ok(PySsm(SsmConfig::new(
            opt_int("passes", passes)?,
            opt_resolution("occluder_resolution", occluder_resolution)?,
            opt_bool("hierarchy", hierarchy)?,
            precision.as_deref(),
        )?))
    }
    options {
        passes: Option<u32> = |c, py| c.0.passes;
        occluder_resolution: Option<(usize, usize)> = |c, py| c.0.occluder_resolution;
        hierarchy: Option<bool> = |c, py| c.0.hierarchy;
        precision: &'static str = |c, py| c.0.precision.name();
    }
}

config_class! {
    /// Micro-patches marking light samples in a bit mask per receiver. See
    /// `capabilities()["bitmask"]`.
    class PyBitmask(BitmaskConfig) as "Bitmask", name "bitmask";
    #[pyo3(signature = (*, samples=None, passes=None, occluder_resolution=None, hierarchy=None, gaps=None))]
    fn new(
        samples: Option<&Bound<'_, PyAny>>,
        passes: Option<&Bound<'_, PyAny>>,
        occluder_resolution: Option<&Bound<'_, PyAny>>,
        hierarchy: Option<&Bound<'_, PyAny>>,
        gaps: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let gaps = opt_string("gaps", gaps)?;
        Ok(PyBitmask(BitmaskConfig::new(
            opt_int("samples", samples)?,
            opt_int("passes", passes)?,
            opt_resolution("occluder_resolution", occluder_resolution)?,
            opt_bool("hierarchy", hierarchy)?,
            gaps.as_deref(),
        )?))
    }
    options {
        samples: u32 = |c, py| c.0.samples;
        passes: Option<u32> = |c, py| c.0.passes;
        occluder_resolution: Option<(usize, usize)> = |c, py| c.0.occluder_resolution;
        hierarchy: Option<bool> = |c, py| c.0.hierarchy;
        gaps: &'static str = |c, py| c.0.gaps.name();
    }
}

config_class! {
    /// Ray casting against the occluder triangles. See `capabilities()["exact"]`.
    class PyExact(ExactConfig) as "Exact", name "exact";
    #[pyo3(signature = (*, samples=None, probe=None))]
    fn new(
        samples: Option<&Bound<'_, PyAny>>,
        probe: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        Ok(PyExact(ExactConfig::new(
            opt_int("samples", samples)?,
            opt_int("probe", probe)?,
        )?))
    }
    options {
        samples: u32 = |c, py| c.0.samples;
        probe: Option<u32> = |c, py| c.0.probe;
    }
}

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
    fn rule(&self, resolution: &Bound<'_, PyAny>) -> PyResult<PySsm> {
        let r = check_resolution(
            "resolution",
            super::convert::resolution("resolution", resolution)?,
        )?;
        Ok(PySsm(auto_rule(r)))
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
            class_names(method.py())?,
            method.get_type().name()?
        )));
    }
    Ok(MethodConfig::from_name(&string("method", method)?, &o)?)
}

/// The method config classes, each with the `MethodConfig` variant it
/// holds: one line a class makes its conversion both ways (`config_of`,
/// `to_py`), its registration in `_core` and its name in `method=`'s
/// TypeError. A class converts through `From` (made by `config_class!` for
/// a class over its core config; `Auto`'s below).
macro_rules! method_classes {
    ($($class:ty => $variant:ident,)*) => {
        /// The core config of a config object, if it is one.
        fn config_of(v: &Bound<'_, PyAny>) -> Option<MethodConfig> {
            $(if let Ok(c) = v.cast::<$class>() {
                return Some(MethodConfig::$variant(c.get().into()));
            })*
            None
        }

        /// A method config as its Python object.
        pub fn to_py(py: Python<'_>, c: &MethodConfig) -> PyResult<Py<PyAny>> {
            Ok(match *c {
                $(MethodConfig::$variant(c) => Py::new(py, <$class>::from(c))?.into_any(),)*
            })
        }

        /// The config classes' Python names, in the list's order.
        fn class_names(py: Python<'_>) -> PyResult<String> {
            let names: Vec<String> =
                vec![$(<$class as pyo3::PyTypeInfo>::type_object(py).name()?.to_string()),*];
            Ok(names.join(", "))
        }

        pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
            $(m.add_class::<$class>()?;)*
            Ok(())
        }
    };
}

method_classes! {
    PySsm => Ssm,
    PyBitmask => Bitmask,
    PyExact => Exact,
    PyAuto => Auto,
    PyPcss => Pcss,
    PySmoothies => Smoothies,
    PyShadowMapping => ShadowMapping,
}
