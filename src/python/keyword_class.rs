//! The Python class of every config with a keyword form
//! (`methods/keywords.rs`: `Ssm`, `Bitmask`, `Exact`, `PCSS`, `Smoothies`
//! and any method added with one), made when the module is imported from
//! the core's table (`MethodConfig::infos`), so that a new method needs no
//! line here: a subclass of one frozen base class per method, named as its
//! table says, with a read-only property per option, a keyword-only
//! constructor whose values the core checks, `repr`
//! (`Class(option=value, ...)`, each value as Python writes it), equality
//! and hashing by value, pickling through the constructor
//! (`__getnewargs_ex__`) and `to_dict`; `inspect.signature` gives the
//! options as keyword-only parameters.
//!
//! Each value given is converted by its option's `Kind` (the same
//! conversions, and TypeErrors naming the option, as every other argument).

use super::capabilities::value as py_value;
use super::config_class::PyRepr;
use super::convert::{opt_bool, opt_float, opt_int, opt_resolution, opt_string};
use crate::methods::info::{Kind, MethodInfo, Value};
use crate::methods::keywords::{Given, Keywords};
use crate::methods::MethodConfig;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyCFunction, PyDict, PyTuple, PyType};

/// The class attribute that names a class's method (the `method=` name).
const METHOD_ATTR: &str = "_method";

/// The base of the classes made here; it holds the core's config.
#[pyclass(
    subclass,
    frozen,
    eq,
    hash,
    module = "softshadow._core",
    name = "_KeywordConfig"
)]
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct PyKeywordConfig(pub MethodConfig);

fn info_of(method: &str) -> Option<MethodInfo> {
    MethodConfig::infos().into_iter().find(|i| i.name == method)
}

/// One keyword's value as the core takes it, converted by the option's kind;
/// `None` (or no value) keeps the default.
fn given(kind: &Kind, name: &str, v: &Bound<'_, PyAny>) -> PyResult<Option<Given>> {
    let v = Some(v);
    Ok(match kind {
        Kind::Int { .. } | Kind::OneOf(_) => opt_int(name, v)?.map(Given::Int),
        Kind::Bool => opt_bool(name, v)?.map(Given::Bool),
        Kind::Choice(_) => opt_string(name, v)?.map(Given::Str),
        Kind::Float => opt_float(name, v)?.map(Given::Float),
        Kind::Resolution { .. } => opt_resolution(name, v)?.map(Given::Resolution),
        Kind::Config(_) => {
            return Err(PyTypeError::new_err(format!(
                "{name}: a config option has no keyword form"
            )))
        }
    })
}

impl PyKeywordConfig {
    fn values(&self) -> Vec<(&'static str, Value)> {
        self.0.keywords().unwrap_or_default()
    }
}

#[pymethods]
impl PyKeywordConfig {
    #[new]
    #[classmethod]
    #[pyo3(signature = (*args, **kwargs))]
    fn new(
        cls: &Bound<'_, PyType>,
        args: &Bound<'_, PyTuple>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let class = cls.name()?.to_string();
        let info = cls
            .getattr(METHOD_ATTR)
            .ok()
            .and_then(|m| m.extract::<String>().ok())
            .and_then(|m| info_of(&m))
            .ok_or_else(|| {
                PyTypeError::new_err(format!(
                    "{class} is the base of the method configs; make one of them (Bitmask(), ...)"
                ))
            })?;
        if !args.is_empty() {
            return Err(PyTypeError::new_err(format!(
                "{class}() takes its options by keyword only, got {} positional argument(s)",
                args.len()
            )));
        }
        let mut k = Keywords::default();
        for (key, v) in kwargs.into_iter().flatten() {
            let key: String = key.extract()?;
            let option = info.options.iter().find(|o| o.name == key).ok_or_else(|| {
                let names: Vec<&str> = info.options.iter().map(|o| o.name).collect();
                PyTypeError::new_err(format!(
                    "{class}() got an unexpected keyword argument '{key}' (its options: {})",
                    names.join(", ")
                ))
            })?;
            if let Some(g) = given(&option.kind, option.name, &v)? {
                k.0.push((key, g));
            }
        }
        Ok(PyKeywordConfig(MethodConfig::from_keywords(info.name, &k)?))
    }

