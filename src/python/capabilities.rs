//! The core's table of methods and limits as Python objects
//! (`softshadow.capabilities()`, `softshadow.limits()`).

use crate::methods::capabilities::{self as caps, Kind, Value};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// An option's value as Python's.
pub fn value(py: Python<'_>, v: &Value) -> PyResult<Py<PyAny>> {
    Ok(match v {
        Value::Resolved => py.None(),
        Value::Int(n) => n.into_pyobject(py)?.into_any().unbind(),
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any().unbind(),
        Value::Str(s) => s.into_pyobject(py)?.into_any().unbind(),
        Value::Float(x) => x.into_pyobject(py)?.into_any().unbind(),
        Value::Pair(w, h) => (w, h).into_pyobject(py)?.into_any().unbind(),
    })
}

/// One option of a method's config.
#[pyclass(frozen, module = "softshadow._core", name = "OptionInfo")]
pub struct OptionInfo {
    #[pyo3(get)]
    name: &'static str,
    /// "int", "one_of", "bool", "choice", "resolution", "float" (limits in
    /// its doc) or "config" (one of the config classes in `choices`, or
    /// None where the default is None).
    #[pyo3(get)]
    kind: &'static str,
    /// The default; None where it is resolved when the config runs.
    #[pyo3(get)]
    default: Py<PyAny>,
    /// The default in words.
    #[pyo3(get)]
    default_doc: &'static str,
    #[pyo3(get)]
    doc: &'static str,
    /// Smallest value ("int"), else None.
    #[pyo3(get)]
    min: Option<i64>,
    /// Largest value ("int"), or most texels ("resolution"), else None.
    #[pyo3(get)]
    max: Option<i64>,
    /// The allowed values ("one_of", "choice"; [False, True] for "bool"), else None.
    #[pyo3(get)]
    choices: Option<Py<PyAny>>,
    /// Backends that accept only some values: {backend: [values]}.
    #[pyo3(get)]
    restricted_on: Py<PyDict>,
}

#[pymethods]
impl OptionInfo {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "OptionInfo(name='{}', kind='{}', default={}, min={}, max={}, choices={})",
            self.name,
            self.kind,
            self.default.bind(py).repr()?,
            self.min.map_or("None".into(), |v| v.to_string()),
            self.max.map_or("None".into(), |v| v.to_string()),
            match &self.choices {
                Some(c) => c.bind(py).repr()?.to_string(),
                None => "None".into(),
            }
        ))
    }
}

/// One method: its config class, options, backends and what it reads.
#[pyclass(frozen, module = "softshadow._core", name = "MethodInfo")]
pub struct MethodInfo {
    #[pyo3(get)]
    name: &'static str,
    /// The config class (softshadow.Ssm, ...).
    #[pyo3(get)]
    config: Py<PyAny>,
    #[pyo3(get)]
    summary: &'static str,
    /// What it reads of the occluders: "occluder_layers", "occluder_triangles".
    #[pyo3(get)]
    reads: Vec<&'static str>,
    /// The backends of this build that run it.
    #[pyo3(get)]
    backends: Vec<&'static str>,
    /// {name: OptionInfo}, in the config's order.
    #[pyo3(get)]
    options: Py<PyDict>,
}

#[pymethods]
impl MethodInfo {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "MethodInfo(name='{}', config={}, options={}, backends={}, reads={})",
            self.name,
            self.config.bind(py).getattr("__name__")?,
            self.options.bind(py).keys().repr()?,
            self.backends.clone().into_pyobject(py)?.repr()?,
            self.reads.clone().into_pyobject(py)?.repr()?
        ))
    }
}

fn option(py: Python<'_>, o: &caps::OptionInfo) -> PyResult<OptionInfo> {
    let (kind, min, max, choices): (_, _, _, Option<Py<PyAny>>) = match &o.kind {
        Kind::Int { min, max } => ("int", Some(*min), Some(*max), None),
        Kind::OneOf(v) => (
            "one_of",
            None,
            None,
            Some(v.clone().into_pyobject(py)?.into_any().unbind()),
        ),
        Kind::Bool => (
            "bool",
            None,
            None,
            Some(vec![false, true].into_pyobject(py)?.into_any().unbind()),
        ),
        Kind::Choice(v) => (
            "choice",
            None,
            None,
            Some(v.clone().into_pyobject(py)?.into_any().unbind()),
        ),
        Kind::Resolution { max_texels } => ("resolution", Some(1), Some(*max_texels), None),
        Kind::Config(v) => (
            "config",
            None,
            None,
            Some(v.clone().into_pyobject(py)?.into_any().unbind()),
        ),
        Kind::Float => ("float", None, None, None),
    };
    let restricted = PyDict::new(py);
    for (b, vals) in &o.restricted_on {
        let vals = vals
            .iter()
            .map(|v| value(py, v))
            .collect::<PyResult<Vec<_>>>()?;
        restricted.set_item(b.name(), vals)?;
    }
    Ok(OptionInfo {
        name: o.name,
        kind,
        default: value(py, &o.default)?,
        default_doc: o.default_doc,
        doc: o.doc,
        min,
        max,
        choices,
        restricted_on: restricted.unbind(),
    })
}

/// {method name: MethodInfo} for every method, in the order a user meets them.
#[pyfunction]
#[pyo3(pass_module)]
pub fn capabilities(m: &Bound<'_, PyModule>) -> PyResult<Py<PyDict>> {
    let py = m.py();
    let out = PyDict::new(py);
    for info in caps::methods() {
        let options = PyDict::new(py);
        for o in &info.options {
            options.set_item(o.name, Py::new(py, option(py, o)?)?)?;
        }
        let mi = MethodInfo {
            name: info.name,
            config: m.getattr(info.config)?.unbind(),
            summary: info.summary,
            reads: info.reads.iter().map(|r| r.name()).collect(),
            backends: info.backends.iter().map(|b| b.name()).collect(),
            options: options.unbind(),
        };
        out.set_item(info.name, Py::new(py, mi)?)?;
    }
    Ok(out.unbind())
}

/// The limits that are not one method's: {name: value}.
#[pyfunction]
pub fn limits(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let l = caps::limits();
    let d = PyDict::new(py);
    d.set_item("max_texels", l.max_texels)?;
    d.set_item("max_extent", l.max_extent)?;
    d.set_item("max_passes", l.max_passes)?;
    d.set_item("max_samples", l.max_samples)?;
    d.set_item("max_threads", l.max_threads)?;
    d.set_item("gpu_max_side", l.gpu_max_side)?;
    d.set_item("max_emission", crate::eye::shading::MAX_EMISSION)?;
    d.set_item("lights", crate::eye::MAX_LIGHTS)?;
    d.set_item("min_receivers", l.min_receivers)?;
    d.set_item("visits_per_receiver", l.visits_per_receiver)?;
    d.set_item("pcss_reads_per_receiver", l.pcss_reads_per_receiver)?;
    Ok(d)
}