    /// The name given as ``method=``.
    #[getter]
    fn name(&self) -> &'static str {
        self.0.name()
    }

    /// The options as keyword arguments: ``Class(**c.to_dict()) == c``.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (name, v) in self.values() {
            d.set_item(name, py_value(py, &v)?)?;
        }
        Ok(d)
    }

    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        Ok((PyTuple::empty(py), self.to_dict(py)?))
    }

    fn __repr__(slf: &Bound<'_, Self>) -> PyResult<String> {
        let parts = slf
            .get()
            .values()
            .iter()
            .map(|(name, v)| Ok(format!("{name}={}", v.py_repr(slf.py())?)))
            .collect::<PyResult<Vec<String>>>()?;
        Ok(format!("{}({})", slf.get_type().name()?, parts.join(", ")))
    }
}

/// The read-only property of option `name`.
fn property<'py>(py: Python<'py>, name: &'static str, doc: &str) -> PyResult<Bound<'py, PyAny>> {
    let get = PyCFunction::new_closure(
        py,
        Some(c"option"),
        None,
        move |args: &Bound<'_, PyTuple>, _: Option<&Bound<'_, PyDict>>| -> PyResult<Py<PyAny>> {
            let slf = args.get_item(0)?;
            let c = slf.cast::<PyKeywordConfig>()?;
            let v = c
                .get()
                .values()
                .into_iter()
                .find(|(n, _)| *n == name)
                .map_or(Value::Resolved, |(_, v)| v);
            py_value(args.py(), &v)
        },
    )?;
    py.import("builtins")?
        .getattr("property")?
        .call1((get, py.None(), py.None(), doc))
}

/// The classes made here are final, as the bindings' other classes: their
/// `__init_subclass__` (called when a class derives from one) refuses.
fn final_class(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    let refuse = PyCFunction::new_closure(
        py,
        Some(c"__init_subclass__"),
        None,
        |args: &Bound<'_, PyTuple>, _: Option<&Bound<'_, PyDict>>| -> PyResult<()> {
            let cls = args.get_item(0)?;
            Err(PyTypeError::new_err(format!(
                "{} is final: it cannot be subclassed",
                cls.getattr("__base__")?.getattr("__name__")?
            )))
        },
    )?;
    py.import("builtins")?
        .getattr("classmethod")?
        .call1((refuse,))
}

/// `inspect.signature` of a class: its options, keyword-only, default None.
fn signature<'py>(py: Python<'py>, info: &MethodInfo) -> PyResult<Bound<'py, PyAny>> {
    let inspect = py.import("inspect")?;
    let parameter = inspect.getattr("Parameter")?;
    let keyword_only = parameter.getattr("KEYWORD_ONLY")?;
    let params = info
        .options
        .iter()
        .map(|o| {
            let kw = PyDict::new(py);
            kw.set_item("default", py.None())?;
            parameter.call((o.name, &keyword_only), Some(&kw))
        })
        .collect::<PyResult<Vec<_>>>()?;
    inspect.getattr("Signature")?.call1((params,))
}

/// Makes and adds every keyword-form class.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    let base = py.get_type::<PyKeywordConfig>();
    let forms = MethodConfig::keyword_forms();
    for info in MethodConfig::infos()
        .into_iter()
        .filter(|i| forms.contains(&i.name))
    {
        let ns = PyDict::new(py);
        ns.set_item("__slots__", PyTuple::empty(py))?;
        ns.set_item("__module__", "softshadow._core")?;
        ns.set_item("__qualname__", info.config)?;
        ns.set_item(
            "__doc__",
            format!(
                "{} See ``capabilities()[\"{}\"]``.",
                info.summary, info.name
            ),
        )?;
        ns.set_item(METHOD_ATTR, info.name)?;
        ns.set_item("__signature__", signature(py, &info)?)?;
        ns.set_item("__init_subclass__", final_class(py)?)?;
        for o in &info.options {
            ns.set_item(o.name, property(py, o.name, o.doc)?)?;
        }
        let class = py
            .get_type::<PyType>()
            .call1((info.config, (base.clone(),), ns))?;
        m.add(info.config, class)?;
    }
    Ok(())
}

/// A keyword-form config as its class's instance (`None`: the config has
/// no keyword form).
pub fn to_py(py: Python<'_>, c: &MethodConfig) -> PyResult<Option<Py<PyAny>>> {
    let (Some(values), Some(info)) = (c.keywords(), info_of(c.name())) else {
        return Ok(None);
    };
    let kwargs = PyDict::new(py);
    for (name, v) in values {
        kwargs.set_item(name, py_value(py, &v)?)?;
    }
    let class = py.import("softshadow._core")?.getattr(info.config)?;
    Ok(Some(class.call((), Some(&kwargs))?.unbind()))
}
